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
pub(super) struct TermLanes<R: Real> {
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
    pub(super) fn gather<'a>(lanes: usize, set: impl Fn(usize) -> (&'a TermSet, f64)) -> Self {
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

    /// `k` with the terms' increments at `flow` (CX -= dCA; the others added), in every lane as
    /// the scalar evaluation adds its run's; a lane's `k` as it is when its run has no
    /// coefficient term.
    #[inline(always)]
    pub(super) fn add(&self, flow: &Flow<R>, k: Coefficients<R>) -> Coefficients<R> {
        if self.len == 0 {
            return k;
        }
        self.add_out_of_line(flow, k)
    }

    /// [`TermLanes::add`] for runs with terms: out of line, so that the regressors' `exp`,
    /// `sin` and `cos` are compiled once per lane type rather than into every copy of the
    /// propagators (a fresh build's compile time); on x86-64 hosts with AVX2 and FMA, a copy
    /// compiled for them (their Horner chains of fused multiply-adds are otherwise calls to the
    /// C library's `fma`: the same bits, fma being correctly rounded, at several times the
    /// cost).
    #[inline(never)]
    fn add_out_of_line(&self, flow: &Flow<R>, k: Coefficients<R>) -> Coefficients<R> {
        #[cfg(target_arch = "x86_64")]
        if super::host_has_fma() {
            // SAFETY: the CPU supports the features `add_fma` is compiled for.
            return unsafe { self.add_fma(flow, k) };
        }
        self.add_inline(flow, k)
    }

    /// [`TermLanes::add_out_of_line`] compiled for x86-64 hosts with AVX2 and FMA.
    ///
    /// # Safety
    /// The CPU must support AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn add_fma(&self, flow: &Flow<R>, k: Coefficients<R>) -> Coefficients<R> {
        self.add_inline(flow, k)
    }

    /// The body of [`TermLanes::add`].
    #[inline(always)]
    fn add_inline(&self, flow: &Flow<R>, k: Coefficients<R>) -> Coefficients<R> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::extension::{Axis, Term, TermInput};
    use crate::lanes::F64x4;

    /// The lanes of `sets` (one per lane of `R`).
    fn gathered<R: Real>(sets: &[(&TermSet, f64)]) -> TermLanes<R> {
        TermLanes::gather(sets.len(), |i| sets[i])
    }

    /// A small seeded generator (xorshift64*), uniform in [lo, hi).
    struct Draw(u64);

    impl Draw {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn within(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
        fn pick(&mut self, n: usize) -> usize {
            ((self.next() * n as f64) as usize).min(n - 1)
        }
    }

    /// A term of `kind` (a regressor and an axis that fits it) with drawn locator and
    /// coefficient, checked; `None` when the draw is outside the locator's domain.
    fn term(g: &mut Draw, regressor: Regressor, axis: Axis) -> Option<Term> {
        let locator = match regressor {
            Regressor::Window => {
                let t0 = g.within(0.0, 0.8);
                [t0, t0 + g.within(0.01, 0.2)]
            }
            Regressor::WindStep | Regressor::WindPulse => [g.within(0.0, 0.8), g.within(0.02, 0.3)],
            Regressor::Sin | Regressor::Cos => [g.within(1.0, 40.0), 0.0],
            Regressor::Step => [g.within(0.0, 0.9), 0.0],
            Regressor::Dm | Regressor::Dm2 => [g.within(0.5, 1.2), 0.0],
            _ => [g.within(0.1, 2.0), 0.0],
        };
        let t = Term {
            axis,
            regressor,
            locator,
            coefficient: g.within(-0.5, 0.5),
        };
        t.check().is_ok().then_some(t)
    }

    /// Four term sets: alike in kind (the same axes and regressors, drawn locators and
    /// coefficients, sine and cosine pairs sometimes sharing their frequency) or, one time in
    /// three, each drawn alone (some empty, some sharing only a first few terms).
    fn drawn_sets(g: &mut Draw) -> [TermSet; 4] {
        if g.next() < 1.0 / 3.0 {
            let n = 1 + g.pick(MAX_TERMS);
            let shared = alike_sets(g, n);
            return std::array::from_fn(|i| {
                let n = g.pick(MAX_TERMS + 1);
                let own = alike_sets(g, n)[0];
                let mut set = TermSet::NONE;
                let keep = g.pick(shared[i].len() + 1);
                for t in shared[i].iter().take(keep).chain(own.iter()) {
                    let _ = set.push(*t);
                }
                set
            });
        }
        let n = 1 + g.pick(MAX_TERMS);
        alike_sets(g, n)
    }

    /// Four term sets of `n` drawn kinds, alike.
    fn alike_sets(g: &mut Draw, n: usize) -> [TermSet; 4] {
        let kinds: Vec<(Regressor, Axis)> = (0..n)
            .map(|_| {
                loop {
                    let r = Regressor::ALL[g.pick(Regressor::ALL.len())].0;
                    let a = Axis::ALL[g.pick(6)];
                    if r.fits(a) {
                        break (r, a);
                    }
                }
            })
            .collect();
        std::array::from_fn(|_| {
            let mut set = TermSet::NONE;
            let mut last_frequency = None;
            for &(r, a) in &kinds {
                if let Some(mut t) = term(g, r, a) {
                    if matches!(r, Regressor::Sin | Regressor::Cos) {
                        match last_frequency {
                            Some(f) if g.next() < 0.5 => t.locator[0] = f,
                            _ => last_frequency = Some(t.locator[0]),
                        }
                    }
                    set.push(t).unwrap();
                }
            }
            set
        })
    }

    /// Each lane's flow, drawn (the distance sometimes past the cut-off, times near steps).
    fn flows(g: &mut Draw) -> [Flow; 4] {
        std::array::from_fn(|_| Flow {
            alpha_rad: g.within(-0.3, 0.3),
            beta_rad: g.within(-0.3, 0.3),
            p_hat: g.within(-0.05, 0.05),
            q_hat: g.within(-0.05, 0.05),
            r_hat: g.within(-0.05, 0.05),
            speed_m_s: g.within(150.0, 350.0),
            interference_factor: g.next(),
            t_s: g.within(0.0, 1.0),
            distance_m: g.within(0.0, 3.0),
            mach: g.within(0.5, 1.2),
        })
    }

    /// The scalar evaluation's coefficients: `k` with `set`'s increments, as
    /// the scalar force evaluation added them before the lanes did (`k.cx -= d[0]`, ...).
    fn scalar(set: &TermSet, flow: &Flow, s_end_m: f64, mut k: Coefficients) -> Coefficients {
        if !set.has_aero() {
            return k;
        }
        let d = set.aero_increments(&TermInput {
            t_s: flow.t_s,
            alpha_rad: flow.alpha_rad,
            beta_rad: flow.beta_rad,
            rates_hat: [flow.p_hat, flow.q_hat, flow.r_hat],
            mach: flow.mach,
            distance_m: flow.distance_m,
            s_end_m,
        });
        k.cx -= d[0];
        k.cy += d[1];
        k.cz += d[2];
        k.cl += d[3];
        k.cm += d[4];
        k.cn += d[5];
        k
    }

    fn bits(k: &Coefficients) -> [u64; 6] {
        [k.cx, k.cy, k.cz, k.cl, k.cm, k.cn].map(f64::to_bits)
    }

    #[test]
    fn every_lane_has_the_bits_of_its_runs_scalar_terms() {
        let mut g = Draw(0x9E37_79B9_7F4A_7C15);
        let (mut alike, mut mixed) = (0, 0);
        for _ in 0..3000 {
            let sets = drawn_sets(&mut g);
            let s_end: [f64; 4] = std::array::from_fn(|_| g.within(0.5, 2.5));
            let flow = flows(&mut g);
            // CY of -0: a lane with terms adds +0 to it (+0), a lane without leaves it.
            let k: [Coefficients; 4] = std::array::from_fn(|_| Coefficients {
                cx: g.within(-1.0, 1.0),
                cy: -0.0,
                cz: g.within(-1.0, 1.0),
                cl: 0.0,
                cm: g.within(-1.0, 1.0),
                cn: g.within(-1.0, 1.0),
            });
            let pairs: Vec<_> = (0..4).map(|i| (&sets[i], s_end[i])).collect();
            let lanes = gathered::<F64x4>(&pairs);
            if lanes
                .slots
                .iter()
                .flatten()
                .all(|s| matches!(s, Slot::Alike(_)))
            {
                alike += 1;
            } else {
                mixed += 1;
            }
            let g4 = |f: &dyn Fn(&Flow) -> f64| gather::<F64x4>(|i| f(&flow[i]));
            let flow4 = Flow {
                alpha_rad: g4(&|f| f.alpha_rad),
                beta_rad: g4(&|f| f.beta_rad),
                p_hat: g4(&|f| f.p_hat),
                q_hat: g4(&|f| f.q_hat),
                r_hat: g4(&|f| f.r_hat),
                speed_m_s: g4(&|f| f.speed_m_s),
                interference_factor: g4(&|f| f.interference_factor),
                t_s: g4(&|f| f.t_s),
                distance_m: g4(&|f| f.distance_m),
                mach: g4(&|f| f.mach),
            };
            let k4 = |f: &dyn Fn(&Coefficients) -> f64| gather::<F64x4>(|i| f(&k[i]));
            let out = lanes.add(
                &flow4,
                Coefficients {
                    cx: k4(&|k| k.cx),
                    cy: k4(&|k| k.cy),
                    cz: k4(&|k| k.cz),
                    cl: k4(&|k| k.cl),
                    cm: k4(&|k| k.cm),
                    cn: k4(&|k| k.cn),
                },
            );
            for i in 0..4 {
                let want = scalar(&sets[i], &flow[i], s_end[i], k[i]);
                let got = Coefficients {
                    cx: lane(out.cx, i),
                    cy: lane(out.cy, i),
                    cz: lane(out.cz, i),
                    cl: lane(out.cl, i),
                    cm: lane(out.cm, i),
                    cn: lane(out.cn, i),
                };
                assert_eq!(bits(&got), bits(&want), "lane {i} of {:?}", sets[i]);
                // One run alone (the scalar propagator's evaluation) gives the same bits.
                let one = gathered::<f64>(&[(&sets[i], s_end[i])]);
                assert_eq!(bits(&one.add(&flow[i], k[i])), bits(&want));
            }
        }
        assert!(alike > 1000 && mixed > 500, "{alike} alike, {mixed} mixed");
    }

    #[test]
    fn terms_alike_at_a_position_are_gathered_there_and_the_rest_lane_by_lane() {
        let t = |regressor, axis| Term {
            axis,
            regressor,
            locator: [0.5, 0.0],
            coefficient: 0.1,
        };
        let a = TermSet::of(&[t(Regressor::F, Axis::Cm), t(Regressor::Beta, Axis::Cn)]).unwrap();
        let b = TermSet::of(&[t(Regressor::F, Axis::Cm), t(Regressor::Q, Axis::Cn)]).unwrap();
        let c = TermSet::of(&[t(Regressor::F, Axis::Cm)]).unwrap();
        let lanes = gathered::<F64x4>(&[(&a, 1.0), (&b, 1.0), (&c, 1.0), (&a, 2.0)]);
        assert_eq!(lanes.len, 2);
        assert!(matches!(lanes.slots[0], Some(Slot::Alike(_))));
        let Some(Slot::ByLane(own)) = lanes.slots[1] else {
            panic!("the second position differs between lanes")
        };
        assert_eq!(
            own.map(|t| t.map(|t| t.regressor)),
            [
                Some(Regressor::Beta),
                Some(Regressor::Q),
                None,
                Some(Regressor::Beta)
            ]
        );
        assert!(lanes.all_aero);
        let none = gathered::<F64x4>(&[(&a, 1.0), (&TermSet::NONE, 1.0), (&a, 1.0), (&a, 1.0)]);
        assert!(!none.all_aero);
    }
}
