//! The parts of a force evaluation that run lane by lane, each lane through the scalar code of
//! its own run, and are put back into the lanes (docs/model.md section 9's rule: a lane has the
//! bits of its run's scalar evaluation): the wind (section 11.2), the tables', catalogue's and
//! extension's terms (sections 3, 7 and 11), and the flowfield of batches whose lanes' fields
//! differ in kind (section 3b); and what one run's evaluation needs for them ([`Parts`]).

use crate::lanes::{Real, lane};
use crate::table::{Inputs, PreparedTables, TableState};

use super::aero::{Coefficients, Flow};
use super::{EjectorCurve, RunSetup};

/// Each lane's wind in L at its time (section 11.2; +0.0 in lanes without one), from the
/// scalar code of its run, as the extra terms below. Out of line: only runs with a wind call
/// it.
#[inline(never)]
pub(super) fn wind_lanes<R: Real>(parts: &[Parts], t_s: R) -> [R; 3] {
    let mut w = [R::splat(0.0).to_array(); 3];
    for (i, part) in parts.iter().enumerate() {
        if part.run.terms.has_wind() {
            let w_i = super::wind_l_m_s(&part.run.terms, lane(t_s, i));
            for (j, v) in w_i.into_iter().enumerate() {
                w[j].as_mut()[i] = v;
            }
        }
    }
    w.map(R::from_array)
}

/// Whether every lane has a field with the same number of stations, so that the fields are
/// evaluated in the lanes together.
pub(super) fn alike_fields(parts: &[Parts]) -> bool {
    // A field with a table is evaluated one run at a time (its lookups are scalar).
    let stations = |p: &Parts| {
        p.run
            .flowfield
            .as_ref()
            .filter(|f| f.in_lanes())
            .map(|f| f.stations)
    };
    stations(&parts[0]).is_some() && parts.iter().all(|p| stations(p) == stations(&parts[0]))
}

/// The flowfield's loads (section 3b) of each lane's run that has a field, one lane at a time,
/// at that lane's CG position `r_m`, axis `axis_l` and flow angles, put back into the lanes:
/// for batches whose lanes' fields differ in kind (never the runs of one scenario). Inlined, so
/// that its fused multiply-adds are compiled with the propagator's target features (out of
/// line, each would be a call to the software `fma`).
#[inline(always)]
pub(super) fn flowfield_lanes<R: Real>(
    parts: &[Parts],
    r_m: [R; 3],
    axis_l: [R; 3],
    flow: &Flow<R>,
    k: Coefficients<R>,
) -> Coefficients<R> {
    let mut c = lanes_of(k);
    for (i, part) in parts.iter().enumerate() {
        let Some(field) = &part.run.flowfield else {
            continue;
        };
        let k_i = lane_of::<R>(&c, i);
        let k_i = field.add_loads(
            r_m.map(|v| lane(v, i)),
            axis_l.map(|v| lane(v, i)),
            part.run.aero_reference_x_m,
            lane(flow.alpha_rad, i),
            lane(flow.beta_rad, i),
            k_i,
        );
        set_lane::<R>(&mut c, i, k_i);
    }
    from_lanes::<R>(c)
}

/// The extra terms of each lane's run ([`Parts::extra_terms`]) at that lane's flow, put back into
/// the lanes (inlined, so that the tables' arithmetic is compiled with the propagator's target
/// features; the catalogue's terms are out of line). The extension's terms are added after
/// these, in the lanes together ([`super::term_lanes`]).
#[inline(always)]
pub(super) fn lane_by_lane_terms<R: Real>(
    parts: &[Parts],
    flow: &Flow<R>,
    lateral_m: R,
    k: Coefficients<R>,
) -> Coefficients<R> {
    // Through arrays, each lane read and written once (a lane written into a register's
    // memory and read back whole stalls the load).
    let f = [
        flow.alpha_rad,
        flow.beta_rad,
        flow.p_hat,
        flow.q_hat,
        flow.r_hat,
        flow.speed_m_s,
        flow.interference_factor,
        flow.t_s,
        flow.distance_m,
        flow.mach,
        lateral_m,
    ]
    .map(R::to_array);
    let mut c = lanes_of(k);
    for (i, part) in parts.iter().enumerate() {
        if !part.has_extra_terms() {
            continue;
        }
        let l = |j: usize| f[j].as_ref()[i];
        let flow_i = Flow {
            alpha_rad: l(0),
            beta_rad: l(1),
            p_hat: l(2),
            q_hat: l(3),
            r_hat: l(4),
            speed_m_s: l(5),
            interference_factor: l(6),
            t_s: l(7),
            distance_m: l(8),
            mach: l(9),
        };
        let k_i = lane_of::<R>(&c, i);
        let k_i = part.extra_terms(&flow_i, l(10), k_i);
        set_lane::<R>(&mut c, i, k_i);
    }
    from_lanes::<R>(c)
}

/// What one run's force evaluation needs beyond its constants: the run, its ejector force curve,
/// and the scenario's tables with this propagation's table scratch (none without tables).
#[derive(Clone, Copy)]
pub(crate) struct Parts<'a> {
    pub(super) run: &'a RunSetup,
    pub(super) curve: &'a EjectorCurve,
    pub(super) tables: Option<(&'a PreparedTables, &'a TableState)>,
}

impl Parts<'_> {
    /// Whether the run has terms beyond the linear coefficients that are evaluated lane by lane
    /// (tables, corrections, catalogue terms; the extension's are evaluated in the lanes).
    pub(super) fn has_extra_terms(&self) -> bool {
        self.tables.is_some()
            || self.run.coefficient_term_count > 0
            || !self.run.corrections.is_empty()
    }

    /// The tables' terms (section 3), the corrections, then the catalogue's extra terms
    /// (section 7), at the flow `flow` and lateral offset `lateral_m` (the extension's terms,
    /// section 11, come after these: [`super::term_lanes`]).
    #[inline(always)]
    pub(super) fn extra_terms(
        &self,
        flow: &Flow,
        lateral_m: f64,
        mut k: Coefficients,
    ) -> Coefficients {
        let run = self.run;
        if let Some((tables, state)) = self.tables {
            state.count_evaluation();
            if tables.runtime() {
                k = add_table_terms(run, tables, state, flow, lateral_m, k);
            }
        }
        if !run.corrections.is_empty() {
            k = add_corrections(run, flow, k);
        }
        if run.coefficient_term_count > 0 {
            k = run.add_coefficient_terms(*flow, k);
        }
        k
    }

    /// The pushing feet's total force \[N\] and its moment arm sum x_i F_i \[N m\] (section 3):
    /// F_i = fac_i F_ej(clamp(s_i, 0, stroke)), s_i = r_z + C_LB(2, 0) x_i, times the
    /// extension's factor.
    #[inline(always)]
    pub(super) fn ejector(&self, c20: f64, rz: f64, t_s: f64, on: [bool; 2]) -> (f64, f64) {
        let run = self.run;
        let (mut force_n, mut arm_force_n_m) = (0.0, 0.0);
        for (foot, _) in run.feet.iter().zip(on).filter(|(_, on)| *on) {
            let s_i = c20.mul_add(foot.x_m, rz);
            let mut f_i = foot.fac * self.curve.force_n(s_i.clamp(0.0, run.stroke_m));
            if !run.terms.is_empty() {
                f_i *= run.ejector_factor(t_s, s_i);
            }
            force_n += f_i;
            arm_force_n_m = foot.x_m.mul_add(f_i, arm_force_n_m);
        }
        (force_n, arm_force_n_m)
    }
}

/// Adds the tables' terms (docs/model.md section 3, "Tabulated coefficients"): the static
/// coefficients (CX = -CA) and the tabulated interference increments times their multipliers,
/// at the stage's local alpha and beta, distance from carriage and lateral offset `lateral_m`.
#[inline(always)]
fn add_table_terms(
    run: &RunSetup,
    tables: &PreparedTables,
    state: &TableState,
    flow: &Flow,
    lateral_m: f64,
    mut k: Coefficients,
) -> Coefficients {
    let (s, d) = tables.evaluate(
        state,
        &Inputs {
            alpha_rad: flow.alpha_rad,
            beta_rad: flow.beta_rad,
            distance_m: flow.distance_m,
            lateral_m,
        },
    );
    let m = &run.interference_multipliers;
    let c = tables.constants();
    // The static tables' values (late: they wait for alpha and beta) are added last.
    k.cx = m[0].mul_add(d[0], k.cx) - s[0];
    k.cy = m[1].mul_add(d[1], k.cy + c[1]) + s[1];
    k.cz = m[2].mul_add(d[2], k.cz + c[2]) + s[2];
    k.cl = m[3].mul_add(d[3], k.cl + c[3]) + s[3];
    k.cm = m[4].mul_add(d[4], k.cm + c[4]) + s[4];
    k.cn = m[5].mul_add(d[5], k.cn + c[5]) + s[5];
    k
}

/// Adds the corrections evaluated at each force evaluation (docs/update.md): a static
/// coefficient's as its table's (CX = -CA), an interference increment's times its multiplier,
/// at the stage's local alpha and beta and distance from carriage. Inlined, so that it is
/// compiled with the propagator's target features and the coefficients stay in registers: out
/// of line, without FMA each fused multiply-add was a call to the C library's `fma`, and the
/// call's arguments and result went through memory, together a fifth of an update's time
/// (`perf`, 2026-11-28).
#[inline(always)]
fn add_corrections(run: &RunSetup, flow: &Flow, mut k: Coefficients) -> Coefficients {
    let d = run
        .corrections
        .evaluate(flow.alpha_rad, flow.beta_rad, flow.distance_m);
    let m = &run.interference_multipliers;
    k.cx = m[0].mul_add(d[6], k.cx) - d[0];
    k.cy = m[1].mul_add(d[7], k.cy) + d[1];
    k.cz = m[2].mul_add(d[8], k.cz) + d[2];
    k.cl = m[3].mul_add(d[9], k.cl) + d[3];
    k.cm = m[4].mul_add(d[10], k.cm) + d[4];
    k.cn = m[5].mul_add(d[11], k.cn) + d[5];
    k
}

/// The six coefficients of every lane as arrays (CX, CY, CZ, Cl, Cm, Cn), each lane read and
/// written once through them (a lane written into a register's memory and read back whole
/// stalls the load).
#[inline(always)]
fn lanes_of<R: Real>(k: Coefficients<R>) -> [R::Array; 6] {
    [k.cx, k.cy, k.cz, k.cl, k.cm, k.cn].map(R::to_array)
}

/// Lane `i`'s coefficients from [`lanes_of`]'s arrays.
#[inline(always)]
fn lane_of<R: Real>(c: &[R::Array; 6], i: usize) -> Coefficients {
    let at = |j: usize| c[j].as_ref()[i];
    Coefficients {
        cx: at(0),
        cy: at(1),
        cz: at(2),
        cl: at(3),
        cm: at(4),
        cn: at(5),
    }
}

/// Puts lane `i`'s coefficients `k` back into [`lanes_of`]'s arrays.
#[inline(always)]
fn set_lane<R: Real>(c: &mut [R::Array; 6], i: usize, k: Coefficients) {
    for (j, v) in [k.cx, k.cy, k.cz, k.cl, k.cm, k.cn].into_iter().enumerate() {
        c[j].as_mut()[i] = v;
    }
}

/// The coefficients of every lane from [`lanes_of`]'s arrays.
#[inline(always)]
fn from_lanes<R: Real>(c: [R::Array; 6]) -> Coefficients<R> {
    let [cx, cy, cz, cl, cm, cn] = c.map(R::from_array);
    Coefficients {
        cx,
        cy,
        cz,
        cl,
        cm,
        cn,
    }
}
