//! The prediction's bands measured against synthetic truths of this binary's own generator
//! (`cases`): the calibration (mean coverage of the noise-free truth by the 95 % bands at
//! least 90 %, bands no wider than a stated multiple of the error, the model form dominating
//! where the fitted model lacks the cause), the post-flight check, bands shrinking with a
//! second release pooled, and the same bands whatever the thread count. The full calibration
//! table is `table` (ignored: run it by name, `scripts/calibration.sh`). Release build.

mod cases;

use cases::{Cause, case, causes, measure, noisy, predicted, prepared, truth};
use sepval_predict::Flown;

/// The widest bands the calibration accepts: RMS half-width over RMS error of the median, mean
/// over the channels (a calibrated normal 95 % band gives 1.96; a band several times wider
/// than the errors it must hold is not a prediction).
const MAX_WIDTH_RATIO: f64 = 8.0;

#[test]
fn bands_hold_the_truth_and_are_not_too_wide() {
    let all = causes();
    let picks = [(0, 2, 11), (1, 3, 12), (2, 3, 13), (4, 2, 14)];
    let mut coverage = 0.0;
    for &(i, releases, seed) in &picks {
        let c = case(all[i], releases, seed);
        let m = measure(&c, 400);
        eprintln!("{}: {m:?}", c.cause.name());
        coverage += m.coverage / picks.len() as f64;
        // Beyond the reach the held-out releases cover, the band carries the reach rule's
        // model form (docs/model.md section 10a, calibrated on its own cases): wide by design
        // where nothing measured how the model's form carries.
        let fitted: Vec<_> = c.fitted.iter().collect();
        let beyond = sepval_predict::reach::uncovered(
            sepval_run::domain::reach(&fitted, &c.predicted),
            sepval_run::domain::covered_reach(&fitted, &[]),
        );
        if beyond <= 0.0 {
            assert!(m.width_ratio < MAX_WIDTH_RATIO, "{}: {m:?}", c.cause.name());
        }
        if !matches!(c.cause, Cause::Null) {
            assert!(
                m.form_share > 0.5,
                "{}: the model lacks the cause, yet the model form has only {:.2} of the band",
                c.cause.name(),
                m.form_share
            );
        }
    }
    assert!(coverage >= 0.9, "mean coverage {coverage:.3}");
}

/// The calibration table of docs/performance.md: every cause, two and three releases fitted, eight
/// seeds each. `cargo test --release -p sepval-predict --test calibration -- --ignored
/// --nocapture table`.
#[test]
#[ignore = "the full table takes minutes: run it by name (scripts/calibration.sh)"]
fn table() {
    println!(
        "| cause | releases fitted | cases | mean coverage | min coverage | width ratio | model-form share |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut total = (0.0, 0usize);
    for (i, cause) in causes().into_iter().enumerate() {
        for releases in [2, 3] {
            // Each row its own cases (bases, conditions, noise): the two null rows differ.
            let first = 1000 * i as u64 + 100 * releases as u64;
            let seeds = first..first + 8;
            let runs: Vec<_> = seeds
                .map(|s| measure(&case(cause, releases, s), 400))
                .collect();
            let n = runs.len() as f64;
            let mean = |f: &dyn Fn(&cases::Measured) -> f64| runs.iter().map(f).sum::<f64>() / n;
            let min = runs.iter().map(|m| m.coverage).fold(1.0, f64::min);
            total.0 += runs.iter().map(|m| m.coverage).sum::<f64>();
            total.1 += runs.len();
            println!(
                "| {} | {releases} | {} | {:.3} | {:.3} | {:.2} | {:.2} |",
                cause.name(),
                runs.len(),
                mean(&|m| m.coverage),
                min,
                mean(&|m| m.width_ratio),
                mean(&|m| m.form_share)
            );
        }
    }
    println!(
        "mean coverage over {} cases: {:.3}",
        total.1,
        total.0 / total.1 as f64
    );
}

#[test]
fn the_check_says_inside_for_a_release_of_the_model_and_outside_for_a_cause_it_lacks() {
    // Drawn from the model: no hidden cause, the flown release the truth with noise.
    let mut c = case(Cause::Null, 2, 21);
    let flown = Flown {
        name: "flown.csv".into(),
        data: noisy(truth(&c, &c.predicted), 777),
    };
    let p = predicted(&prepared(&c, 400, Some(flown)), 2);
    let check = p.check.unwrap();
    assert!(check.inside, "{check:?}");
    assert_eq!(check.verdict, "inside the predicted bands");

    // A yaw moment growing with sideslip near the aircraft, which the fitted model lacks: the
    // releases fitted were flown without sideslip, so nothing in them shows it; the release
    // checked is flown at 6 deg of sideslip.
    c = case(causes()[2], 2, 22);
    for f in &mut c.fitted {
        f.beta_deg = 0.0;
    }
    c.predicted.beta_deg = 6.0;
    let flown = Flown {
        name: "flown.csv".into(),
        data: noisy(truth(&c, &c.predicted), 778),
    };
    let p = predicted(&prepared(&c, 400, Some(flown)), 2);
    let check = p.check.unwrap();
    assert!(!check.inside, "{check:?}");
    let yaw = &check.channels[5];
    let t = yaw.leaves_at_s.expect("yaw leaves its band");
    let first = check
        .channels
        .iter()
        .filter_map(|c| c.leaves_at_s)
        .fold(f64::INFINITY, f64::min);
    assert!((t - first).abs() < 1e-12, "yaw leaves first: {check:?}");
    // The interference decays over half a metre of separation: the yaw error builds while the
    // store is near the aircraft, in the first few tenths of a second.
    assert!((0.02..0.6).contains(&t), "{check:?}");
    assert!(check.verdict.contains("in yaw"), "{}", check.verdict);
}

#[test]
fn bands_shrink_when_a_second_release_is_pooled() {
    let two = case(Cause::Null, 2, 31);
    let mut one = two.clone();
    one.fitted.truncate(1);
    // The 200 samples this test was written with, at the level they can give (20 / (1 -
    // level) samples at least: 0.9).
    let width = |c: &cases::Case| {
        let p = predicted(&cases::prepared_at(c, 200, 0.9, None), 2);
        p.bands
            .channels
            .iter()
            .map(|b| {
                let n = b.lo.len() as f64;
                b.hi.iter().zip(&b.lo).map(|(h, l)| h - l).sum::<f64>() / n
            })
            .collect::<Vec<f64>>()
    };
    let (w1, w2) = (width(&one), width(&two));
    let shrunk = w1.iter().zip(&w2).filter(|(a, b)| b < a).count();
    assert!(shrunk >= 5, "one release {w1:?}, two {w2:?}");
}

#[test]
fn the_same_seed_gives_the_same_bands_whatever_the_thread_count() {
    let c = case(causes()[1], 2, 41);
    let p = prepared(&c, 400, None);
    let (a, b) = (predicted(&p, 1), predicted(&p, 2));
    for (x, y) in a.bands.channels.iter().zip(&b.bands.channels) {
        for (u, v) in
            x.lo.iter()
                .chain(&x.mid)
                .chain(&x.hi)
                .zip(y.lo.iter().chain(&y.mid).chain(&y.hi))
        {
            assert_eq!(u.to_bits(), v.to_bits());
        }
    }
}

/// At release the state is known (carriage): the band is empty there, whatever the model gets
/// wrong later (issue 36: a floor constant in time gave the Eglin case +-25 mm in x and +-3 deg
/// in roll at t = 0), and it grows from there. A cause the model lacks, one release fitted: the
/// only evidence is the answer's own misfit on it.
#[test]
fn the_band_is_empty_at_carriage_and_grows_after_it() {
    let mut c = case(causes()[1], 2, 17);
    c.fitted.truncate(1);
    let prepared = cases::prepared_at(&c, 200, 0.9, None);
    assert!(
        prepared.grid.t_s[0].abs() < 1e-12,
        "the grid starts at release"
    );
    let p = predicted(&prepared, 2);
    for (k, b) in p.bands.channels.iter().enumerate() {
        assert!(
            b.hi[0] - b.lo[0] < 1e-9,
            "channel {k} at t = 0: [{}, {}]",
            b.lo[0],
            b.hi[0]
        );
        let n = b.lo.len();
        let late = b.hi[n - 1] - b.lo[n - 1];
        assert!(late > 0.0, "channel {k} has no band at the end");
    }
}
