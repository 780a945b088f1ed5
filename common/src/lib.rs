//! sepval's model library: the store-separation 6DOF model specified in the repository's
//! `docs/model.md`, the 17 factors and their binary encoding, telemetry files, goals, and the
//! batch evaluation interface shared by the searches, the coordinator and the workers. It
//! builds without any transport (those live in `sepval-transport`).
//!
//! Module map (mirrors `docs/model.md`):
//! - [`scenario`]: section 1, the scenario file and the embedded default;
//! - [`frames`]: section 2, quaternions, direction cosines, Euler angles;
//! - [`model`]: sections 2 and 3, forces, moments and equations of motion;
//! - [`propagator`]: section 3a, RK4 with located switching events and sampling;
//! - the factors and their encoding (section 4) are `sepval_core`'s, with the outcome of an
//!   evaluation, cancellation, atomic output files and checked input files;
//! - [`goals`]: section 5;
//! - [`telemetry`]: section 6;
//! - [`effects`]: section 7, the effect catalogue;
//! - [`table`], [`table_form`]: sections 1 and 3, tabulated coefficients and interference;
//! - [`correction`]: section 15, corrections of the data whose values a search estimates;
//! - [`noise`]: the measurement noise of the synthetic flight test (section 4);
//! - [`elementary`], [`lanes`]: section 9, sepval's own elementary functions (no C library),
//!   written once for one double and for four lanes.

#![deny(clippy::float_cmp)]

pub mod atmosphere;
pub mod correction;
mod effect_error;
pub mod effects;
pub mod elementary;
pub mod evaluation;
pub mod extension;
pub mod frames;
pub mod goals;
pub mod lanes;
pub mod model;
pub mod noise;
pub mod propagator;
pub mod scenario;
mod setup;
pub mod simulation;
pub mod synthetic;
pub mod table;
pub mod table_form;
pub mod telemetry;

/// Kernels and helpers inside the crate, re-exported for the model library's own tests
/// (`common/tests/model/units`), which live outside it so that it compiles once when tested.
/// Not part of the API.
#[doc(hidden)]
pub mod internals {
    pub use crate::elementary::trig::MEDIUM_MAX;
    pub use crate::elementary::{ASIN_A_MAX, ATAN_T_MAX, exp_dd};
    pub use crate::model::term_lanes::TermLanes;
    pub use crate::telemetry::lines::{BoundedLines, too_long};
    pub use crate::telemetry::outliers::{fit, unwrap_deg};
}

/// The version of the simulation's arithmetic, raised whenever a change moves any bit of a
/// result (recorded in checkpoints, so that one that no longer reproduces can say why):
/// 1, the host's C library for the elementary functions (wire protocol 3 and earlier); 2,
/// sepval's own (`elementary`, docs/model.md section 9; protocol 4); 3, stroke ends located to
/// the last bit rather than to a bracket of 1e-12 s (docs/model.md section 3a; protocol 8).
pub const ARITHMETIC_VERSION: u32 = 3;

pub use effects::EffectSet;
pub use goals::Goals;
pub use scenario::Scenario;
pub use sepval_core::factors::{Factor, FactorTable, Factors};
pub use simulation::Simulator;
pub use telemetry::Trajectory;
