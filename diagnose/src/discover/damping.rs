//! The moment axes' own damping terms (`Cl p d/2V`, `Cm q d/2V`, `Cn r d/2V`): a damping term
//! feeds back the rate it drives, so a change of it comparable to the model's own damping moves
//! the store's time constant, and the screening's column, linear about the baseline's rates,
//! can miss it entirely (docs/discovery.md 11.5, step 4c). Two consequences:
//!
//! - a refit of a damping term may move it as far as the model's own damping either way, at
//!   least ([`floor`]: the refits' bounds are ten times the located coefficient's size,
//!   `Picked::free_terms`, and the regression's coefficient about the baseline can be far too
//!   small);
//! - at discovery's first step each axis's own damping is refitted as a contender of the rival
//!   search whatever it screens (`mimic::dampings`).
//!
//! Roll damping 0.41 times the model's (the first-release cases drawn from seed
//! 0x2545_F491_4F6C_DD1D, case 7; 2026-12-07) screened at X 1.2 while its effect moved the
//! chi-square by some 80; refitted within the regression's bounds it gained 8.5, within the
//! model's own damping it fits as well as the answer (a rolling moment due to sideslip, BIC
//! -0.5), which was named with `Cl q d/2V` its only rival before.

use sepval_common::extension::{Axis, Regressor};

use super::search::Search;
use crate::library::Entry;

/// The moment axes and their own rates.
const DAMPINGS: [(Axis, Regressor); 3] = [
    (Axis::Cl, Regressor::P),
    (Axis::Cm, Regressor::Q),
    (Axis::Cn, Regressor::R),
];

/// Whether `entry` is a moment axis's own damping.
pub(super) fn is_damping(entry: &Entry) -> bool {
    DAMPINGS.contains(&(entry.axis(), entry.terms[0].regressor))
}

/// The largest size of the model's own damping on moment `axis` (per rad of the rate times
/// d/2V) over the job's releases, each at its flight Mach.
fn own_damping(search: &Search, axis: Axis) -> f64 {
    search
        .job
        .events()
        .iter()
        .map(|e| {
            let a = &e.simulator.model().aero_at_mach;
            match axis {
                Axis::Cl => a.cl_p_per_rad,
                Axis::Cm => a.cm_q_per_rad,
                _ => a.cn_r_per_rad,
            }
            .abs()
        })
        .fold(0.0, f64::max)
}

/// A located damping entry's coefficient raised to a tenth of the model's own damping in
/// size (its sign kept), so that its refit's bounds reach the whole of it; other entries as
/// they are.
pub(super) fn floor(search: &Search, entry: &mut Entry) {
    if !is_damping(entry) {
        return;
    }
    let own = own_damping(search, entry.axis());
    let t = &mut entry.terms[0];
    t.coefficient = raised(t.coefficient, own);
}

/// `coefficient` at least a tenth of `own` in size, its sign kept (0 and NaN become positive).
fn raised(coefficient: f64, own: f64) -> f64 {
    let size = coefficient.abs().max(own / 10.0);
    if coefficient < 0.0 { -size } else { size }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The three own dampings and nothing else; the start's size raised to a tenth of the
    /// model's damping (the default's Cl_p is -40, so bounds of at least +-40) with its sign,
    /// a larger one kept.
    #[test]
    fn only_an_axiss_own_rate_is_its_damping_and_its_bounds_reach_the_models() {
        assert!(is_damping(&Entry::one(Axis::Cl, Regressor::P)));
        assert!(is_damping(&Entry::one(Axis::Cm, Regressor::Q)));
        assert!(is_damping(&Entry::one(Axis::Cn, Regressor::R)));
        assert!(!is_damping(&Entry::one(Axis::Cl, Regressor::Q)));
        assert!(!is_damping(&Entry::one(Axis::Cm, Regressor::P)));
        assert!(!is_damping(&Entry::one(Axis::Cm, Regressor::FQ)));
        for (c, want) in [(0.3, 4.0), (-0.3, -4.0), (0.0, 4.0), (-9.0, -9.0)] {
            let got = raised(c, 40.0);
            assert!((got - want).abs() < 1e-12, "{c}: {got}");
        }
    }
}
