//! The flowfield's loads (docs/model.md section 3b) written once over [`Real`]: for one run,
//! and for four runs in the lanes of an `F64x4` with the same operations, so that a lane has
//! its run's bits ([`super::flowfield`] holds the run's field, its equations and their sources).

use super::aero::Coefficients;
use super::flowfield::{FlowfieldRun, ShapeRun};
use crate::lanes::Real;
use crate::scenario::MAX_STATIONS;

impl FlowfieldRun {
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

    /// The coefficients `k` with the field's loads added (docs/model.md section 3b), for the
    /// CG at `r_m` (L), the store's axis `axis_l` (C_LB's first column), the moment reference
    /// point `x_ref_m` ahead of the CG, and the stage's flow angles.
    /// Inlined, so that its fused multiply-adds are compiled with the caller's target features;
    /// a field with a table goes out of line (`add_tabulated_loads`).
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
            let at = LoadsAt {
                r_m,
                axis_l,
                x_ref_m,
                alpha_rad,
                beta_rad,
            };
            return self.add_tabulated_loads(&at, k);
        }
        let f = FieldLanes::<f64>::gather(|_| self, x_ref_m);
        f.sums(r_m, axis_l).add_loads(&f, alpha_rad, beta_rad, k)
    }

    /// [`FlowfieldRun::add_loads`] for a field with a table (a shape over depth or tables over
    /// position), out of line: inlined, its lookups made the lane propagators a tenth larger and
    /// their analytic field 4 % slower (flowfield_cost, 2026-11-28); compiled for AVX2 and FMA
    /// where the host has them, as [`super::wind_l_m_s`] (the same bits).
    #[inline(never)]
    fn add_tabulated_loads(&self, at: &LoadsAt, k: Coefficients) -> Coefficients {
        #[cfg(target_arch = "x86_64")]
        if super::host_has_fma() {
            // SAFETY: the CPU supports the features `tabulated_loads_fma` is compiled for.
            return unsafe { self.tabulated_loads_fma(at, k) };
        }
        self.tabulated_loads(at, k)
    }

    /// [`FlowfieldRun::tabulated_loads`] compiled for x86-64 hosts with AVX2 and FMA.
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn tabulated_loads_fma(&self, at: &LoadsAt, k: Coefficients) -> Coefficients {
        self.tabulated_loads(at, k)
    }

    /// The loads of a field with a table.
    #[inline(always)]
    fn tabulated_loads(&self, at: &LoadsAt, k: Coefficients) -> Coefficients {
        let LoadsAt {
            r_m,
            axis_l,
            x_ref_m,
            alpha_rad,
            beta_rad,
        } = *at;
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

/// Where and how the store meets the field at one force evaluation ([`FlowfieldRun::add_loads`]'s
/// arguments but the coefficients).
#[derive(Debug, Clone, Copy)]
struct LoadsAt {
    r_m: [f64; 3],
    axis_l: [f64; 3],
    x_ref_m: f64,
    alpha_rad: f64,
    beta_rad: f64,
}

/// The fields of one run per lane (see [`crate::lanes`]), all with the same number of stations:
/// the loads of section 3b as one sequence of operations on every lane, so that a lane has the
/// bits of its run's scalar evaluation.
#[derive(Debug, Clone, Copy)]
pub(crate) struct FieldLanes<R> {
    pub(super) stations: usize,
    /// Each station's arm from the CG, x_k + x_ref \[m\].
    pub(super) arm_m: [R; MAX_STATIONS],
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
    pub(super) any_roll: bool,
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
            slopes_per_rad: [g(&|r| r.slopes_per_rad()[0]), g(&|r| r.slopes_per_rad()[1])],
            slopes_per_rad_m: [
                g(&|r| r.slopes_per_rad()[0] * r.inv_diameter_per_m),
                g(&|r| r.slopes_per_rad()[1] * r.inv_diameter_per_m),
            ],
            inv_stations: g(&|r| 1.0 / r.stations as f64),
            any_roll: (0..R::LANES).any(|i| runs(i).roll_cl != 0.0),
        }
    }

    /// g(z) = (1 - z+ / z_r) / (1 + z+ / L_z), z+ = max(z, 0).
    #[inline(always)]
    pub(super) fn analytic_shape(&self, z_m: R) -> R {
        let zero = R::splat(0.0);
        let z = R::select(z_m.lt(zero), zero, z_m);
        (-z).mul_add(self.inv_reversal_per_m, R::splat(1.0))
            / z.mul_add(self.inv_half_depth_per_m, R::splat(1.0))
    }

    /// (alpha_i, beta_i, eta) at the point `p_m` of L (the field does not vary with y), with
    /// the shape `shape`.
    #[inline(always)]
    pub(super) fn at_with(&self, p_m: [R; 3], shape: impl Fn(R) -> R) -> [R; 3] {
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
    pub(super) fn sums_table(&self, r_m: [R; 3], axis_l: [R; 3], t: &ShapeRun) -> FieldSums<R> {
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
    pub(super) fn sums_by(
        &self,
        station: impl Fn(usize, R) -> [R; 3],
        roll: impl Fn() -> R,
    ) -> FieldSums<R> {
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
