//! The unit tests of `sepval_common::model::term_lanes`.

use sepval_common::extension::{Axis, Term, TermInput};
use sepval_common::extension::{MAX_TERMS, Regressor, TermSet};
use sepval_common::internals::TermLanes;
use sepval_common::lanes::F64x4;
use sepval_common::lanes::{Real, gather, lane};
use sepval_common::model::aero::{Coefficients, Flow};

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
        if lanes.all_alike() {
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
    assert_eq!(lanes.positions(), 2);
    assert_eq!(
        lanes.by_lane_regressors(0),
        None,
        "the first position is alike"
    );
    let Some(own) = lanes.by_lane_regressors(1) else {
        panic!("the second position differs between lanes")
    };
    assert_eq!(
        own,
        [
            Some(Regressor::Beta),
            Some(Regressor::Q),
            None,
            Some(Regressor::Beta)
        ]
    );
    assert!(lanes.all_aero());
    let none = gathered::<F64x4>(&[(&a, 1.0), (&TermSet::NONE, 1.0), (&a, 1.0), (&a, 1.0)]);
    assert!(!none.all_aero());
}
