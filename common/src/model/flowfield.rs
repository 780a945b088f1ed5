//! The aircraft's flowfield acting on the store station by station (docs/model.md section 3b).
//!
//! Sources: the flow-angularity method (F. D. Fernandes, *Theoretical prediction of
//! interference loading on aircraft stores*, NASA CR-112065, 1972): the store's loads from the
//! local flow angles at stations along its length; the field's scaling with the aircraft's lift
//! and the Prandtl-Glauert factor, its inverse-distance decay as a vortex line's induced
//! velocity (J. Katz and A. Plotkin, *Low-Speed Aerodynamics*, 2nd ed.,
//! 2001). The equations, from docs/model.md section 3b:
//!
//! ```text
//! g(z)       = (1 - z+ / z_r) / (1 + z+ / L_z),   z+ = max(z, 0)
//! alpha_i(P) = (A + A_x p_x) g(p_z),   beta_i(P) = (B + B_x p_x) g(p_z),   eta(P) = 1 + E g(p_z)
//! P_k        = r + C_LB (x_k + x_ref, 0, 0)
//! n_k = eta_k (alpha + alpha_k) - alpha,       m_k = eta_k (beta + beta_k) - beta
//! dCZ = CZ_alpha sum w_k n_k,    dCm = -(CZ_alpha / d) sum w_k x_k n_k
//! dCY = CY_beta  sum v_k m_k,    dCn =  (CY_beta / d)  sum v_k x_k m_k
//! dCX = (eta_bar - 1) CX,        dCl = Lr g(r_z)
//! ```
//!
//! A field given as tables over position ([`FieldGrid`]) takes the tables' values at P_k in
//! place of (A + A_x p_x) g, (B + B_x p_x) g and E g, each times its factor and scaling, and
//! the rolling-moment table's at the CG in place of Lr g(r_z).
//!
//! The loads are written once over `Real` (`flowfield_lanes`): for one run, and for four runs
//! in the lanes of an `F64x4` with the same operations, so that a lane has its run's bits. A
//! run without a field takes none of these operations. The shape as a table is
//! `flowfield_shape`'s, the field as tables over position `flowfield_grid`'s.

use std::sync::Arc;

use super::flowfield_grid::FieldGrid;
pub use super::flowfield_shape::ShapeRun;
use super::tables::AeroAtMach;
use crate::correction::{FieldChangeError, ShapeChange};
use crate::scenario::{FlowfieldSpec, MAX_STATIONS, MachScaling};
use sepval_core::factors::{Factor, Factors};

/// Pg(M) of docs/model.md section 3b: 1 / sqrt(max(|1 - M^2|, 0.1)), or 1 without scaling.
pub fn mach_factor(scaling: MachScaling, mach: f64) -> f64 {
    match scaling {
        MachScaling::PrandtlGlauert => 1.0 / (1.0 - mach * mach).abs().max(0.1).sqrt(),
        MachScaling::None => 1.0,
    }
}

/// The normal force's weights w_k and the side force's v_k at `station_x_m` (docs/model.md
/// section 3b, "Stations"): 1/N plus a part linear in x_k - x_bar that puts their centre at
/// the centre of pressure of the store's `slopes` \[CZ_alpha, Cm_alpha, CY_beta, Cn_beta\].
fn station_weights(
    station_x_m: &[f64],
    x_bar: f64,
    diameter_m: f64,
    slopes: [f64; 4],
) -> [[f64; MAX_STATIONS]; 2] {
    let n = station_x_m.len();
    let spread: f64 = station_x_m.iter().map(|x| (x - x_bar).powi(2)).sum();
    let centres_of_pressure = [
        -diameter_m * slopes[1] / slopes[0],
        diameter_m * slopes[3] / slopes[2],
    ];
    centres_of_pressure.map(|x_cp| {
        let mut w = [0.0; MAX_STATIONS];
        for (w_k, x_k) in w.iter_mut().zip(station_x_m) {
            *w_k = 1.0 / n as f64 + (x_cp - x_bar) * (x_k - x_bar) / spread;
        }
        w
    })
}

/// One run's field and stations, with the factors and the flight condition applied.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowfieldRun {
    /// Number of stations in use.
    pub stations: usize,
    /// Body x of each station from the moment reference point \[m\].
    pub station_x_m: [f64; MAX_STATIONS],
    /// Weights of the normal force (w_k) and of the side force (v_k).
    pub weights: [[f64; MAX_STATIONS]; 2],
    /// x_bar: the middle of the store between nose and tail \[m\].
    pub centre_x_m: f64,
    /// The store's CZ_alpha, Cm_alpha, CY_beta and Cn_beta \[1/rad\]: the weights were made
    /// with them, and the field acts through CZ_alpha and CY_beta
    /// ([`FlowfieldRun::slopes_per_rad`]).
    pub store_slopes_per_rad: [f64; 4],
    /// What a change of 1 deg/deg of a_alpha and of b_alpha adds to A and B \[rad\]: their
    /// factors times s_M times (alpha_a - alpha_ref) in radians.
    pub per_alpha_rad: [f64; 2],
    /// A: upwash at the carriage point \[rad\], and A_x, its gradient along L's x \[rad/m\].
    pub upwash: [f64; 2],
    /// B and B_x: the sidewash's \[rad, rad/m\].
    pub sidewash: [f64; 2],
    /// E: eta - 1 at carriage.
    pub dynamic_pressure: f64,
    /// Lr: the rolling-moment coefficient at carriage.
    pub roll_cl: f64,
    /// L_z: the depth below carriage at which the field has halved \[m\] (the effect
    /// `interference_decay` scales it); infinite when the shape is a table.
    pub half_depth_m: f64,
    /// The shape as a table over depth, in place of L_z and z_r (the effect
    /// `interference_decay` scales its depths).
    pub shape: Option<ShapeRun>,
    /// The field as tables over position, in place of the analytic field: `upwash[0]` and
    /// `sidewash[0]` are then the factors that turn its angles (degrees) into radians,
    /// `dynamic_pressure` its eta - 1's, `roll_cl` its rolling moment's.
    pub grid: Option<Arc<FieldGrid>>,
    /// 1 / k, the inverse of the depth scale k of a field of tables (the effect
    /// `interference_decay`: the field at depth z is the tables' at z / k); 1 otherwise.
    pub inv_depth_scale: f64,
    /// 1 / z_r \[1/m\] (0: the field never changes sign), with any correction of it.
    pub inv_reversal_per_m: f64,
    /// A correction's change of 1 / L_z \[1/m\] (docs/update.md): 0 but in an update's
    /// refits.
    pub inv_half_depth_change_per_m: f64,
    /// d \[m\], the store's diameter (the weights' centres of pressure).
    pub diameter_m: f64,
    /// 1 / d \[1/m\].
    pub inv_diameter_per_m: f64,
}

impl FlowfieldRun {
    /// The run of `spec` for a store of diameter `diameter_m` with the derivatives `aero` at
    /// the flight condition (`mach`, aircraft angle of attack `alpha_deg`), with `factors`;
    /// `grid` is the field's tables over position ([`FieldGrid::of`] `spec`), if it has them.
    pub fn new(
        spec: &FlowfieldSpec,
        grid: Option<&Arc<FieldGrid>>,
        aero: &AeroAtMach,
        diameter_m: f64,
        mach: f64,
        alpha_deg: f64,
        factors: &Factors,
    ) -> Self {
        let fx = |f: Factor| factors.get(f);
        let s_m = mach_factor(spec.mach_scaling, mach)
            / mach_factor(spec.mach_scaling, spec.reference_mach);
        let d_alpha = alpha_deg - spec.reference_alpha_deg;
        let n = spec.stations;
        let length_m = spec.nose_x_m - spec.tail_x_m;
        let mut station_x_m = [0.0; MAX_STATIONS];
        for (k, x) in station_x_m.iter_mut().take(n).enumerate() {
            *x = spec.tail_x_m + (k as f64 + 0.5) * length_m / n as f64;
        }
        let x_bar = 0.5 * (spec.nose_x_m + spec.tail_x_m);
        let slopes = [
            aero.cz_alpha_per_rad,
            aero.cm_alpha_per_rad,
            aero.cy_beta_per_rad,
            aero.cn_beta_per_rad,
        ];
        let [a0, b0, eta0, l0] = spec.carriage_values();
        let run = FlowfieldRun {
            stations: n,
            station_x_m,
            weights: station_weights(&station_x_m[..n], x_bar, diameter_m, slopes),
            centre_x_m: x_bar,
            store_slopes_per_rad: slopes,
            per_alpha_rad: [
                fx(Factor::Czintfac) * s_m * d_alpha.to_radians(),
                fx(Factor::Cyintfac) * s_m * d_alpha.to_radians(),
            ],
            upwash: [
                fx(Factor::Czintfac) * s_m * (a0 + spec.upwash_per_alpha * d_alpha).to_radians(),
                fx(Factor::Cmintfac) * s_m * spec.upwash_gradient_deg_per_m.to_radians(),
            ],
            sidewash: [
                fx(Factor::Cyintfac) * s_m * (b0 + spec.sidewash_per_alpha * d_alpha).to_radians(),
                fx(Factor::Cnintfac) * s_m * spec.sidewash_gradient_deg_per_m.to_radians(),
            ],
            dynamic_pressure: fx(Factor::Caintfac) * s_m * (eta0 - 1.0),
            roll_cl: fx(Factor::Clintfac) * s_m * l0,
            half_depth_m: spec.half_depth_m.unwrap_or(f64::INFINITY),
            shape: spec.shape.as_ref().map(|t| ShapeRun::new(&t.depth_m, &t.g)),
            grid: None,
            inv_depth_scale: 1.0,
            inv_reversal_per_m: spec.reversal_m.map_or(0.0, |z_r| 1.0 / z_r),
            inv_half_depth_change_per_m: 0.0,
            diameter_m,
            inv_diameter_per_m: 1.0 / diameter_m,
        };
        match grid {
            Some(grid) => run.with_grid(grid, spec, factors, s_m, alpha_deg),
            None => run,
        }
    }

    /// The run with the field of tables `grid` in place of the analytic field: its angles
    /// scaled by the factor, s_M and (alpha_a - alpha_0) / (alpha_ref - alpha_0) (1 without
    /// alpha_0), its eta - 1 and rolling moment by the factor and s_M (docs/model.md section
    /// 3b, "The field as a table over position").
    fn with_grid(
        mut self,
        grid: &Arc<FieldGrid>,
        spec: &FlowfieldSpec,
        factors: &Factors,
        s_m: f64,
        alpha_deg: f64,
    ) -> Self {
        let fx = |f: Factor| factors.get(f);
        let c_alpha = spec.zero_lift_alpha_deg.map_or(1.0, |a_0| {
            (alpha_deg - a_0) / (spec.reference_alpha_deg - a_0)
        });
        let has = |j: usize| spec.position_tables()[j].is_some();
        self.upwash = [(fx(Factor::Czintfac) * s_m * c_alpha).to_radians(), 0.0];
        self.sidewash = [(fx(Factor::Cyintfac) * s_m * c_alpha).to_radians(), 0.0];
        self.dynamic_pressure = fx(Factor::Caintfac) * s_m;
        self.roll_cl = if has(3) {
            fx(Factor::Clintfac) * s_m
        } else {
            0.0
        };
        self.grid = Some(Arc::clone(grid));
        self
    }

    /// How far the stations of the store in state `x` (and its CG, where the rolling moment is
    /// a table) lie beyond the field's grid along each axis, in the tables' coordinates \[m\],
    /// with the moment reference point `x_ref_m` ahead of the CG; none without tables over
    /// position. The points are those [`FlowfieldRun::add_loads`] looks the tables up at.
    pub fn beyond_grid(&self, x: &crate::model::StateVector, x_ref_m: f64) -> Option<[f64; 3]> {
        let grid = self.grid.as_ref()?;
        let c_lb = crate::frames::dcm_from_quaternion([x[6], x[7], x[8], x[9]]);
        let r_m = [x[0], x[1], x[2]];
        let scaled = |p: [f64; 3]| [p[0], p[1], p[2] * self.inv_depth_scale];
        let mut worst = if self.roll_cl != 0.0 {
            grid.beyond(scaled(r_m))
        } else {
            [0.0; 3]
        };
        for &x_k in &self.station_x_m[..self.stations] {
            let arm = x_k + x_ref_m;
            let p = std::array::from_fn(|j| c_lb[(j, 0)].mul_add(arm, r_m[j]));
            for (w, b) in worst.iter_mut().zip(grid.beyond(scaled(p))) {
                *w = w.max(b);
            }
        }
        Some(worst)
    }

    /// Whether the field is evaluated in the lanes with others (an analytic field); a field
    /// with a table goes one run at a time (its lookups are scalar).
    pub fn in_lanes(&self) -> bool {
        !self.shape_is_tabulated()
    }

    /// CZ_alpha and CY_beta \[1/rad\], the slopes the field acts through.
    #[inline(always)]
    pub fn slopes_per_rad(&self) -> [f64; 2] {
        [self.store_slopes_per_rad[0], self.store_slopes_per_rad[2]]
    }

    /// Whether the shape is a table over depth or the field tables over position (no half
    /// depth or reversal depth to correct, and scalar lookups).
    pub(super) fn shape_is_tabulated(&self) -> bool {
        self.shape.is_some() || self.grid.is_some()
    }

    /// 1 / L_z \[1/m\], with any correction of it.
    pub fn inv_half_depth_per_m(&self) -> f64 {
        // Without a change, 1 / L_z to the bit (a positive number plus 0).
        1.0 / self.half_depth_m + self.inv_half_depth_change_per_m
    }

    /// The field changed by the corrections `change` (docs/update.md section 15.3a), in
    /// [`FieldPart::ALL`](crate::correction::FieldPart::ALL) order: 1 / L_z and 1 / z_r
    /// \[1/m\], a_alpha and b_alpha \[deg/deg\]. Refused when 1 / L_z would not stay above 0
    /// or 1 / z_r below 0 (the field would not decay, or would grow with depth), and when a
    /// part the field does not have is changed (a table's shape has no depths; tables over
    /// position scale with alpha by their zero-lift angle, not a slope). A part not changed
    /// (0) keeps the field's bits.
    pub fn with_change(mut self, change: [f64; 4]) -> Result<Self, FieldChangeError> {
        if change[..2].iter().any(|&c| c != 0.0) {
            self = self.with_shape_change([change[0], change[1]])?;
        }
        if change[2..].iter().any(|&c| c != 0.0) {
            if self.grid.is_some() {
                return Err(FieldChangeError::GridPerAlpha);
            }
            self.upwash[0] = self.per_alpha_rad[0].mul_add(change[2], self.upwash[0]);
            self.sidewash[0] = self.per_alpha_rad[1].mul_add(change[3], self.sidewash[0]);
        }
        Ok(self)
    }

    /// The field with its shape table corrected by `change` (a correction `flowfield.shape`
    /// over depth, [`crate::correction::corrected_shape`]); refused when the shape is not a
    /// table. No change keeps the field's bits.
    pub fn with_shape_table_change(
        mut self,
        change: &ShapeChange,
    ) -> Result<Self, FieldChangeError> {
        if change.len == 0 {
            return Ok(self);
        }
        let Some(shape) = &self.shape else {
            return Err(FieldChangeError::NoShapeTable);
        };
        let n = change.len;
        self.shape = Some(shape.corrected(&change.depth_m[..n], &change.value[..n])?);
        Ok(self)
    }

    /// The field acting through the store's slopes changed by `change` (CZ_alpha, Cm_alpha,
    /// CY_beta, Cn_beta \[1/rad\]: corrections of the store's derivatives, which the field's
    /// loads and weights take as the store's own, docs/model.md section 3b). A change of 0
    /// keeps the field's bits.
    pub fn with_slope_change(mut self, change: [f64; 4]) -> Self {
        if change.iter().all(|&c| c == 0.0) {
            return self;
        }
        let mut slopes = self.store_slopes_per_rad;
        for (s, c) in slopes.iter_mut().zip(change) {
            *s += c;
        }
        let n = self.stations;
        self.weights = station_weights(
            &self.station_x_m[..n],
            self.centre_x_m,
            self.diameter_m,
            slopes,
        );
        self.store_slopes_per_rad = slopes;
        self
    }

    /// The shape changed by `change` \[1/m\] (added to 1 / L_z and 1 / z_r).
    fn with_shape_change(mut self, change: [f64; 2]) -> Result<Self, FieldChangeError> {
        if self.shape_is_tabulated() {
            return Err(FieldChangeError::ShapeIsTable);
        }
        let inv_half_depth = 1.0 / self.half_depth_m + change[0];
        let inv_reversal = self.inv_reversal_per_m + change[1];
        if !(inv_half_depth > 0.0 && inv_half_depth.is_finite()) {
            return Err(FieldChangeError::HalfDepth {
                inverse: inv_half_depth,
            });
        }
        if !(inv_reversal >= 0.0 && inv_reversal.is_finite()) {
            return Err(FieldChangeError::Reversal {
                inverse: inv_reversal,
            });
        }
        self.inv_half_depth_change_per_m += change[0];
        self.inv_reversal_per_m = inv_reversal;
        Ok(self)
    }

    /// A field of tables at the point `p_m`: alpha_i \[rad\], beta_i \[rad\], e = eta - 1
    /// and eta.
    #[inline(always)]
    pub(super) fn grid_station(&self, grid: &FieldGrid, p_m: [f64; 3]) -> [f64; 4] {
        let [up_deg, side_deg, eta_change, _] =
            grid.at([p_m[0], p_m[1], p_m[2] * self.inv_depth_scale]);
        let e = self.dynamic_pressure * eta_change;
        [
            self.upwash[0] * up_deg,
            self.sidewash[0] * side_deg,
            e,
            1.0 + e,
        ]
    }
}
