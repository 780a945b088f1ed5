//! Aircraft interference decay with distance from carriage.
//!
//! Source: `docs/model.md` section 1:
//!
//! ```text
//! f(s) = (exp(-s/lambda) - exp(-s_end/lambda)) / (1 - exp(-s_end/lambda))   for s < s_end
//! f(s) = 0                                                                    for s >= s_end
//! ```
//!
//! Both exponentials are sepval's [`exp`] (docs/model.md section 9).

use crate::elementary::exp;
use crate::lanes::Real;

/// Precomputed constants of f(s) for one lambda and s_end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterferenceDecay {
    /// Decay length lambda \[m\].
    pub lambda_m: f64,
    /// Cut-off distance \[m\].
    pub s_end_m: f64,
    pub(crate) inv_lambda_per_m: f64,
    pub(crate) exp_end: f64,
    pub(crate) inv_denominator: f64,
}

impl InterferenceDecay {
    /// Constants for decay length `lambda_m` and cut-off `s_end_m`.
    pub fn new(lambda_m: f64, s_end_m: f64) -> Self {
        let exp_end = exp(-s_end_m / lambda_m);
        InterferenceDecay {
            lambda_m,
            s_end_m,
            inv_lambda_per_m: 1.0 / lambda_m,
            exp_end,
            inv_denominator: 1.0 / (1.0 - exp_end),
        }
    }

    /// f(s) for the CG distance `s_m` from carriage.
    #[inline(always)]
    pub fn factor(&self, s_m: f64) -> f64 {
        DecayLanes::gather(|_| self).factor(s_m)
    }
}

/// The constants of f(s) of one run per lane (see [`crate::lanes`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct DecayLanes<R> {
    s_end_m: R,
    inv_lambda_per_m: R,
    exp_end: R,
    inv_denominator: R,
}

impl<R: Real> DecayLanes<R> {
    /// The decays of one run per lane (`runs(i)`: lane `i`'s).
    #[inline(always)]
    pub(crate) fn gather<'a>(runs: impl Fn(usize) -> &'a InterferenceDecay) -> Self {
        let g = |f: fn(&InterferenceDecay) -> f64| crate::lanes::gather::<R>(|i| f(runs(i)));
        DecayLanes {
            s_end_m: g(|d| d.s_end_m),
            inv_lambda_per_m: g(|d| d.inv_lambda_per_m),
            exp_end: g(|d| d.exp_end),
            inv_denominator: g(|d| d.inv_denominator),
        }
    }

    /// f(s) for the CG distance `s_m` from carriage (0 from s_end on).
    #[inline(always)]
    pub(crate) fn factor(&self, s_m: R) -> R {
        let inside = (exp(-s_m * self.inv_lambda_per_m) - self.exp_end) * self.inv_denominator;
        R::select(s_m.lt(self.s_end_m), inside, R::splat(0.0))
    }
}
