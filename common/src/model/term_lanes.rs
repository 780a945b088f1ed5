//! The extension's coefficient terms (docs/model.md section 11) of the four runs of a batch
//! evaluated in the lanes together where the runs carry the same terms on the same axes (every
//! candidate of one refit or one Jacobian: only coefficients and locators differ).
//!
//! Each lane has the bits of [`crate::extension::TermSet::aero_increments`] of its run, added as
//! the scalar force evaluation adds them (the rule of [`crate::lanes`]): the same regressors in
//! the same order, each a sequence of the same IEEE operations (the decay shape, the smooth
//! step and the oscillation's sine and cosine are the generic functions the scalar code calls),
//! and each lane's increments summed term by term from zero. What changes is the cost: a term's
//! `exp`, `sin` and `cos` are computed once for the four lanes, and the decay shape's value at
//! the cut-off, exp(-s_end / lambda), once per propagation rather than at every force
//! evaluation (the same value: the same operations on the same inputs). Where the runs' terms
//! differ in kind at a position, each lane's term there is computed in its own lane with the
//! scalar code ([`crate::extension::Term::regressor_value`]).

use std::f64::consts::TAU;

use crate::elementary::sin_cos;
use crate::extension::{
    MAX_TERMS, Regressor, Term, TermInput, TermSet, decay_end, decay_inside, step, wind,
};
use crate::lanes::{Real, gather, lane, mask};

use super::aero::{Coefficients, Flow};

/// One term of every lane: the same axis and regressor, each lane's locator and coefficient.
#[derive(Clone, Copy)]
struct LaneTerm<R: Real> {
    /// The coefficient's index (CA, CY, CZ, Cl, Cm, Cn).
    axis: usize,
    regressor: Regressor,
    /// The locator's two parts.
    a: R,
    b: R,
    coefficient: R,
    /// exp(-s_end / lambda) for a decay term (`a` = lambda); 0 otherwise.
    decay_end: R,
    /// For a sine or cosine: whether the previous pair computed has this argument in every
    /// lane (the same locator), so that its sine and cosine are read again.
    shares_pair: bool,
}

/// Lanes in a batch at most ([`crate::lanes::F64x4`]).
const MAX_LANES: usize = 4;

/// The terms at one position of the lanes' term lists.
#[derive(Clone, Copy)]
enum Slot<R: Real> {
    /// The same axis and regressor in every lane.
    Alike(LaneTerm<R>),
    /// Not alike: each lane's own term (`None` in a lane whose run has fewer terms).
    ByLane([Option<Term>; MAX_LANES]),
}

/// The coefficient terms of the lanes' runs: position by position, alike in kind (evaluated in
/// the lanes together) or not (each lane's own term, with the scalar code).
#[derive(Clone, Copy)]
pub struct TermLanes<R: Real> {
    len: usize,
    slots: [Option<Slot<R>>; MAX_TERMS],
    /// The interference cut-off distance of each lane's run \[m\].
    s_end_m: R,
    /// The lanes whose run has a coefficient term (the others' coefficients are left as they
    /// are, as the scalar evaluation leaves them).
    aero: R::Mask,
    /// Whether every lane has one.
    all_aero: bool,
}

impl<R: Real> TermLanes<R> {
    /// The terms of the `lanes` runs (`set(i)`: lane `i`'s terms and cut-off distance; one per
    /// lane of `R`), position by position: where every lane has the same axis and regressor,
    /// gathered into the lanes. Nothing is allocated (a propagation starts here).
    pub fn gather<'a>(lanes: usize, set: impl Fn(usize) -> (&'a TermSet, f64)) -> Self {
        // Each lane's coefficient terms, in order.
        let mut terms = [[None; MAX_TERMS]; MAX_LANES];
        let mut counts = [0; MAX_LANES];
        for (i, (own, count)) in terms.iter_mut().zip(&mut counts).enumerate().take(lanes) {
            for t in set(i).0.iter().filter(|t| t.axis.is_coefficient()) {
                own[*count] = Some(*t);
                *count += 1;
            }
        }
        let len = counts[..lanes].iter().copied().max().unwrap_or(0);
        let s_end_m = gather::<R>(|i| set(i).1);
        let mut slots = [None; MAX_TERMS];
        let mut last_pair: Option<R::Array> = None;
        for (j, slot) in slots.iter_mut().enumerate().take(len) {
            let kind = |i: usize| terms[i][j].map(|t| (t.axis, t.regressor));
            if !(1..lanes).all(|i| kind(i) == kind(0)) {
                *slot = Some(Slot::ByLane(std::array::from_fn(|i| terms[i][j])));
                continue;
            }
            let t = terms[0][j].expect("a position below the longest list, alike in every lane");
            let per_lane = |f: fn(&Term) -> f64| {
                gather::<R>(|i| f(&terms[i][j].expect("alike in every lane")))
            };
            let a = per_lane(|t| t.locator[0]);
            let decays = matches!(
                t.regressor,
                Regressor::F
                    | Regressor::FAlpha
                    | Regressor::FBeta
                    | Regressor::FP
                    | Regressor::FQ
                    | Regressor::FR
            );
            let mut shares_pair = false;
            if matches!(t.regressor, Regressor::Sin | Regressor::Cos) {
                let now = a.to_array();
                let same_bits = |p: &R::Array| {
                    let pairs = p.as_ref().iter().zip(now.as_ref());
                    pairs.into_iter().all(|(x, y)| x.to_bits() == y.to_bits())
                };
                shares_pair = last_pair.as_ref().is_some_and(same_bits);
                if !shares_pair {
                    last_pair = Some(now);
                }
            }
            *slot = Some(Slot::Alike(LaneTerm {
                axis: t.axis.index(),
                regressor: t.regressor,
                a,
                b: per_lane(|t| t.locator[1]),
                coefficient: per_lane(|t| t.coefficient),
                decay_end: if decays {
                    decay_end(s_end_m, a)
                } else {
                    R::splat(0.0)
                },
                shares_pair,
            }));
        }
        TermLanes {
            len,
            slots,
            s_end_m,
            aero: mask::<R>(|i| counts[i] > 0),
            all_aero: counts[..lanes].iter().all(|&n| n > 0),
        }
    }

    /// Positions of the lanes' term lists (the longest list's length).
    #[doc(hidden)]
    pub fn positions(&self) -> usize {
        self.len
    }

    /// Whether every position is alike in every lane.
    #[doc(hidden)]
    pub fn all_alike(&self) -> bool {
        self.slots[..self.len]
            .iter()
            .flatten()
            .all(|s| matches!(s, Slot::Alike(_)))
    }

    /// Each lane's regressor at position `j` where the lanes differ there (`None` where they
    /// are alike).
    #[doc(hidden)]
    pub fn by_lane_regressors(&self, j: usize) -> Option<[Option<Regressor>; MAX_LANES]> {
        match self.slots[j] {
            Some(Slot::ByLane(own)) => Some(own.map(|t| t.map(|t| t.regressor))),
            _ => None,
        }
    }

    /// Whether every lane's run has a coefficient term.
    #[doc(hidden)]
    pub fn all_aero(&self) -> bool {
        self.all_aero
    }

    /// `k` with the terms' increments at `flow` (CX -= dCA; the others added), in every lane as
    /// the scalar evaluation adds its run's; a lane's `k` as it is when its run has no
    /// coefficient term.
    ///
    /// Only the increments are formed out of line, from a copy of the flow: `k` and the caller's
    /// flow stay in registers. (Given to the out-of-line call, `k` lived in memory on every
    /// path, written a double at a time and read back whole by the path without terms, a load
    /// that waits for the stores at every force evaluation: 13 % of the scalar propagator's
    /// samples, `perf`, 2026-12-02; `simulate_default_event` 1.29 to 1.2 times 3b260f4's.)
    #[inline(always)]
    pub fn add(&self, flow: &Flow<R>, k: Coefficients<R>) -> Coefficients<R> {
        if self.len == 0 {
            return k;
        }
        let flow = *flow;
        let d = self.increments_out_of_line(&flow);
        let added = Coefficients {
            cx: k.cx - d[0],
            cy: k.cy + d[1],
            cz: k.cz + d[2],
            cl: k.cl + d[3],
            cm: k.cm + d[4],
            cn: k.cn + d[5],
        };
        if self.all_aero {
            return added;
        }
        let pick = |new: R, old: R| R::select(self.aero, new, old);
        Coefficients {
            cx: pick(added.cx, k.cx),
            cy: pick(added.cy, k.cy),
            cz: pick(added.cz, k.cz),
            cl: pick(added.cl, k.cl),
            cm: pick(added.cm, k.cm),
            cn: pick(added.cn, k.cn),
        }
    }

    /// The terms' increments at `flow` (dCA, dCY, dCZ, dCl, dCm, dCn, each summed term by term
    /// from zero), for [`TermLanes::add`]: out of line, so that the regressors' `exp`, `sin`
    /// and `cos` are compiled once per lane type rather than into every copy of the
    /// propagators (a fresh build's compile time); on x86-64 hosts with AVX2 and FMA, a copy
    /// compiled for them (their Horner chains of fused multiply-adds are otherwise calls to the
    /// C library's `fma`: the same bits, fma being correctly rounded, at several times the
    /// cost).
    #[inline(never)]
    fn increments_out_of_line(&self, flow: &Flow<R>) -> [R; 6] {
        #[cfg(target_arch = "x86_64")]
        if super::host_has_fma() {
            // SAFETY: the CPU supports the features `increments_fma` is compiled for.
            return unsafe { self.increments_fma(flow) };
        }
        self.increments(flow)
    }

    /// [`TermLanes::increments_out_of_line`] compiled for x86-64 hosts with AVX2 and FMA.
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn increments_fma(&self, flow: &Flow<R>) -> [R; 6] {
        self.increments(flow)
    }

    /// The body of [`TermLanes::increments_out_of_line`].
    #[inline(always)]
    fn increments(&self, flow: &Flow<R>) -> [R; 6] {
        let mut d = [R::splat(0.0); 6];
        let mut pair = (R::splat(0.0), R::splat(0.0));
        for slot in self.slots[..self.len].iter().flatten() {
            let t = match slot {
                Slot::Alike(t) => t,
                Slot::ByLane(terms) => {
                    d = by_lane(terms, flow, self.s_end_m, d);
                    continue;
                }
            };
            let v = match t.regressor {
                Regressor::Sin | Regressor::Cos => {
                    if !t.shares_pair {
                        pair = sin_cos(R::splat(TAU) * t.a * flow.t_s);
                    }
                    if t.regressor == Regressor::Sin {
                        pair.0
                    } else {
                        pair.1
                    }
                }
                _ => self.value(t, flow),
            };
            d[t.axis] = d[t.axis] + t.coefficient * v;
        }
        d
    }

    /// The regressor of `t` at `flow` (all but the oscillation's), as
    /// [`crate::extension::Term::regressor_value`] computes it.
    #[inline(always)]
    fn value(&self, t: &LaneTerm<R>, flow: &Flow<R>) -> R {
        let (alpha, beta) = (flow.alpha_rad, flow.beta_rad);
        // A macro, not a closure: a closure is a function of its own that the compiler may
        // leave out of line, compiled without the caller's FMA units.
        macro_rules! f {
            () => {
                R::select(
                    flow.distance_m.ge(self.s_end_m),
                    R::splat(0.0),
                    decay_inside(flow.distance_m, t.a, t.decay_end),
                )
            };
        }
        match t.regressor {
            Regressor::Alpha => alpha,
            Regressor::Beta => beta,
            Regressor::Alpha2 => alpha * alpha,
            Regressor::Beta2 => beta * beta,
            Regressor::Alpha3 => alpha * alpha * alpha,
            Regressor::Beta3 => beta * beta * beta,
            Regressor::AlphaBeta => alpha * beta,
            Regressor::P => flow.p_hat,
            Regressor::Q => flow.q_hat,
            Regressor::R => flow.r_hat,
            Regressor::F => f!(),
            Regressor::FAlpha => f!() * alpha,
            Regressor::FBeta => f!() * beta,
            Regressor::FP => f!() * flow.p_hat,
            Regressor::FQ => f!() * flow.q_hat,
            Regressor::FR => f!() * flow.r_hat,
            Regressor::Dm => flow.mach - t.a,
            Regressor::Dm2 => (flow.mach - t.a) * (flow.mach - t.a),
            Regressor::Step => step(flow.t_s, t.a),
            Regressor::Window => {
                let inside = R::select(flow.t_s.lt(t.b), R::splat(1.0), R::splat(0.0));
                R::select(flow.t_s.ge(t.a), inside, R::splat(0.0))
            }
            Regressor::Stroke | Regressor::Stroke2 => R::splat(0.0),
            // A pair computed for this term alone (`add` shares pairs).
            Regressor::Sin => sin_cos(R::splat(TAU) * t.a * flow.t_s).0,
            Regressor::Cos => sin_cos(R::splat(TAU) * t.a * flow.t_s).1,
            // A wind's shape on a coefficient (no term's check lets one through): lane by lane.
            Regressor::WindStep => {
                gather::<R>(|i| wind::onset(lane(flow.t_s, i), lane(t.a, i), lane(t.b, i)))
            }
            Regressor::WindPulse => {
                gather::<R>(|i| wind::pulse(lane(flow.t_s, i), lane(t.a, i), lane(t.b, i)))
            }
        }
    }
}

/// `d` with each lane's own term of `terms` added in that lane (its axis, its regressor by the
/// scalar code), lanes without one left as they are.
#[inline(always)]
fn by_lane<R: Real>(
    terms: &[Option<Term>; MAX_LANES],
    flow: &Flow<R>,
    s_end_m: R,
    d: [R; 6],
) -> [R; 6] {
    let mut d = d.map(R::to_array);
    for (i, term) in terms.iter().enumerate().take(R::LANES) {
        let Some(t) = term else { continue };
        let v = t.regressor_value(&TermInput {
            t_s: lane(flow.t_s, i),
            alpha_rad: lane(flow.alpha_rad, i),
            beta_rad: lane(flow.beta_rad, i),
            rates_hat: [
                lane(flow.p_hat, i),
                lane(flow.q_hat, i),
                lane(flow.r_hat, i),
            ],
            mach: lane(flow.mach, i),
            distance_m: lane(flow.distance_m, i),
            s_end_m: lane(s_end_m, i),
        });
        let slot = &mut d[t.axis.index()].as_mut()[i];
        *slot += t.coefficient * v;
    }
    d.map(R::from_array)
}
