//! Unit tests of the stages that need no simulation: the draws, the quantiles, the grid, the
//! check's rule, the settings and the condition's checks.

use sepval_common::effects::EffectSet;
use sepval_common::scenario::Scenario;
use sepval_fit::space::ParamSpace;
use sepval_solve::identifiability::{Identifiability, ParamEstimate};

use crate::bands::{ChannelBand, quantile};
use crate::check::check;
use crate::condition::{ConditionError, Settings, check_condition};
use crate::sampling::{ParameterDistribution, sample_rng};
use crate::simulate::{Grid, MAX_BAND_POINTS};

/// An identifiability record of the 17 factors of `space` with standard errors `std` (None:
/// not determined) and the correlation `rho` between the first two.
fn record(space: &ParamSpace, std: &[Option<f64>], rho: f64) -> Identifiability {
    let n = space.len();
    let mut correlation = vec![vec![0.0; n]; n];
    for (i, row) in correlation.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    correlation[0][1] = rho;
    correlation[1][0] = rho;
    Identifiability {
        parameters: (0..n)
            .map(|i| ParamEstimate {
                name: space.params.names[i].clone(),
                unit: "-".into(),
                value: 0.0,
                std_error: std.get(i).copied().flatten(),
                std_error_white: std.get(i).copied().flatten(),
                identifiable: true,
            })
            .collect(),
        names: space.params.names.clone(),
        correlation,
        compensating: Vec::new(),
        not_identifiable: Vec::new(),
        max_lag: 1,
    }
}

#[test]
fn draws_have_the_covariance_stay_in_bounds_and_hold_undetermined_parameters() {
    let table = Scenario::embedded_default().factors;
    let space = ParamSpace::new(&table, &EffectSet::NONE);
    let mid: Vec<f64> = (0..space.len())
        .map(|i| 0.5 * (space.params.lo[i] + space.params.hi[i]))
        .collect();
    let (s0, s1) = (0.02 * space.params.range(0), 0.01 * space.params.range(1));
    let mut std = vec![Some(s0), Some(s1)];
    std.extend(vec![None; space.len() - 2]);
    let d = ParameterDistribution::of(&space, &mid, &record(&space, &std, 0.8));
    let n = 20_000;
    let draws: Vec<Vec<f64>> = (0..n).map(|i| d.draw(&mut sample_rng(7, i, 0))).collect();
    let mean = |j: usize| draws.iter().map(|x| x[j]).sum::<f64>() / n as f64;
    let (m0, m1) = (mean(0), mean(1));
    let cov = draws.iter().map(|x| (x[0] - m0) * (x[1] - m1)).sum::<f64>() / n as f64;
    let v0 = draws.iter().map(|x| (x[0] - m0).powi(2)).sum::<f64>() / n as f64;
    // Within 3 % of the covariance asked (20 000 draws: about 1 % standard error).
    assert!(
        (v0.sqrt() / s0 - 1.0).abs() < 0.03,
        "sd {} vs {s0}",
        v0.sqrt()
    );
    assert!((cov / (0.8 * s0 * s1) - 1.0).abs() < 0.05, "cov {cov}");
    for x in &draws {
        assert!(
            x[2..]
                .iter()
                .zip(&mid[2..])
                .all(|(a, b)| a.to_bits() == b.to_bits())
        );
    }
    // Near a bound, a wide distribution is redrawn into the box.
    let mut low = mid.clone();
    low[0] = space.params.lo[0] + 0.01 * space.params.range(0);
    let wide = vec![Some(0.3 * space.params.range(0))];
    let d = ParameterDistribution::of(&space, &low, &record(&space, &wide, 0.0));
    for i in 0..2000 {
        let x = d.draw(&mut sample_rng(3, i, 0));
        assert!(x[0] >= space.params.lo[0] && x[0] <= space.params.hi[0]);
    }
}

#[test]
fn a_sample_is_the_same_whatever_else_is_drawn() {
    let a: f64 = crate::sampling::normal(&mut sample_rng(1, 5, 0));
    let b: f64 = crate::sampling::normal(&mut sample_rng(1, 5, 0));
    let c: f64 = crate::sampling::normal(&mut sample_rng(1, 6, 0));
    let d: f64 = crate::sampling::normal(&mut sample_rng(1, 5, 1));
    assert_eq!(a.to_bits(), b.to_bits());
    assert_ne!(a.to_bits(), c.to_bits());
    assert_ne!(a.to_bits(), d.to_bits());
}

#[test]
fn quantiles_interpolate_between_order_statistics() {
    let v = [1.0, 2.0, 3.0, 4.0, 5.0];
    assert!((quantile(&v, 0.5) - 3.0).abs() < 1e-15);
    assert!((quantile(&v, 0.125) - 1.5).abs() < 1e-15);
    assert!((quantile(&v, 1.0) - 5.0).abs() < 1e-15);
    assert!((quantile(&[2.0], 0.9) - 2.0).abs() < 1e-15);
    assert!(quantile(&[], 0.5).is_nan());
}

#[test]
fn the_grid_keeps_every_sample_of_a_short_release_and_thins_a_long_one() {
    let short: Vec<f64> = (0..201).map(|k| k as f64 * 0.005).collect();
    let g = Grid::of(&short);
    assert_eq!(g.len(), 201);
    let long: Vec<f64> = (0..10_001).map(|k| k as f64 * 1e-4).collect();
    let g = Grid::of(&long);
    assert!(g.len() <= MAX_BAND_POINTS + 1, "{}", g.len());
    assert_eq!(*g.indices.last().unwrap(), 10_000);
    assert!(g.indices.windows(2).all(|w| w[0] < w[1]));
}

fn flat_bands(n: usize) -> [ChannelBand; 6] {
    std::array::from_fn(|_| ChannelBand {
        lo: vec![-1.0; n],
        mid: vec![0.0; n],
        hi: vec![1.0; n],
    })
}

#[test]
fn the_check_lets_isolated_points_through_and_names_a_run_outside() {
    let n = 100;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 0.01).collect();
    let mut data = vec![[0.0; 6]; n];
    // Isolated points outside in every channel: inside.
    for k in (5..n).step_by(10) {
        data[k] = [2.0; 6];
    }
    let c = check("d", &data, &t, &flat_bands(n));
    assert!(c.inside, "{c:?}");
    assert!((c.channels[0].inside - 0.9).abs() < 1e-12);
    // Pitch leaves at 0.31 s and stays out for 6 points (>= 5 % of 100): outside in pitch.
    for p in &mut data[31..37] {
        p[4] = 1.5;
    }
    let c = check("d", &data, &t, &flat_bands(n));
    assert!(!c.inside);
    assert_eq!(
        c.verdict,
        "outside from t = 0.31 s in pitch: the model does not hold at this condition"
    );
    assert!((c.channels[4].by.unwrap() - 0.5).abs() < 1e-12);
    assert!(c.channels[3].leaves_at_s.is_none());
}

#[test]
fn settings_and_conditions_are_checked() {
    let ok = Settings {
        samples: 1000,
        level: 0.95,
        seed: 1,
        with_noise: false,
        threads: 1,
    };
    assert!(ok.check().is_ok());
    for level in [0.0, 1.0, -0.5, f64::NAN] {
        let e = Settings { level, ..ok }.check().unwrap_err();
        assert!(matches!(e, ConditionError::Level(_)), "{e}");
    }
    let e = Settings { samples: 0, ..ok }.check().unwrap_err();
    assert!(
        e.to_string().starts_with(
            "--samples 0: bands at level 0.95 need at least 400 samples (20 / (1 - level)"
        ),
        "{e}"
    );
    // The rule at other levels, exactly at its edge.
    for (level, least) in [(0.95, 400), (0.9, 200), (0.5, 40), (0.99, 2000)] {
        assert_eq!(crate::condition::min_samples(level), least, "{level}");
        let at = |samples| {
            Settings {
                samples,
                level,
                ..ok
            }
            .check()
        };
        assert!(at(least).is_ok() && at(least - 1).is_err(), "{level}");
    }
    let e = Settings {
        samples: 1_000_000,
        ..ok
    }
    .check()
    .unwrap_err();
    assert_eq!(e.to_string(), "--samples 1000000: expected at most 100000");
    assert!(
        Settings {
            samples: 100_000,
            ..ok
        }
        .check_size(20_000)
        .is_err()
    );

    let fitted = Scenario::embedded_default();
    let mut other = fitted.clone();
    other.flight.mach = 0.9;
    other.name = "at Mach 0.9".into();
    assert!(check_condition(&fitted, &other).is_ok());
    other.store.mass_kg *= 1.1;
    let e = check_condition(&fitted, &other).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "its store differs from that of the releases fitted ({}): store.mass_kg is {}, not {}; a prediction flies the store that was fitted: change only [flight]",
            fitted.name, other.store.mass_kg, fitted.store.mass_kg
        )
    );
    let mut far = fitted.clone();
    far.flight.mach = 5.0;
    let e = check_condition(&fitted, &far).unwrap_err().to_string();
    assert!(
        e.contains("the condition's Mach = 5 is outside the model's domain"),
        "{e}"
    );
}
