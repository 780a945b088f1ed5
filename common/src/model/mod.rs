//! The store-separation model: one scenario set up once ([`Model`]), one run's constants
//! ([`RunSetup`]: factors and effects applied), and the equations of motion
//! ([`EquationsOfMotion`], in `equations.rs`: once for one run and for one run per SIMD lane).
//!
//! Source: `docs/model.md` sections 1 to 3. The tree mirrors the physics:
//! [`ejector`] (force-versus-displacement table), [`interference`] (decay with distance),
//! [`aero`] (coefficients and the flow state the catalogue's terms see).
//!
//! Equations of motion (docs/model.md section 2), implemented in
//! [`EquationsOfMotion::derivative`] (and [`RunSetup::derivative`] for one state):
//!
//! ```text
//! dr/dt     = v
//! dv/dt     = g_L + (C_LB F_aero_B + F_ej_L) / m
//! dq/dt     = 0.5 * q (x) (0, omega)
//! domega/dt = I^-1 (M_B - omega x (I omega))
//! ```
//!
//! Generalisations of the contract, used by the effect catalogue (section 7) and neutral by
//! default so the baseline is exactly the contract: a full inertia tensor (`inertia_product_xz`),
//! an aerodynamic moment reference point away from the CG (`cg_offset`), an ejector force
//! direction in L (`ejector_cant`), an ejector start time (`ejector_delay`), initial rates
//! (`release_rates`), and the measurement knobs (time offset, attitude bias, tracked point).
//! Model extensions (section 11) add coefficient increments and ejector factors, and a wind
//! (the `wind` family, [`crate::extension::wind`]): the air's velocity in L, subtracted from
//! the store's air-relative velocity before anything is read from it; a run without one takes
//! exactly the contract's operations.

pub mod aero;
mod by_lane;
mod dcm;
pub mod ejector;
mod equations;
pub mod flowfield;
pub mod flowfield_grid;
mod flowfield_lanes;
mod flowfield_shape;
pub mod interference;
pub mod tables;
pub(crate) mod term_lanes;

pub use dcm::Dcm;
pub use equations::EquationsOfMotion;
pub(crate) use equations::{LaneEquations, dot};

use nalgebra::{Matrix3, Vector3};

use crate::atmosphere::isa_troposphere;
use crate::correction::{Correction, CorrectionError, CorrectionRun};
use crate::effect_error::{EffectError, MAX_EFFECT_PARAMS};
use crate::elementary::{cos, sin};
use crate::extension::{TermError, TermSet};
use crate::scenario::Scenario;
use crate::table::PreparedTables;
use sepval_core::factors::{Factor, FactorError, Factors};
use tables::AeroAtMach;

pub use aero::{Coefficients, Flow};
pub use ejector::EjectorCurve;
pub use flowfield::FlowfieldRun;
pub use flowfield_grid::FieldGrid;
pub use interference::InterferenceDecay;

/// Standard gravity [m/s^2] (docs/model.md section 1).
pub const G_M_S2: f64 = 9.80665;

/// Length of the state vector: r (3), v (3), q (4), omega (3).
pub const STATE_LEN: usize = 13;

/// The state `[r_L (m), v_L (m/s), q (scalar first), omega_B (rad/s)]` (docs/model.md section 2).
pub type StateVector = [f64; STATE_LEN];

/// Errors building a run.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum ModelError {
    /// A factor is non-finite or out of bounds.
    #[error(transparent)]
    Factor(#[from] FactorError),
    /// An effect's parameters are invalid.
    #[error(transparent)]
    Effect(#[from] EffectError),
    /// Extension terms that cannot be run.
    #[error(transparent)]
    Term(#[from] TermError),
    /// Correction values that do not fit the scenario's corrections.
    #[error(transparent)]
    Correction(#[from] CorrectionError),
    /// The resulting inertia tensor is not positive definite.
    #[error("inertia tensor is not positive definite (xz block determinant {det_kg2_m4} <= 0)")]
    InertiaNotPositiveDefinite {
        /// Ixx Izz - Ixz^2.
        det_kg2_m4: f64,
    },
}

/// One scenario, set up once: every constant derived from its file (docs/model.md section 1).
#[derive(Debug, Clone)]
pub struct Model {
    scenario: Scenario,
    /// Mass \[kg\].
    pub mass_kg: f64,
    /// Nominal principal inertias (Ixx, Iyy, Izz) [kg m^2].
    pub inertia_kg_m2: [f64; 3],
    /// Reference diameter \[m\].
    pub diameter_m: f64,
    /// Reference area pi d^2 / 4 [m^2].
    pub area_m2: f64,
    /// Body x of the (forward, aft) ejector feet relative to the nominal CG \[m\].
    pub feet_x_m: [f64; 2],
    /// Ejector stroke \[m\].
    pub stroke_m: f64,
    /// Nominal ejector force curve.
    pub curve: EjectorCurve,
    /// Air density at the flight condition [kg/m^3].
    pub density_kg_m3: f64,
    /// Free-stream speed V_inf = Mach a [m/s].
    pub v_inf_m_s: f64,
    /// Speed of sound at the flight condition [m/s].
    pub speed_of_sound_m_s: f64,
    /// The scenario's model extension (docs/discovery.md), in every run.
    pub extension: TermSet,
    /// Aircraft velocity relative to the air in L:
    /// V_inf (cos a cos b, sin b, sin a cos b) (docs/model.md section 2).
    pub v_aircraft_air_l_m_s: Vector3<f64>,
    /// Gravity in L: g (-sin theta_a, 0, cos theta_a), theta_a = alpha + gamma.
    pub gravity_l_m_s2: Vector3<f64>,
    /// Fixed RK4 step \[s\].
    pub dt_s: f64,
    /// Initial velocity relative to L [m/s].
    pub initial_velocity_m_s: Vector3<f64>,
    /// Initial body rates [rad/s].
    pub initial_rates_rad_s: Vector3<f64>,
    /// The freestream database's constants at the flight Mach (docs/model.md section 3).
    pub aero_at_mach: AeroAtMach,
    /// The constant interference increments at carriage (dCX0, ..., dCn0; 0 where tabulated).
    pub interference_at_carriage: [f64; 6],
    /// The scenario's tables, ready for the force evaluation (docs/model.md section 3).
    pub tables: PreparedTables,
    /// The aircraft's flowfield as tables over position (docs/model.md section 3b), when the
    /// scenario gives it so.
    pub field_grid: Option<std::sync::Arc<FieldGrid>>,
    /// The scenario's corrections (docs/update.md), whose values candidates carry.
    pub corrections: Vec<Correction>,
}

impl Model {
    /// Sets up a validated scenario.
    pub fn new(scenario: &Scenario) -> Model {
        let s = &scenario.store;
        let f = &scenario.flight;
        let air = isa_troposphere(f.altitude_m);
        let v_inf = f.mach * air.speed_of_sound_m_s;
        let (a, b) = (f.alpha_deg.to_radians(), f.beta_deg.to_radians());
        let theta_a = (f.alpha_deg + f.gamma_deg).to_radians();
        let (aero_at_mach, interference_at_carriage, tables) = tables::prepare(scenario);
        Model {
            scenario: scenario.clone(),
            mass_kg: s.mass_kg,
            inertia_kg_m2: [s.ixx_kg_m2, s.iyy_kg_m2, s.izz_kg_m2],
            diameter_m: s.diameter_m,
            area_m2: std::f64::consts::PI * s.diameter_m * s.diameter_m / 4.0,
            feet_x_m: [s.fwd_foot_x_m, s.aft_foot_x_m],
            stroke_m: s.stroke_m,
            curve: EjectorCurve::new(&scenario.ejector.curve),
            density_kg_m3: air.density_kg_m3,
            v_inf_m_s: v_inf,
            speed_of_sound_m_s: air.speed_of_sound_m_s,
            extension: scenario.extension_terms(),
            v_aircraft_air_l_m_s: Vector3::new(
                v_inf * cos(a) * cos(b),
                v_inf * sin(b),
                v_inf * sin(a) * cos(b),
            ),
            gravity_l_m_s2: Vector3::new(-G_M_S2 * sin(theta_a), 0.0, G_M_S2 * cos(theta_a)),
            dt_s: scenario.integrator.dt_s,
            initial_velocity_m_s: Vector3::from(scenario.initial.velocity_m_s),
            initial_rates_rad_s: Vector3::from(scenario.initial.rates_deg_s.map(f64::to_radians)),
            aero_at_mach,
            interference_at_carriage,
            tables,
            field_grid: scenario
                .flowfield
                .as_ref()
                .and_then(FieldGrid::of)
                .map(std::sync::Arc::new),
            corrections: scenario.corrections(),
        }
    }

    /// The scenario this model was set up from.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }
}

/// An extra term of the aerodynamic coefficients contributed by an effect (for example
/// `Cl += Cl_beta beta`), called once per force evaluation.
pub type CoefficientFn = fn(&[f64; MAX_EFFECT_PARAMS], &Flow, &mut Coefficients);

/// Most coefficient terms one run can carry.
pub const MAX_COEFFICIENT_TERMS: usize = 8;

/// One ejector foot of a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Foot {
    /// Body x of the foot relative to the (true) CG \[m\].
    pub x_m: f64,
    /// Force multiplier (fwdfac or aftfac).
    pub fac: f64,
}

/// The constants of one run: the model with one factor set and one effect set applied.
/// Built per evaluation (cheap, no allocation) and then used for every force evaluation.
#[derive(Clone)]
pub struct RunSetup {
    /// 1 / m [1/kg].
    pub inv_mass_per_kg: f64,
    /// Inertia tensor about the CG, body axes [kg m^2].
    pub inertia_kg_m2: Matrix3<f64>,
    /// Its inverse (set when the run is built, after the effects).
    pub inertia_inv: Matrix3<f64>,
    /// Whether the tensor is diagonal (the contract's case; a shorter path).
    pub inertia_diagonal: bool,
    /// Its diagonal (Ixx, Iyy, Izz) [kg m^2].
    pub inertia_principal: [f64; 3],
    /// Reciprocals of the diagonal (valid when `inertia_diagonal`).
    pub inertia_principal_inv: [f64; 3],
    /// (Izz - Iyy, Ixx - Izz, Iyy - Ixx), for omega x (I omega) with a diagonal tensor.
    pub inertia_principal_differences: [f64; 3],
    /// 0.5 rho S [kg/m]: multiplied by V^2 gives qbar S.
    pub half_rho_area: f64,
    /// Reference diameter d \[m\].
    pub diameter_m: f64,
    /// d / 2 \[m\], for the non-dimensional rates.
    pub half_diameter_m: f64,
    /// Aircraft velocity relative to the air in L [m/s].
    pub v_aircraft_air_l_m_s: Vector3<f64>,
    /// Gravity in L [m/s^2].
    pub gravity_l_m_s2: Vector3<f64>,
    /// Freestream coefficients with the factor offsets applied.
    pub aero: aero::AeroConstants,
    /// Interference increments times their multipliers: (dCX, dCY, dCZ, dCl, dCm, dCn).
    pub interference_increments: [f64; 6],
    /// The interference multipliers (caintfac, ..., cnintfac), for tabulated increments.
    pub interference_multipliers: [f64; 6],
    /// Interference decay f(s).
    pub decay: InterferenceDecay,
    /// The aircraft's flowfield (docs/model.md section 3b), when the scenario has one.
    pub flowfield: Option<FlowfieldRun>,
    /// Forward and aft feet.
    pub feet: [Foot; 2],
    /// Ejector stroke \[m\].
    pub stroke_m: f64,
    /// Unit direction of each foot's force in L (docs/model.md: +z of L).
    pub ejector_direction_l: Vector3<f64>,
    /// Time at which the feet start pushing \[s\] (0: at release).
    pub ejector_start_s: f64,
    /// Body x of the aerodynamic moment reference point relative to the CG \[m\] (0: the CG);
    /// moments about the CG are M_ref + (x_ref, 0, 0) x F_aero.
    pub aero_reference_x_m: f64,
    /// Initial velocity relative to L [m/s].
    pub initial_velocity_m_s: Vector3<f64>,
    /// Initial body rates [rad/s].
    pub initial_rates_rad_s: Vector3<f64>,
    /// Extra coefficient terms (effects), `coefficient_term_count` of them in use.
    pub coefficient_terms: [(CoefficientFn, [f64; MAX_EFFECT_PARAMS]); MAX_COEFFICIENT_TERMS],
    /// Number of entries of `coefficient_terms` in use.
    pub coefficient_term_count: usize,
    /// Measurement: the sample labelled t shows the store at t + offset \[s\].
    pub time_offset_s: f64,
    /// Measurement: constant Euler angle biases (roll, pitch, yaw) \[rad\].
    pub attitude_bias_rad: [f64; 3],
    /// Measurement: the tracked body point relative to the CG, body axes \[m\].
    pub tracked_point_b_m: Vector3<f64>,
    /// Model-extension terms (the scenario's and the candidate's; docs/discovery.md).
    pub terms: TermSet,
    /// 1 / a, the speed of sound's reciprocal [s/m] (the store's Mach number is V / a).
    pub inv_speed_of_sound_s_m: f64,
    /// The corrections evaluated at each force evaluation (docs/update.md; none
    /// without correction values).
    pub corrections: CorrectionRun,
}

fn no_term(_: &[f64; MAX_EFFECT_PARAMS], _: &Flow, _: &mut Coefficients) {}

impl RunSetup {
    /// The run of `model` with `factors`, before any effect is applied (factors need only be
    /// finite): what [`RunSetup::new`] and its kin (`crate::setup`) start from, then finish
    /// with [`RunSetup::finish`].
    pub(crate) fn base(model: &Model, factors: &Factors) -> Result<Self, ModelError> {
        for (i, &value) in factors.0.iter().enumerate() {
            if !value.is_finite() {
                return Err(FactorError::NotFinite {
                    name: sepval_core::factors::Factor::NAMES[i],
                    value,
                }
                .into());
            }
        }
        let sc = &model.scenario;
        let fx = |f: Factor| factors.get(f);
        let ia = model.inertia_kg_m2;
        let inertia = Matrix3::from_diagonal(&Vector3::new(
            ia[0] * fx(Factor::Xinerfac),
            ia[1] * fx(Factor::Yinerfac),
            ia[2] * fx(Factor::Zinerfac),
        ));
        let i = &model.interference_at_carriage;
        let run = RunSetup {
            inv_mass_per_kg: 1.0 / model.mass_kg,
            inertia_kg_m2: inertia,
            inertia_inv: Matrix3::identity(),
            inertia_diagonal: true,
            inertia_principal: [0.0; 3],
            inertia_principal_inv: [0.0; 3],
            inertia_principal_differences: [0.0; 3],
            half_rho_area: 0.5 * model.density_kg_m3 * model.area_m2,
            diameter_m: model.diameter_m,
            half_diameter_m: 0.5 * model.diameter_m,
            v_aircraft_air_l_m_s: model.v_aircraft_air_l_m_s,
            gravity_l_m_s2: model.gravity_l_m_s2,
            aero: aero::AeroConstants::new(&model.aero_at_mach, factors),
            interference_increments: [
                fx(Factor::Caintfac) * i[0],
                fx(Factor::Cyintfac) * i[1],
                fx(Factor::Czintfac) * i[2],
                fx(Factor::Clintfac) * i[3],
                fx(Factor::Cmintfac) * i[4],
                fx(Factor::Cnintfac) * i[5],
            ],
            interference_multipliers: [
                fx(Factor::Caintfac),
                fx(Factor::Cyintfac),
                fx(Factor::Czintfac),
                fx(Factor::Clintfac),
                fx(Factor::Cmintfac),
                fx(Factor::Cnintfac),
            ],
            decay: InterferenceDecay::new(sc.interference.lambda_m, sc.interference.s_end_m),
            flowfield: sc.flowfield.as_ref().map(|f| {
                FlowfieldRun::new(
                    f,
                    model.field_grid.as_ref(),
                    &model.aero_at_mach,
                    model.diameter_m,
                    sc.flight.mach,
                    sc.flight.alpha_deg,
                    factors,
                )
            }),
            feet: [
                Foot {
                    x_m: model.feet_x_m[0],
                    fac: fx(Factor::Fwdfac),
                },
                Foot {
                    x_m: model.feet_x_m[1],
                    fac: fx(Factor::Aftfac),
                },
            ],
            stroke_m: model.stroke_m,
            ejector_direction_l: Vector3::new(0.0, 0.0, 1.0),
            ejector_start_s: 0.0,
            aero_reference_x_m: 0.0,
            initial_velocity_m_s: model.initial_velocity_m_s,
            initial_rates_rad_s: model.initial_rates_rad_s,
            coefficient_terms: [(no_term as CoefficientFn, [0.0; MAX_EFFECT_PARAMS]);
                MAX_COEFFICIENT_TERMS],
            coefficient_term_count: 0,
            time_offset_s: 0.0,
            attitude_bias_rad: [0.0; 3],
            tracked_point_b_m: Vector3::zeros(),
            terms: model.extension,
            inv_speed_of_sound_s_m: 1.0 / model.speed_of_sound_m_s,
            corrections: CorrectionRun::NONE,
        };
        Ok(run)
    }

    /// The run once its effects are applied: the inertia tensor's inverse and its diagonal
    /// (the effects may have changed the tensor).
    pub(crate) fn finish(mut self) -> Result<Self, ModelError> {
        let run = &mut self;
        run.inertia_inv = invert_inertia(&run.inertia_kg_m2)?;
        run.inertia_diagonal = is_diagonal(&run.inertia_kg_m2);
        let i = &run.inertia_kg_m2;
        run.inertia_principal = [i[(0, 0)], i[(1, 1)], i[(2, 2)]];
        run.inertia_principal_inv = run.inertia_principal.map(|d| 1.0 / d);
        let [ixx, iyy, izz] = run.inertia_principal;
        run.inertia_principal_differences = [izz - iyy, ixx - izz, iyy - ixx];
        Ok(self)
    }

    /// Adds a coefficient term (used by effects).
    pub fn add_coefficient_term(
        &mut self,
        term: CoefficientFn,
        params: [f64; MAX_EFFECT_PARAMS],
    ) -> Result<(), EffectError> {
        if self.coefficient_term_count == MAX_COEFFICIENT_TERMS {
            return Err(EffectError::TooManyCoefficientTerms {
                max: MAX_COEFFICIENT_TERMS,
            });
        }
        self.coefficient_terms[self.coefficient_term_count] = (term, params);
        self.coefficient_term_count += 1;
        Ok(())
    }

    /// The initial state: carriage position and attitude, initial velocity and rates.
    pub fn initial_state(&self) -> StateVector {
        let v = &self.initial_velocity_m_s;
        let w = &self.initial_rates_rad_s;
        [
            0.0, 0.0, 0.0, v.x, v.y, v.z, 1.0, 0.0, 0.0, 0.0, w.x, w.y, w.z,
        ]
    }

    /// Stroke displacement of foot `i`: the L-frame z of its body point (docs/model.md section 3),
    /// `s_i = (r + C_LB (x_i, 0, 0))_z`, given `c20 = C_LB[2][0]`.
    #[inline(always)]
    pub fn foot_displacement_m(&self, i: usize, r_z: f64, c20: f64) -> f64 {
        r_z + c20 * self.feet[i].x_m
    }

    /// The state derivative (docs/model.md sections 2 and 3) with the ejector feet in the given
    /// modes (`on[i]`: foot i pushes). See [`EquationsOfMotion::derivative`], which the
    /// propagator calls with the run's constant products formed once.
    #[inline(always)]
    pub fn derivative(&self, curve: &EjectorCurve, x: &StateVector, on: [bool; 2]) -> StateVector {
        EquationsOfMotion::new(self, curve).derivative(x, 0.0, on)
    }

    /// [`RunSetup::derivative`] at time `t_s` (time matters to extension terms only).
    pub fn derivative_at(
        &self,
        curve: &EjectorCurve,
        x: &StateVector,
        t_s: f64,
        on: [bool; 2],
    ) -> StateVector {
        EquationsOfMotion::new(self, curve).derivative(x, t_s, on)
    }

    /// Adds the catalogue's coefficient terms (section 7). Out of line, so that the flow and
    /// the coefficients go through memory only when there are terms.
    #[inline(never)]
    fn add_coefficient_terms(&self, flow: Flow, mut k: Coefficients) -> Coefficients {
        for (term, params) in &self.coefficient_terms[..self.coefficient_term_count] {
            term(params, &flow, &mut k);
        }
        k
    }

    /// The extension's factor on a foot's force at displacement `s_i` (section 11). Out of line
    /// (only runs with an ejector term call it), so on x86-64 hosts with AVX2 and FMA, a copy
    /// compiled for them: the regressors' `exp` is a Horner chain of fused multiply-adds, each
    /// otherwise a call to the C library's `fma` (the same bits either way, fma being correctly
    /// rounded).
    #[inline(never)]
    fn ejector_factor(&self, t_s: f64, s_i: f64) -> f64 {
        if !self.terms.has_ejector() {
            return 1.0;
        }
        let sigma = s_i.clamp(0.0, self.stroke_m) / self.stroke_m;
        #[cfg(target_arch = "x86_64")]
        if host_has_fma() {
            // SAFETY: the CPU supports the features `ejector_factor_fma` is compiled for.
            return unsafe { ejector_factor_fma(&self.terms, t_s, sigma) };
        }
        self.terms.ejector_factor(t_s, sigma)
    }
}

/// Whether this x86-64 host has AVX2 and FMA units (detected once, then a cached flag).
#[cfg(target_arch = "x86_64")]
#[inline]
pub(crate) fn host_has_fma() -> bool {
    std::arch::is_x86_feature_detected!("fma") && std::arch::is_x86_feature_detected!("avx2")
}

/// The extension's wind in L at `t_s` ([`TermSet::wind_l_m_s`]), compiled for AVX2 and FMA
/// where the host has them, as [`RunSetup::ejector_factor`].
#[inline(never)]
pub(crate) fn wind_l_m_s(terms: &TermSet, t_s: f64) -> [f64; 3] {
    #[cfg(target_arch = "x86_64")]
    if host_has_fma() {
        // SAFETY: the CPU supports the features `wind_l_m_s_fma` is compiled for.
        return unsafe { wind_l_m_s_fma(terms, t_s) };
    }
    terms.wind_l_m_s(t_s)
}

/// [`TermSet::wind_l_m_s`] compiled for x86-64 hosts with AVX2 and FMA.
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn wind_l_m_s_fma(terms: &TermSet, t_s: f64) -> [f64; 3] {
    terms.wind_l_m_s(t_s)
}

/// [`TermSet::ejector_factor`] compiled for x86-64 hosts with AVX2 and FMA.
///
/// # Safety
/// The CPU must support AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn ejector_factor_fma(terms: &TermSet, t_s: f64, sigma: f64) -> f64 {
    terms.ejector_factor(t_s, sigma)
}

/// Inverse of a symmetric inertia tensor, refusing one that is not positive definite.
fn invert_inertia(i: &Matrix3<f64>) -> Result<Matrix3<f64>, ModelError> {
    // Principal minors (Sylvester's criterion) for a clear message in the common xz case.
    let det_xz = i[(0, 0)] * i[(2, 2)] - i[(0, 2)] * i[(2, 0)];
    if det_xz <= 0.0 || i.determinant() <= 0.0 || i[(0, 0)] <= 0.0 {
        return Err(ModelError::InertiaNotPositiveDefinite { det_kg2_m4: det_xz });
    }
    if is_diagonal(i) {
        // Exact reciprocals for the diagonal tensor of the contract.
        return Ok(Matrix3::from_diagonal(&i.diagonal().map(|d| 1.0 / d)));
    }
    i.try_inverse()
        .ok_or(ModelError::InertiaNotPositiveDefinite { det_kg2_m4: det_xz })
}

fn is_diagonal(i: &Matrix3<f64>) -> bool {
    (0..3).all(|r| (0..3).all(|c| r == c || i[(r, c)] == 0.0))
}
