//! The equations of motion (docs/model.md sections 2 and 3), written once over [`Real`]: for one
//! run ([`EquationsOfMotion`], `f64`) and for one run per SIMD lane ([`LaneEquations`],
//! [`F64x4`]), with the same operations in the same order, so that a lane's derivative has the
//! bits of the scalar derivative of its run (the rule of [`crate::lanes`]).
//!
//! ```text
//! dr/dt     = v
//! dv/dt     = g_L + (C_LB F_aero_B + F_ej_L) / m
//! dq/dt     = 0.5 q (x) (0, omega)
//! domega/dt = I^-1 (M_B - omega x (I omega))
//! ```
//!
//! What the lanes share is straight-line arithmetic on the stage's state: the flow (section 3),
//! the linear coefficients, the moments, the kinematics. What differs from run to run in its
//! structure (the ejector feet's modes and their force table, the scenario's tables, the
//! catalogue's coefficient terms, the extension's terms: section 3, 7 and 11) runs lane by lane
//! through the scalar code of each lane's run ([`Parts`]), and its result is put back into the
//! lane; a lane whose feet do not push keeps its value by a select, never by arithmetic. Both
//! keep the rule. A wind (section 11.2) is evaluated the same way, lane by lane, and subtracted
//! from the air-relative velocity only when a lane has one (the others subtract +0.0, which
//! changes no bit).

use crate::elementary::atan2_asin;
use crate::lanes::{F64x4, Real, gather, lane, mask};
use crate::table::TableState;

use super::aero::{AeroConstants, Flow};
use super::by_lane::{Parts, alike_fields, flowfield_lanes, lane_by_lane_terms, wind_lanes};
use super::flowfield_lanes::{FieldLanes, FieldSums};
use super::interference::DecayLanes;
use super::term_lanes::TermLanes;
use super::{Dcm, EjectorCurve, Model, RunSetup, STATE_LEN, StateVector};

/// The constants of the force evaluation, one run per lane of `R`, with the products of the
/// run's constants formed once, when a propagation starts.
#[derive(Clone, Copy)]
pub(crate) struct Constants<R: Real> {
    /// 0.5 rho S / m [1/m]: times V^2 and a force coefficient, an acceleration.
    accel_per_speed2: R,
    /// 0.5 rho S d \[kg\]: times V^2 and a moment coefficient, a moment.
    moment_per_speed2: R,
    /// x_ref / d: moving the moments to the CG is Cm -= CZ x_ref / d, Cn += CY x_ref / d.
    reference_arm: R,
    v_aircraft_air_l_m_s: [R; 3],
    gravity_l_m_s2: [R; 3],
    half_diameter_m: R,
    inv_speed_of_sound_s_m: R,
    inv_mass_per_kg: R,
    decay: DecayLanes<R>,
    aero: AeroConstants<R>,
    interference_increments: [R; 6],
    ejector_direction_l: [R; 3],
    inertia_principal_differences: [R; 3],
    inertia_principal_inv: [R; 3],
    inertia_kg_m2: [[R; 3]; 3],
    inertia_inv: [[R; 3]; 3],
    /// Lanes whose inertia tensor is diagonal.
    diagonal: R::Mask,
    all_diagonal: bool,
    any_diagonal: bool,
    /// Whether any lane has terms beyond the linear coefficients that are evaluated lane by
    /// lane (the tables', the corrections', the catalogue's).
    extra_terms: bool,
    /// The lanes' extension terms (section 11).
    terms: TermLanes<R>,
    /// Whether any lane has a wind (section 11.2: the air's velocity in L).
    wind: bool,
    /// The lanes' aircraft flowfields (section 3b), when every lane has one with the same
    /// number of stations (every run of one scenario).
    field: Option<FieldLanes<R>>,
    /// Whether some lanes have a field but not all alike (each is then evaluated alone).
    field_by_lane: bool,
    /// Whether any lane has the decay increments of section 3 (a run without a field): with a
    /// field in every lane, f(s) is not formed (section 3b: the increments are 0, so the factor
    /// they multiply is taken as 0, the same bits).
    decay_used: bool,
}

impl<R: Real> Constants<R> {
    /// The constants of `parts` (one per lane of `R`).
    fn gather(parts: &[Parts]) -> Self {
        let runs = |i: usize| parts[i].run;
        let g = |f: &dyn Fn(&RunSetup) -> f64| gather::<R>(|i| f(runs(i)));
        let g3 =
            |f: &dyn Fn(&RunSetup) -> [f64; 3]| [0, 1, 2].map(|j| gather::<R>(|i| f(runs(i))[j]));
        let g33 = |f: &dyn Fn(&RunSetup) -> nalgebra::Matrix3<f64>| {
            [0, 1, 2].map(|r| [0, 1, 2].map(|c| gather::<R>(|i| f(runs(i))[(r, c)])))
        };
        let alike = alike_fields(parts);
        let terms = TermLanes::gather(parts.len(), |i| (&runs(i).terms, runs(i).decay.s_end_m));
        Constants {
            accel_per_speed2: g(&|r| r.half_rho_area * r.inv_mass_per_kg),
            moment_per_speed2: g(&|r| r.half_rho_area * r.diameter_m),
            reference_arm: g(&|r| r.aero_reference_x_m / r.diameter_m),
            v_aircraft_air_l_m_s: g3(&|r| r.v_aircraft_air_l_m_s.into()),
            gravity_l_m_s2: g3(&|r| r.gravity_l_m_s2.into()),
            half_diameter_m: g(&|r| r.half_diameter_m),
            inv_speed_of_sound_s_m: g(&|r| r.inv_speed_of_sound_s_m),
            inv_mass_per_kg: g(&|r| r.inv_mass_per_kg),
            decay: DecayLanes::gather(|i| &runs(i).decay),
            aero: AeroConstants::gather(|i| &runs(i).aero),
            interference_increments: [0, 1, 2, 3, 4, 5]
                .map(|j| gather::<R>(|i| runs(i).interference_increments[j])),
            ejector_direction_l: g3(&|r| r.ejector_direction_l.into()),
            inertia_principal_differences: g3(&|r| r.inertia_principal_differences),
            inertia_principal_inv: g3(&|r| r.inertia_principal_inv),
            inertia_kg_m2: g33(&|r| r.inertia_kg_m2),
            inertia_inv: g33(&|r| r.inertia_inv),
            diagonal: mask::<R>(|i| runs(i).inertia_diagonal),
            all_diagonal: parts.iter().all(|p| p.run.inertia_diagonal),
            any_diagonal: parts.iter().any(|p| p.run.inertia_diagonal),
            extra_terms: parts.iter().any(Parts::has_extra_terms),
            terms,
            wind: parts.iter().any(|p| p.run.terms.has_wind()),
            field: alike.then(|| {
                FieldLanes::gather(
                    |i| runs(i).flowfield.as_ref().expect("every lane has a field"),
                    g(&|r| r.aero_reference_x_m),
                )
            }),
            field_by_lane: !alike && parts.iter().any(|p| p.run.flowfield.is_some()),
            decay_used: parts.iter().any(|p| p.run.flowfield.is_none()),
        }
    }
}

/// The equations of motion of one run (docs/model.md sections 2 and 3), with the products of the
/// run's constants that the force evaluation needs formed once, when a propagation starts.
#[derive(Clone, Copy)]
pub struct EquationsOfMotion<'a> {
    parts: Parts<'a>,
    constants: Constants<f64>,
}

impl<'a> EquationsOfMotion<'a> {
    /// The equations of `run` with the ejector force curve `curve`, for a scenario without
    /// tables (the flow alone does not depend on them; for the forces of a scenario with
    /// tables, use [`EquationsOfMotion::with_tables`]).
    pub fn new(run: &'a RunSetup, curve: &'a EjectorCurve) -> Self {
        Self::of(Parts {
            run,
            curve,
            tables: None,
        })
    }

    /// The equations of `run` for `model` (its ejector curve and tables), keeping cursors and
    /// excursion counts in `state`.
    pub fn with_tables(run: &'a RunSetup, model: &'a Model, state: &'a TableState) -> Self {
        Self::of(Parts {
            run,
            curve: &model.curve,
            tables: model
                .tables
                .in_evaluation()
                .then_some((&model.tables, state)),
        })
    }

    fn of(parts: Parts<'a>) -> Self {
        EquationsOfMotion {
            parts,
            constants: Constants::gather(&[parts]),
        }
    }

    /// The parts of this run, for a [`LaneEquations`].
    pub(crate) fn parts(&self) -> Parts<'a> {
        self.parts
    }

    /// The flow the store sees in state `x` at time `t_s` (docs/model.md section 3): what the
    /// catalogue's and the extension's terms read, for reports and diagnoses.
    pub fn flow(&self, x: &StateVector, t_s: f64) -> Flow {
        flow_frame::<_, false>(&self.constants, std::slice::from_ref(&self.parts), x, t_s).0
    }

    /// Whether the run takes the contract's force evaluation and nothing beside it: the decay
    /// increments, no field, no wind and no term beyond the linear coefficients (the default
    /// event, and every run of a fit without extension terms or tables). Such a run may use
    /// [`EquationsOfMotion::derivative_plain`].
    pub(crate) fn plain(&self) -> bool {
        let c = &self.constants;
        !c.extra_terms
            && !c.wind
            && c.terms.positions() == 0
            && c.field.is_none()
            && !c.field_by_lane
            && c.decay_used
    }

    /// The state derivative with the ejector feet in the given modes (`on[i]`: foot i
    /// pushes).
    ///
    /// This is the hot path (four calls per RK4 step): straight-line scalar arithmetic on the
    /// stage's own state, one direction-cosine matrix, inlined elementary functions, no
    /// allocation. Each block of the generic `derivative` behind it cites the docs/model.md line it implements.
    ///
    /// Products are summed with fused multiply-adds (`mul_add`, one rounding): the same bits
    /// whether the host has an FMA unit or not (see [`crate::propagator`] for the dispatch).
    #[inline(always)]
    pub fn derivative(&self, x: &StateVector, t_s: f64, on: [bool; 2]) -> StateVector {
        derivative::<_, false>(
            &self.constants,
            std::slice::from_ref(&self.parts),
            x,
            t_s,
            &[on],
        )
    }

    /// [`EquationsOfMotion::derivative`] of a run that is [`EquationsOfMotion::plain`], compiled
    /// without the tests and paths of what it does not have: the same operations in the same
    /// order, so the same bits. (Those tests at every force evaluation, and the values they
    /// kept live, cost the scalar propagator about 10 % of its instructions: callgrind,
    /// 2026-12-06.)
    #[inline(always)]
    pub(crate) fn derivative_plain(&self, x: &StateVector, t_s: f64, on: [bool; 2]) -> StateVector {
        derivative::<_, true>(
            &self.constants,
            std::slice::from_ref(&self.parts),
            x,
            t_s,
            &[on],
        )
    }
}

/// The equations of motion of four runs, one per lane of an [`F64x4`].
pub(crate) struct LaneEquations<'a> {
    parts: [Parts<'a>; 4],
    constants: Constants<F64x4>,
}

impl<'a> LaneEquations<'a> {
    /// The equations of four runs (a run may appear in several lanes).
    pub(crate) fn new(parts: [Parts<'a>; 4]) -> Self {
        LaneEquations {
            constants: Constants::gather(&parts),
            parts,
        }
    }

    /// The derivatives of the four lanes' states `x` at time `t_s`, lane `i`'s feet in the
    /// modes `on[i]`: lane `i` has the bits of [`EquationsOfMotion::derivative`] of its run.
    #[inline(always)]
    pub(crate) fn derivative(
        &self,
        x: &[F64x4; STATE_LEN],
        t_s: F64x4,
        on: &[[bool; 2]; 4],
    ) -> [F64x4; STATE_LEN] {
        derivative::<_, false>(&self.constants, &self.parts, x, t_s, on)
    }
}

/// The flow of a stage (section 3) with its direction cosines and V^2: the first half of
/// [`derivative`], inlined there (`parts`: one per lane, for their winds; `PLAIN`: the lanes'
/// runs are [`EquationsOfMotion::plain`], so the tests for a field and a wind are left out).
#[inline(always)]
fn flow_frame<R: Real, const PLAIN: bool>(
    c: &Constants<R>,
    parts: &[Parts],
    x: &[R; STATE_LEN],
    t_s: R,
) -> (Flow<R>, Dcm<R>, R, Option<FieldSums<R>>) {
    let [rx, ry, rz, vx, vy, vz, q0, q1, q2, q3, p, q, r] = *x;
    // Section 1: interference decay with s = |r|. First: its input is ready long before
    // the stage's velocity and attitude, so the exponential overlaps the rest.
    // A field in every lane: the increments are 0 (section 3b), so f(s) is not formed; 0 in its
    // place leaves every coefficient's bits as they are (0 f = 0 for any f >= 0).
    let distance_m = dot([rx, ry, rz], [rx, ry, rz]).sqrt();
    let f_s = if PLAIN || c.decay_used {
        c.decay.factor(distance_m)
    } else {
        R::splat(0.0)
    };
    // Section 2: C_LB of the stage's quaternion scaled to unit length, kept as
    // |q|^2 C_LB and 1 / |q|^2 (the scale is applied where it is needed, off the chain
    // from the stage's state to the flow angles).
    let dcm = Dcm::from_quaternion(q0, q1, q2, q3);
    // Section 3b: the flowfield's sums over the stations need only the position and the
    // attitude; formed here, they run beside the flow angles' chain below.
    // (An `if let`, not `Option::map`: a closure left out of line would compile its fused
    // multiply-adds without the propagator's target features.)
    let field = if PLAIN {
        None
    } else if let Some(f) = &c.field {
        let axis_l = [
            dcm.m[0][0] * dcm.inv_n2,
            dcm.m[1][0] * dcm.inv_n2,
            dcm.m[2][0] * dcm.inv_n2,
        ];
        Some(f.sums([rx, ry, rz], axis_l))
    } else {
        None
    };

    // Section 2: v_air = v + V_inf (cos a cos b, sin b, sin a cos b) in L;
    // (u, v, w) = C_BL v_air, here |q|^2 (u, v, w).
    let va = &c.v_aircraft_air_l_m_s;
    let mut air = [vx + va[0], vy + va[1], vz + va[2]];
    // Section 11.2: a wind w_L moves the air, v_air -= w_L. Only when a lane has one (a lane
    // without subtracts +0.0, which leaves every value's bits as they are), so a run without
    // wind takes the contract's operations and no other.
    if !PLAIN && c.wind {
        let w = wind_lanes(parts, t_s);
        air = [air[0] - w[0], air[1] - w[1], air[2] - w[2]];
    }
    let [u_s, v_s, w_s] = dcm.to_body_scaled(air);
    // Section 3: V = |v_air| (rotation-invariant, so taken in L), qbar = 0.5 rho V^2,
    // alpha = atan2(w, u) (the scale |q|^2 cancels), beta = asin(v / V) with
    // (v / V)^2 = (|q|^2 v)^2 / (|q|^4 V^2), p^ = p d / 2V (likewise q^, r^).
    let speed2 = dot(air, air);
    let inv_speed = R::splat(1.0) / speed2.sqrt();
    let (alpha, beta) = atan2_asin(
        w_s,
        u_s,
        v_s * (dcm.inv_n2 * inv_speed),
        v_s * v_s,
        speed2 * (dcm.n2 * dcm.n2),
    );
    let rate_scale = c.half_diameter_m * inv_speed;
    let flow = Flow {
        alpha_rad: alpha,
        beta_rad: beta,
        p_hat: p * rate_scale,
        q_hat: q * rate_scale,
        r_hat: r * rate_scale,
        speed_m_s: speed2 * inv_speed,
        interference_factor: f_s,
        t_s,
        distance_m,
        mach: (speed2 * inv_speed) * c.inv_speed_of_sound_s_m,
    };
    (flow, dcm, speed2, field)
}

/// The state derivative (docs/model.md sections 2 and 3) of one run per lane of `R` (`parts`
/// and `on`: one per lane; `PLAIN`: their runs are [`EquationsOfMotion::plain`], so only the
/// contract's terms are tested for and added).
#[inline(always)]
fn derivative<R: Real, const PLAIN: bool>(
    c: &Constants<R>,
    parts: &[Parts],
    x: &[R; STATE_LEN],
    t_s: R,
    on: &[[bool; 2]],
) -> [R; STATE_LEN] {
    let (flow, dcm, speed2, field) = flow_frame::<R, PLAIN>(c, parts, x, t_s);
    let [rx, ry, rz, vx, vy, vz, q0, q1, q2, q3, p, q, r] = *x;
    // Section 3: the six coefficients, then the tables' terms and the catalogue's extra terms
    // (section 7), lane by lane, and the extension's (section 11), in the lanes together.
    let mut k = c.aero.coefficients(&flow, &c.interference_increments);
    if !PLAIN && c.extra_terms {
        k = lane_by_lane_terms(parts, &flow, ry, k);
    }
    if !PLAIN {
        k = c.terms.add(&flow, k);
    }
    // Section 3b: the aircraft's flowfield, station by station, after every other term.
    if let (Some(f), Some(sums)) = (&c.field, field) {
        k = sums.add_loads(f, flow.alpha_rad, flow.beta_rad, k);
    } else if !PLAIN && c.field_by_lane {
        let axis_l = [
            dcm.m[0][0] * dcm.inv_n2,
            dcm.m[1][0] * dcm.inv_n2,
            dcm.m[2][0] * dcm.inv_n2,
        ];
        k = flowfield_lanes(parts, [rx, ry, rz], axis_l, &flow, k);
    }
    // Section 3: M_aero_B = qbar S d (Cl, Cm, Cn), moved from the moment reference point
    // (x_ref, 0, 0) to the CG: M += (x_ref, 0, 0) x F_aero_B.
    let moment_scale = c.moment_per_speed2 * speed2;
    let arm = c.reference_arm;
    let mx = moment_scale * k.cl;
    let mut my = moment_scale * (-arm).mul_add(k.cz, k.cm);
    let mut mz = moment_scale * arm.mul_add(k.cy, k.cn);
    // Sections 2 and 3: dv/dt = g_L + (C_LB F_aero_B + F_ej_L) / m, F_aero_B = qbar S
    // (CX, CY, CZ), with 1 / (m |q|^2) folded into the body force.
    let body_scale = (c.accel_per_speed2 * speed2) * dcm.inv_n2;
    let [mut ax, mut ay, mut az] = dcm.to_launch_scaled(
        [body_scale * k.cx, body_scale * k.cy, body_scale * k.cz],
        c.gravity_l_m_s2,
    );

    // Section 3: each foot pushes along its L direction d with
    // F_i = fac_i F_ej(clamp(s_i, 0, stroke)), s_i = (r + C_LB (x_i, 0, 0))_z; its moment
    // about the CG is (x_i, 0, 0) x (C_BL F_i d) = F_i x_i (0, -(C_BL d)_z, (C_BL d)_y).
    // Lanes whose feet do not push keep their values (a select).
    let mut any_pushing = false;
    for o in on {
        any_pushing |= o[0] || o[1];
    }
    if any_pushing {
        let c20 = dcm.m[2][0] * dcm.inv_n2;
        let (mut force_n, mut arm_force_n_m) = (R::splat(0.0).to_array(), R::splat(0.0).to_array());
        for (i, (part, &on)) in parts.iter().zip(on).enumerate() {
            if on[0] || on[1] {
                let (f, a) = part.ejector(lane(c20, i), lane(rz, i), lane(t_s, i), on);
                force_n.as_mut()[i] = f;
                arm_force_n_m.as_mut()[i] = a;
            }
        }
        let (force_n, arm_force_n_m) = (R::from_array(force_n), R::from_array(arm_force_n_m));
        let pushing = mask::<R>(|i| on[i][0] || on[i][1]);
        let d = c.ejector_direction_l;
        let accel = force_n * c.inv_mass_per_kg;
        ax = R::select(pushing, accel.mul_add(d[0], ax), ax);
        ay = R::select(pushing, accel.mul_add(d[1], ay), ay);
        az = R::select(pushing, accel.mul_add(d[2], az), az);
        let [_, by, bz] = dcm.to_body_scaled(d);
        let arm_force = arm_force_n_m * dcm.inv_n2;
        my = R::select(pushing, (-arm_force).mul_add(bz, my), my);
        mz = R::select(pushing, arm_force.mul_add(by, mz), mz);
    }

    // Section 2: dq/dt = 0.5 q (x) (0, omega).
    let [dq0, dq1, dq2, dq3] = quaternion_rate([q0, q1, q2, q3], p, q, r);
    // Section 2: domega/dt = I^-1 (M_B - omega x (I omega)).
    let [dp, dq, dr] = angular_acceleration(c, [mx, my, mz], [p, q, r]);
    [vx, vy, vz, ax, ay, az, dq0, dq1, dq2, dq3, dp, dq, dr]
}

/// I^-1 (M - omega x (I omega)) (docs/model.md section 2), with a short path for the diagonal
/// tensor of the contract.
#[inline(always)]
fn angular_acceleration<R: Real>(c: &Constants<R>, m: [R; 3], w: [R; 3]) -> [R; 3] {
    let [p, q, r] = w;
    if c.all_diagonal {
        return diagonal_angular_acceleration(c, m, w);
    }
    let i = &c.inertia_kg_m2;
    let h = [dot(i[0], w), dot(i[1], w), dot(i[2], w)];
    let t = [
        m[0] - q.mul_add(h[2], -r * h[1]),
        m[1] - r.mul_add(h[0], -p * h[2]),
        m[2] - p.mul_add(h[1], -q * h[0]),
    ];
    let j = &c.inertia_inv;
    let general = [dot(j[0], t), dot(j[1], t), dot(j[2], t)];
    if !c.any_diagonal {
        return general;
    }
    let d = diagonal_angular_acceleration(c, m, w);
    [
        R::select(c.diagonal, d[0], general[0]),
        R::select(c.diagonal, d[1], general[1]),
        R::select(c.diagonal, d[2], general[2]),
    ]
}

/// [`angular_acceleration`] for a diagonal tensor: omega x (I omega) = ((Izz - Iyy) q r,
/// (Ixx - Izz) r p, (Iyy - Ixx) p q).
#[inline(always)]
fn diagonal_angular_acceleration<R: Real>(c: &Constants<R>, m: [R; 3], w: [R; 3]) -> [R; 3] {
    let [p, q, r] = w;
    let [dyz, dzx, dxy] = c.inertia_principal_differences;
    let [jx, jy, jz] = c.inertia_principal_inv;
    [
        (-dyz * q).mul_add(r, m[0]) * jx,
        (-dzx * r).mul_add(p, m[1]) * jy,
        (-dxy * p).mul_add(q, m[2]) * jz,
    ]
}

/// a . b with fused multiply-adds.
#[inline(always)]
pub(crate) fn dot<R: Real>(a: [R; 3], b: [R; 3]) -> R {
    a[0].mul_add(b[0], a[1].mul_add(b[1], a[2] * b[2]))
}

/// Quaternion kinematics `dq/dt = 0.5 q (x) (0, omega)` (docs/model.md section 2), as
/// [`crate::frames::quaternion_rate`] with fused multiply-adds.
#[inline(always)]
fn quaternion_rate<R: Real>(q: [R; 4], p: R, qq: R, r: R) -> [R; 4] {
    let [q0, q1, q2, q3] = q;
    // Halving is exact: 0.5 (a p + b q + c r) = a (p/2) + b (q/2) + c (r/2).
    let half = R::splat(0.5);
    let (hp, hq, hr) = (half * p, half * qq, half * r);
    [
        -q1.mul_add(hp, q2.mul_add(hq, q3 * hr)),
        q0.mul_add(hp, q2.mul_add(hr, -q3 * hq)),
        q0.mul_add(hq, q3.mul_add(hp, -q1 * hr)),
        q0.mul_add(hr, q1.mul_add(hq, -q2 * hp)),
    ]
}
