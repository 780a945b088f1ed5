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
//! The loads are written once over [`Real`] (`FieldLanes`): for one run, and for four runs
//! in the lanes of an `F64x4` with the same operations, so that a lane has its run's bits. A
//! run without a field takes none of these operations.

use std::sync::Arc;

use super::aero::Coefficients;
use super::flowfield_grid::FieldGrid;
pub use super::flowfield_shape::{ShapeRun, corrected_shape};
use super::tables::AeroAtMach;
use crate::correction::ShapeChange;
use crate::lanes::Real;
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
    /// The store's CZ_alpha, Cm_alpha, CY_beta and Cn_beta \[1/rad\] the weights were made
    /// with.
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
    /// CZ_alpha and CY_beta \[1/rad\], the slopes the field acts through.
    pub slopes_per_rad: [f64; 2],
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
            slopes_per_rad: [aero.cz_alpha_per_rad, aero.cy_beta_per_rad],
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

    /// Whether the field is evaluated in the lanes with others (an analytic field); a field
    /// with a table goes one run at a time (its lookups are scalar).
    pub fn in_lanes(&self) -> bool {
        !self.shape_is_tabulated()
    }

    /// Whether the shape is a table over depth or the field tables over position (no half
    /// depth or reversal depth to correct, and scalar lookups).
    fn shape_is_tabulated(&self) -> bool {
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
    pub fn with_change(mut self, change: [f64; 4]) -> Result<Self, String> {
        if change[..2].iter().any(|&c| c != 0.0) {
            self = self.with_shape_change([change[0], change[1]])?;
        }
        if change[2..].iter().any(|&c| c != 0.0) {
            if self.grid.is_some() {
                return Err(
                    "the flowfield is given as tables over position: it scales with alpha by its \
                     zero-lift angle, with no upwash_per_alpha or sidewash_per_alpha to correct"
                        .to_string(),
                );
            }
            self.upwash[0] = self.per_alpha_rad[0].mul_add(change[2], self.upwash[0]);
            self.sidewash[0] = self.per_alpha_rad[1].mul_add(change[3], self.sidewash[0]);
        }
        Ok(self)
    }

    /// The field with its shape table corrected by `change` (a correction `flowfield.shape`
    /// over depth, [`corrected_shape`]); refused when the shape is not a table. No change
    /// keeps the field's bits.
    pub fn with_shape_table_change(mut self, change: &ShapeChange) -> Result<Self, String> {
        if change.len == 0 {
            return Ok(self);
        }
        let Some(shape) = &self.shape else {
            return Err(
                "the flowfield's shape is not a table over depth: it has no table to correct"
                    .to_string(),
            );
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
        let diameter_m = 1.0 / self.inv_diameter_per_m;
        self.weights = station_weights(&self.station_x_m[..n], self.centre_x_m, diameter_m, slopes);
        self.store_slopes_per_rad = slopes;
        self.slopes_per_rad = [slopes[0], slopes[2]];
        self
    }

    /// The shape changed by `change` \[1/m\] (added to 1 / L_z and 1 / z_r).
    fn with_shape_change(mut self, change: [f64; 2]) -> Result<Self, String> {
        if self.shape_is_tabulated() {
            return Err(
                "the flowfield's shape is a table: it has no half depth or reversal depth to correct"
                    .to_string(),
            );
        }
        let inv_half_depth = 1.0 / self.half_depth_m + change[0];
        let inv_reversal = self.inv_reversal_per_m + change[1];
        if !(inv_half_depth > 0.0 && inv_half_depth.is_finite()) {
            return Err(format!(
                "the flowfield's corrected 1 / half_depth_m is {inv_half_depth} per m: expected above 0"
            ));
        }
        if !(inv_reversal >= 0.0 && inv_reversal.is_finite()) {
            return Err(format!(
                "the flowfield's corrected 1 / reversal_m is {inv_reversal} per m: expected 0 or above"
            ));
        }
        self.inv_half_depth_change_per_m += change[0];
        self.inv_reversal_per_m = inv_reversal;
        Ok(self)
    }

    /// The field at the point `p_m` of L: (alpha_i \[rad\], beta_i \[rad\], eta).
    pub fn at(&self, p_m: [f64; 3]) -> [f64; 3] {
        if let Some(grid) = &self.grid {
            let [alpha_i, beta_i, _, eta] = self.grid_station(grid, p_m);
            return [alpha_i, beta_i, eta];
        }
        let f = FieldLanes::<f64>::gather(|_| self, 0.0);
        match &self.shape {
            Some(t) => f.at_with(p_m, |z| t.lanes(z)),
            None => f.at_with(p_m, |z| f.analytic_shape(z)),
        }
    }

    /// A field of tables at the point `p_m`: alpha_i \[rad\], beta_i \[rad\], e = eta - 1
    /// and eta.
    #[inline(always)]
    fn grid_station(&self, grid: &FieldGrid, p_m: [f64; 3]) -> [f64; 4] {
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

    /// The coefficients `k` with the field's loads added (docs/model.md section 3b), for the
    /// CG at `r_m` (L), the store's axis `axis_l` (C_LB's first column), the moment reference
    /// point `x_ref_m` ahead of the CG, and the stage's flow angles.
    /// Inlined, so that its fused multiply-adds are compiled with the caller's target features;
    /// a field with a table goes out of line ([`FlowfieldRun::add_tabulated_loads`]).
    #[inline(always)]
    pub fn add_loads(
        &self,
        r_m: [f64; 3],
        axis_l: [f64; 3],
        x_ref_m: f64,
        alpha_rad: f64,
        beta_rad: f64,
        k: Coefficients,
    ) -> Coefficients {
        if self.shape_is_tabulated() {
            return self.add_tabulated_loads(r_m, axis_l, x_ref_m, alpha_rad, beta_rad, k);
        }
        let f = FieldLanes::<f64>::gather(|_| self, x_ref_m);
        f.sums(r_m, axis_l).add_loads(&f, alpha_rad, beta_rad, k)
    }

    /// [`FlowfieldRun::add_loads`] for a field with a table (a shape over depth or tables over
    /// position), out of line: inlined, its lookups made the lane propagators a tenth larger and
    /// their analytic field 4 % slower (flowfield_cost, 2026-11-28); compiled for AVX2 and FMA
    /// where the host has them, as [`super::wind_l_m_s`] (the same bits).
    #[inline(never)]
    pub(crate) fn add_tabulated_loads(
        &self,
        r_m: [f64; 3],
        axis_l: [f64; 3],
        x_ref_m: f64,
        alpha_rad: f64,
        beta_rad: f64,
        k: Coefficients,
    ) -> Coefficients {
        #[cfg(target_arch = "x86_64")]
        if super::host_has_fma() {
            // SAFETY: the CPU supports the features `tabulated_loads_fma` is compiled for.
            return unsafe {
                self.tabulated_loads_fma(r_m, axis_l, x_ref_m, alpha_rad, beta_rad, k)
            };
        }
        self.tabulated_loads(r_m, axis_l, x_ref_m, alpha_rad, beta_rad, k)
    }

    /// [`FlowfieldRun::tabulated_loads`] compiled for x86-64 hosts with AVX2 and FMA.
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn tabulated_loads_fma(
        &self,
        r_m: [f64; 3],
        axis_l: [f64; 3],
        x_ref_m: f64,
        alpha_rad: f64,
        beta_rad: f64,
        k: Coefficients,
    ) -> Coefficients {
        self.tabulated_loads(r_m, axis_l, x_ref_m, alpha_rad, beta_rad, k)
    }

    /// The loads of a field with a table.
    #[inline(always)]
    fn tabulated_loads(
        &self,
        r_m: [f64; 3],
        axis_l: [f64; 3],
        x_ref_m: f64,
        alpha_rad: f64,
        beta_rad: f64,
        k: Coefficients,
    ) -> Coefficients {
        let f = FieldLanes::<f64>::gather(|_| self, x_ref_m);
        let sums = match (&self.grid, &self.shape) {
            (Some(grid), _) => {
                // Each station's field looked up in a loop of its own, so that the closures
                // given to `sums_by` stay small enough to be inlined (out of line, a closure's
                // fused multiply-adds are calls to the software `fma`; perf, 2026-11-28).
                let mut at = [[0.0; 3]; MAX_STATIONS];
                for (a, &arm) in at.iter_mut().zip(&f.arm_m).take(f.stations) {
                    let p = [
                        axis_l[0].mul_add(arm, r_m[0]),
                        axis_l[1].mul_add(arm, r_m[1]),
                        axis_l[2].mul_add(arm, r_m[2]),
                    ];
                    let [alpha_k, beta_k, e_k, eta_k] = self.grid_station(grid, p);
                    *a = [e_k, eta_k * alpha_k, eta_k * beta_k];
                }
                let roll = if f.any_roll {
                    let r = [r_m[0], r_m[1], r_m[2] * self.inv_depth_scale];
                    self.roll_cl * grid.at(r)[3]
                } else {
                    0.0
                };
                f.sums_by(|i, _| at[i], || roll)
            }
            (None, Some(t)) => f.sums_table(r_m, axis_l, t),
            (None, None) => f.sums(r_m, axis_l),
        };
        sums.add_loads(&f, alpha_rad, beta_rad, k)
    }
}

/// The fields of one run per lane (see [`crate::lanes`]), all with the same number of stations:
/// the loads of section 3b as one sequence of operations on every lane, so that a lane has the
/// bits of its run's scalar evaluation.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FieldLanes<R> {
    stations: usize,
    /// Each station's arm from the CG, x_k + x_ref \[m\].
    arm_m: [R; MAX_STATIONS],
    weights: [[R; MAX_STATIONS]; 2],
    /// w_k x_k and v_k x_k \[m\].
    weighted_x_m: [[R; MAX_STATIONS]; 2],
    upwash: [R; 2],
    sidewash: [R; 2],
    dynamic_pressure: R,
    roll_cl: R,
    inv_half_depth_per_m: R,
    inv_reversal_per_m: R,
    /// CZ_alpha / d and CY_beta / d \[1/(rad m)\], and the slopes themselves \[1/rad\].
    slopes_per_rad: [R; 2],
    slopes_per_rad_m: [R; 2],
    inv_stations: R,
    /// Whether any lane's field has a rolling moment (its shape at the CG is otherwise not
    /// formed).
    any_roll: bool,
}

impl<R: Real> FieldLanes<R> {
    /// The fields of one run per lane (`runs(i)`: lane `i`'s), each lane's moment reference
    /// point `x_ref_m`; every run has [`FieldLanes::stations`] of lane 0.
    #[inline(always)]
    pub(crate) fn gather<'a>(runs: impl Fn(usize) -> &'a FlowfieldRun, x_ref_m: R) -> Self {
        let g = |f: &dyn Fn(&FlowfieldRun) -> f64| crate::lanes::gather::<R>(|i| f(runs(i)));
        let per_station = |f: &dyn Fn(&FlowfieldRun, usize) -> f64| {
            std::array::from_fn(|k| crate::lanes::gather::<R>(|i| f(runs(i), k)))
        };
        let station_x_m: [R; MAX_STATIONS] = per_station(&|r, k| r.station_x_m[k]);
        FieldLanes {
            stations: runs(0).stations,
            arm_m: station_x_m.map(|x| x + x_ref_m),
            weights: [
                per_station(&|r, k| r.weights[0][k]),
                per_station(&|r, k| r.weights[1][k]),
            ],
            weighted_x_m: [
                per_station(&|r, k| r.weights[0][k] * r.station_x_m[k]),
                per_station(&|r, k| r.weights[1][k] * r.station_x_m[k]),
            ],
            upwash: [g(&|r| r.upwash[0]), g(&|r| r.upwash[1])],
            sidewash: [g(&|r| r.sidewash[0]), g(&|r| r.sidewash[1])],
            dynamic_pressure: g(&|r| r.dynamic_pressure),
            roll_cl: g(&|r| r.roll_cl),
            inv_half_depth_per_m: g(&|r| r.inv_half_depth_per_m()),
            inv_reversal_per_m: g(&|r| r.inv_reversal_per_m),
            slopes_per_rad: [g(&|r| r.slopes_per_rad[0]), g(&|r| r.slopes_per_rad[1])],
            slopes_per_rad_m: [
                g(&|r| r.slopes_per_rad[0] * r.inv_diameter_per_m),
                g(&|r| r.slopes_per_rad[1] * r.inv_diameter_per_m),
            ],
            inv_stations: g(&|r| 1.0 / r.stations as f64),
            any_roll: (0..R::LANES).any(|i| runs(i).roll_cl != 0.0),
        }
    }

    /// g(z) = (1 - z+ / z_r) / (1 + z+ / L_z), z+ = max(z, 0).
    #[inline(always)]
    fn analytic_shape(&self, z_m: R) -> R {
        let zero = R::splat(0.0);
        let z = R::select(z_m.lt(zero), zero, z_m);
        (-z).mul_add(self.inv_reversal_per_m, R::splat(1.0))
            / z.mul_add(self.inv_half_depth_per_m, R::splat(1.0))
    }

    /// (alpha_i, beta_i, eta) at the point `p_m` of L (the field does not vary with y), with
    /// the shape `shape`.
    #[inline(always)]
    fn at_with(&self, p_m: [R; 3], shape: impl Fn(R) -> R) -> [R; 3] {
        let g = shape(p_m[2]);
        [
            self.upwash[1].mul_add(p_m[0], self.upwash[0]) * g,
            self.sidewash[1].mul_add(p_m[0], self.sidewash[0]) * g,
            self.dynamic_pressure.mul_add(g, R::splat(1.0)),
        ]
    }

    /// The sums over the stations that need the field alone, for the CG at `r_m` and the
    /// store's axis `axis_l`.
    ///
    /// With e_k = E g_k (so eta_k = 1 + e_k), n_k = e_k alpha + eta_k alpha_k: the sums of the
    /// weights times e_k and times eta_k alpha_k (or eta_k beta_k) need only the position and
    /// attitude, so they are formed beside the flow angles (the slowest chain of a force
    /// evaluation), which then enter by one multiply-add each ([`FieldSums::add_loads`]).
    #[inline(always)]
    pub(crate) fn sums(&self, r_m: [R; 3], axis_l: [R; 3]) -> FieldSums<R> {
        self.sums_with(r_m, axis_l, |z| self.analytic_shape(z))
    }

    /// [`FieldLanes::sums`] with the shape `shape` (g at each lane's depth).
    #[inline(always)]
    fn sums_with(&self, r_m: [R; 3], axis_l: [R; 3], shape: impl Fn(R) -> R) -> FieldSums<R> {
        let upwash = self.upwash_at(r_m, axis_l);
        let sidewash = self.sidewash_at(r_m, axis_l);
        self.sums_by(
            |_, arm| self.station(upwash, sidewash, shape(axis_l[2].mul_add(arm, r_m[2])), arm),
            || self.roll_cl * shape(r_m[2]),
        )
    }

    /// [`FieldLanes::sums`] with the shape a table `t` (a field of one run: a field whose shape
    /// is a table is evaluated one run at a time, through [`FlowfieldRun::add_loads`]). The
    /// stations' g are looked up first, in a loop of their own, so that the closure given to
    /// [`FieldLanes::sums_by`] stays small enough to be inlined: out of line, its fused
    /// multiply-adds were calls to the software `fma` (perf, 2026-11-28).
    #[inline(always)]
    fn sums_table(&self, r_m: [R; 3], axis_l: [R; 3], t: &ShapeRun) -> FieldSums<R> {
        let mut g = [R::splat(0.0); MAX_STATIONS];
        for (g_k, &arm) in g.iter_mut().zip(&self.arm_m).take(self.stations) {
            *g_k = t.lanes(axis_l[2].mul_add(arm, r_m[2]));
        }
        let roll_g = if self.any_roll {
            t.lanes(r_m[2])
        } else {
            R::splat(0.0)
        };
        let upwash = self.upwash_at(r_m, axis_l);
        let sidewash = self.sidewash_at(r_m, axis_l);
        self.sums_by(
            |i, arm| self.station(upwash, sidewash, g[i], arm),
            || self.roll_cl * roll_g,
        )
    }

    /// alpha_i / g = A + A_x p_x with p_x = r_x + C_LB[0][0] arm: at each station
    /// (A + A_x r_x) + (A_x C_LB[0][0]) arm, one multiply-add.
    #[inline(always)]
    fn upwash_at(&self, r_m: [R; 3], axis_l: [R; 3]) -> [R; 2] {
        [
            self.upwash[1].mul_add(r_m[0], self.upwash[0]),
            self.upwash[1] * axis_l[0],
        ]
    }

    /// The same for beta_i / g.
    #[inline(always)]
    fn sidewash_at(&self, r_m: [R; 3], axis_l: [R; 3]) -> [R; 2] {
        [
            self.sidewash[1].mul_add(r_m[0], self.sidewash[0]),
            self.sidewash[1] * axis_l[0],
        ]
    }

    /// (e_k, eta_k alpha_k, eta_k beta_k) at a station's `arm` where the shape is `g`.
    #[inline(always)]
    fn station(&self, upwash: [R; 2], sidewash: [R; 2], g: R, arm: R) -> [R; 3] {
        let e_k = self.dynamic_pressure * g;
        let eta_g = e_k.mul_add(g, g);
        [
            e_k,
            upwash[1].mul_add(arm, upwash[0]) * eta_g,
            sidewash[1].mul_add(arm, sidewash[0]) * eta_g,
        ]
    }

    /// The sums over the stations of the field `station` gives at each station's arm
    /// (e_k, eta_k alpha_k, eta_k beta_k), with the rolling moment `roll` (formed only when a
    /// lane's field has one).
    #[inline(always)]
    fn sums_by(&self, station: impl Fn(usize, R) -> [R; 3], roll: impl Fn() -> R) -> FieldSums<R> {
        let zero = R::splat(0.0);
        // Each sum its own variable (an array indexed in a loop may be kept in memory).
        let [mut e_n, mut e_m, mut e_y, mut e_r] = [zero; 4];
        let [mut f_n, mut f_m, mut f_y, mut f_r] = [zero; 4];
        let mut e_sum = zero;
        for i in 0..self.stations {
            let [e_k, alpha_k, beta_k] = station(i, self.arm_m[i]);
            let (w, wx) = (self.weights[0][i], self.weighted_x_m[0][i]);
            let (v, vx) = (self.weights[1][i], self.weighted_x_m[1][i]);
            e_n = w.mul_add(e_k, e_n);
            e_m = wx.mul_add(e_k, e_m);
            e_y = v.mul_add(e_k, e_y);
            e_r = vx.mul_add(e_k, e_r);
            f_n = w.mul_add(alpha_k, f_n);
            f_m = wx.mul_add(alpha_k, f_m);
            f_y = v.mul_add(beta_k, f_y);
            f_r = vx.mul_add(beta_k, f_r);
            e_sum = e_sum + e_k;
        }
        let (by_angle, field) = ([e_n, e_m, e_y, e_r], [f_n, f_m, f_y, f_r]);
        FieldSums {
            by_angle,
            field,
            e_sum,
            roll_cl: if self.any_roll { roll() } else { zero },
        }
    }
}

/// The sums over a field's stations that need the field alone ([`FieldLanes::sums`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct FieldSums<R> {
    /// Normal, pitch, side and yaw: sum w_k e_k, sum w_k x_k e_k, sum v_k e_k, sum v_k x_k e_k.
    by_angle: [R; 4],
    /// The same with eta_k alpha_k (normal, pitch) and eta_k beta_k (side, yaw) for e_k.
    field: [R; 4],
    /// sum e_k.
    e_sum: R,
    /// dCl = Lr g(r_z).
    roll_cl: R,
}

impl<R: Real> FieldSums<R> {
    /// The loads of docs/model.md section 3b added to `k`, at the stage's flow angles.
    #[inline(always)]
    pub(crate) fn add_loads(
        &self,
        f: &FieldLanes<R>,
        alpha_rad: R,
        beta_rad: R,
        mut k: Coefficients<R>,
    ) -> Coefficients<R> {
        k.cx = (self.e_sum * f.inv_stations).mul_add(k.cx, k.cx);
        k.cz = f.slopes_per_rad[0].mul_add(self.sum(0, alpha_rad), k.cz);
        k.cm = (-f.slopes_per_rad_m[0]).mul_add(self.sum(1, alpha_rad), k.cm);
        k.cy = f.slopes_per_rad[1].mul_add(self.sum(2, beta_rad), k.cy);
        k.cn = f.slopes_per_rad_m[1].mul_add(self.sum(3, beta_rad), k.cn);
        k.cl = k.cl + self.roll_cl;
        k
    }

    /// Sum `j` (normal, pitch, side, yaw) at the flow angle `angle`: sum w_k n_k = angle
    /// sum w_k e_k + sum w_k eta_k alpha_k (likewise the others). A method, not a closure: sure
    /// to be inlined, so its multiply-add is compiled with the propagator's target features.
    #[inline(always)]
    fn sum(&self, j: usize, angle: R) -> R {
        self.by_angle[j].mul_add(angle, self.field[j])
    }
}
