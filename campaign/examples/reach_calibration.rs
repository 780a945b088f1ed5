//! The calibration of the reach rule's RHO (docs/model.md, "Model form away from the
//! releases"): a model fitted (`ga+lm`) to one noisy release of a truth with a hidden cause,
//! inside the catalogue (an effect) or outside it (an extension term), predicts the truth at
//! conditions 0.5 to 4 units of reach away; at every sample and channel where the store has
//! moved (its motion at least 5 % of the channel's largest), the error of the fitted model's
//! trajectory is compared with the band 1.96 RHO r m_c(t). Prints the share of points covered
//! for several RHO and the quantiles of the RHO each point needs. The factors' band and the
//! discrepancy at the releases are left out, so the coverage is a lower bound.
//!
//! Run: `cargo run --release -p sepval-campaign --example reach_calibration [SEED_BASE]`.

use std::sync::Arc;

use sepval_common::effects::EffectSet;
use sepval_common::evaluation::{Event, InProcess, Job};
use sepval_common::extension::{TermRecord, parse_extension};
use sepval_common::scenario::Scenario;
use sepval_common::simulation::{Simulator, sample_times};
use sepval_common::synthetic::synthetic_flight_test;
use sepval_core::factors::Factors;
use sepval_fit::sigma::Sigma;
use sepval_fit::space::ParamSpace;
use sepval_fit::{FitOptions, run_fit};
use sepval_run::inputs::InputsRecord;
use sepval_solve::ga::GaSettings;
use sepval_solve::lm::LmSettings;
use sepval_solve::run::NoProgress;

/// A hidden cause: effects, or an extension term (TOML), with its name.
struct Cause {
    name: &'static str,
    effects: &'static str,
    extension: &'static str,
}

const CAUSES: [Cause; 6] = [
    Cause {
        name: "pitch_stiffness_cubic",
        effects: "pitch_stiffness_cubic=-400",
        extension: "",
    },
    Cause {
        name: "interference_decay",
        effects: "interference_decay=2.0",
        extension: "",
    },
    Cause {
        name: "cg_offset",
        effects: "cg_offset=0.08",
        extension: "",
    },
    Cause {
        name: "Cm on Mach (outside)",
        effects: "",
        extension: "[[term]]\naxis = \"Cm\"\nfamily = \"mach\"\nregressor = \"dm\"\nmach0 = 0.8\ncoefficient = -0.6\n",
    },
    Cause {
        name: "CZ on alpha^2 (outside)",
        effects: "",
        extension: "[[term]]\naxis = \"CZ\"\nfamily = \"flow_angle\"\nregressor = \"alpha2\"\ncoefficient = -3.0\n",
    },
    Cause {
        name: "Cm interference on q (outside)",
        effects: "",
        extension: "[[term]]\naxis = \"Cm\"\nfamily = \"interference_flow_angle\"\nregressor = \"f_q\"\nlambda_m = 0.6\ncoefficient = -20.0\n",
    },
];

fn at(base: &Scenario, mach: f64, alpha_deg: f64) -> Scenario {
    let mut s = base.clone();
    s.flight.mach = mach;
    s.flight.alpha_deg = alpha_deg;
    s
}

fn main() {
    let seed_base: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(100);
    let model = Scenario::embedded_default();
    let times = sample_times(model.integrator.t_end_s, model.integrator.rate_hz);
    let fitted_at = [(0.8, 0.0), (0.95, 4.0)];
    let predicted_at = [
        (0.85, 0.0),
        (0.9, 2.0),
        (1.0, 0.0),
        (0.7, -4.0),
        (0.6, 6.0),
        (1.1, 8.0),
    ];
    let mut needed: Vec<(f64, f64)> = Vec::new(); // (reach, rho needed)
    let mut per_channel: Vec<Vec<f64>> = vec![Vec::new(); 6];
    for (ci, cause) in CAUSES.iter().enumerate() {
        let mut truth = model.clone();
        if !cause.extension.is_empty() {
            let text = format!("format = \"sepval-extension/1\"\n\n{}", cause.extension);
            let terms = parse_extension(&text, "calibration").expect("the term parses");
            truth.extension.extend(terms.iter().map(TermRecord::of));
        }
        let mut effects = EffectSet::NONE;
        if !cause.effects.is_empty() {
            effects.push_spec(cause.effects).expect("the effect parses");
        }
        for (ai, &(ma, aa)) in fitted_at.iter().enumerate() {
            let seed = seed_base + 10 * ci as u64 + ai as u64;
            let data = synthetic_flight_test(
                &Simulator::new(&at(&truth, ma, aa)),
                &Factors::TRUTH,
                &effects,
                &times,
                Some(seed),
            )
            .expect("the truth flies");
            let job = Job::new(vec![Event {
                name: "A".into(),
                simulator: Simulator::new(&at(&model, ma, aa)),
                data,
            }])
            .expect("a job");
            let out =
                std::env::temp_dir().join(format!("sepval-reach-{}-{seed}", std::process::id()));
            let inputs = InputsRecord {
                data: Vec::new(),
                scenario: None,
                extension: None,
                outliers: Default::default(),
            };
            let ga = GaSettings {
                generations: 10,
                seed,
                ..GaSettings::default()
            };
            let sigma = Sigma::resolve(&job, None, None).expect("sigma");
            let options = FitOptions::baseline(ga, sigma, &LmSettings::default(), &out, inputs);
            let mut ev = InProcess::new(Arc::new(job.clone()), 2);
            let fit = run_fit(&options, &mut ev, &mut NoProgress).expect("the fit runs");
            let _ = std::fs::remove_dir_all(&out);
            let x = fit.refined.expect("ga+lm refines").x;
            let space = ParamSpace::new(job.factor_table(), &EffectSet::NONE);
            let c = space.candidate(&x).expect("a candidate");
            let a_flight = at(&model, ma, aa).flight;
            for &(mb, ab) in &predicted_at {
                let b = at(&model, mb, ab);
                let r = sepval_run::domain::reach(&[&a_flight], &b.flight);
                if r < 0.25 {
                    continue;
                }
                let (Ok(t), Ok(y)) = (
                    synthetic_flight_test(
                        &Simulator::new(&at(&truth, mb, ab)),
                        &Factors::TRUTH,
                        &effects,
                        &times,
                        None,
                    ),
                    Simulator::new(&b).simulate(&c.factors, &EffectSet::NONE, &times),
                ) else {
                    println!("{}: diverged at Mach {mb}, alpha {ab}", cause.name);
                    continue;
                };
                let ch = |tr: &sepval_common::telemetry::Trajectory, k: usize, c: usize| {
                    if c < 3 {
                        tr.pos_m[k][c]
                    } else {
                        tr.att_deg[k][c - 3]
                    }
                };
                for (c, channel) in per_channel.iter_mut().enumerate() {
                    let motion: Vec<f64> = (0..times.len())
                        .map(|k| (ch(&y, k, c) - ch(&y, 0, c)).abs())
                        .collect();
                    let top = motion.iter().copied().fold(0.0, f64::max);
                    for (k, &m) in motion.iter().enumerate() {
                        if m >= 0.05 * top && m > 0.0 {
                            let e = (ch(&t, k, c) - ch(&y, k, c)).abs();
                            needed.push((r, e / (1.96 * r * m)));
                            channel.push(e / (1.96 * r * m));
                        }
                    }
                }
            }
        }
    }
    let mut rhos: Vec<f64> = needed.iter().map(|p| p.1).collect();
    rhos.sort_by(f64::total_cmp);
    let q = |p: f64| rhos[((p * (rhos.len() - 1) as f64).round()) as usize];
    println!("points: {} (seed base {seed_base})", rhos.len());
    println!(
        "RHO needed: median {:.4}, 90 % {:.4}, 95 % {:.4}, 99 % {:.4}",
        q(0.5),
        q(0.9),
        q(0.95),
        q(0.99)
    );
    for rho in [0.02, 0.05, 0.1, 0.15, 0.2, 0.3] {
        let covered = rhos.iter().filter(|&&v| v <= rho).count();
        println!(
            "RHO {rho}: covers {:.3} of the points",
            covered as f64 / rhos.len() as f64
        );
    }
    for (c, v) in per_channel.iter_mut().enumerate() {
        v.sort_by(f64::total_cmp);
        let at = |p: f64| v[((p * (v.len() - 1) as f64).round()) as usize];
        println!(
            "channel {c}: {} points, RHO needed 50 % {:.4}, 90 % {:.4}, 95 % {:.4}",
            v.len(),
            at(0.5),
            at(0.9),
            at(0.95)
        );
    }
    for (lo, hi) in [(0.25, 1.0), (1.0, 2.0), (2.0, 4.0), (4.0, 100.0)] {
        let mut v: Vec<f64> = needed
            .iter()
            .filter(|p| p.0 >= lo && p.0 < hi)
            .map(|p| p.1)
            .collect();
        if v.is_empty() {
            continue;
        }
        v.sort_by(f64::total_cmp);
        println!(
            "reach {lo} to {hi}: {} points, RHO needed 90 % {:.4}, 95 % {:.4}",
            v.len(),
            v[(0.9 * (v.len() - 1) as f64) as usize],
            v[(0.95 * (v.len() - 1) as f64) as usize]
        );
    }
}
