//! The statistics against the hand-written special functions they replaced (W. H. Press et
//! al., "Numerical Recipes", 3rd ed., sections 5.2, 6.1, 6.2 and 6.4), kept here as the
//! reference, and against known values.

use super::*;

/// Largest relative difference allowed between statrs and the reference.
const RELATIVE: f64 = 1e-12;

/// Smallest p-value compared: below it the reference's exponentials are subnormal (module
/// documentation).
const SMALLEST_P: f64 = 1e-300;

/// Log-spaced points from `lo` to `hi`, `n` of them.
fn log_grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
        .collect()
}

/// Checks `ours` against `reference` over `cases` (described by `what`), returns the largest
/// relative difference and the number of cases compared.
fn compare(
    cases: &[[f64; 3]],
    ours: impl Fn([f64; 3]) -> f64,
    reference: impl Fn([f64; 3]) -> f64,
    what: &str,
) -> (f64, usize) {
    let (mut worst, mut compared) = (0.0f64, 0usize);
    for &c in cases {
        let (p, r) = (ours(c), reference(c));
        if r < SMALLEST_P {
            assert!(p < 1e-290, "{what} {c:?}: statrs {p:e}, reference {r:e}");
            continue;
        }
        let rel = (p - r).abs() / r;
        assert!(
            rel <= RELATIVE,
            "{what} {c:?}: statrs {p:e}, reference {r:e}, relative difference {rel:e}"
        );
        worst = worst.max(rel);
        compared += 1;
    }
    (worst, compared)
}

#[test]
fn chi_square_tail_matches_the_reference_to_1e_12() {
    // Degrees of freedom of the Ljung-Box tests (lags 1..20 per channel and event, pooled) and
    // beyond; x from deep in the body (p near 1) to far in the tail, around the mean dof where
    // the reference switches from its series to its continued fraction.
    let mut cases = Vec::new();
    for dof in [
        1.0, 2.0, 3.0, 5.0, 7.0, 10.0, 19.0, 20.0, 40.0, 60.0, 120.0, 240.0, 1000.0,
    ] {
        for x in log_grid(1e-3, 50.0 * dof + 2000.0, 400) {
            cases.push([x, dof, 0.0]);
        }
        for k in 0..=40 {
            cases.push([dof + 2.0 * (k as f64 - 20.0) * 0.05 * dof.sqrt(), dof, 0.0]);
        }
    }
    let (worst, n) = compare(
        &cases,
        |[x, dof, _]| chi2_sf(x, dof),
        |[x, dof, _]| reference::gamma_q(0.5 * dof, 0.5 * x),
        "chi2_sf(x, dof)",
    );
    assert!(n > 5000, "{n} cases compared");
    eprintln!("chi2_sf: {n} cases, largest relative difference {worst:e}");
}

#[test]
fn f_tail_matches_known_values_to_1e_12() {
    // I_{d2 / (d2 + d1 f)}(d2 / 2, d1 / 2) to 17 digits (mpmath `betainc`, 40 digits).
    let known = [
        ([2.443_204_762_186_487, 1.0, 30.0], 0.128_523_464_353_326_68),
        ([3.0, 4.0, 100.0], 0.021_996_867_431_635_51),
        ([0.5, 3.0, 1_183.0], 0.682_343_467_813_307_9),
        ([6.0, 2.0, 1_183.0], 0.002_554_820_967_926_669_4),
        ([20.0, 6.0, 1_183.0], 2.338_063_772_785_604e-22),
    ];
    for ([f, d1, d2], p) in known {
        let rel = (f_sf(f, d1, d2) - p).abs() / p;
        assert!(
            rel <= RELATIVE,
            "f_sf({f}, {d1}, {d2}): relative error {rel:e}"
        );
    }
}

#[test]
fn statrs_f_tail_is_not_the_same_to_1e_12() {
    // Why the incomplete beta function stays hand-written (module documentation): should a
    // statrs release meet 1e-12 here, this fails and the F tail can move to statrs as well.
    let mut worst = 0.0f64;
    for d1 in [1.0, 2.0, 3.0, 6.0] {
        for d2 in [30.0, 1_183.0, 12_000.0] {
            for f in log_grid(0.1, 30.0, 50) {
                let x = d2 / (d2 + d1 * f);
                let theirs = statrs::function::beta::beta_reg(0.5 * d2, 0.5 * d1, x);
                let ours = f_sf(f, d1, d2);
                worst = worst.max((theirs - ours).abs() / ours);
            }
        }
    }
    assert!(worst > RELATIVE, "statrs now within {worst:e}");
}

#[test]
fn edges_are_as_before() {
    assert_eq!(chi2_sf(0.0, 3.0).to_bits(), 1.0f64.to_bits());
    assert_eq!(chi2_sf(-1.0, 3.0).to_bits(), 1.0f64.to_bits());
    assert_eq!(chi2_sf(f64::INFINITY, 3.0).to_bits(), 0.0f64.to_bits());
    assert!(chi2_sf(f64::NAN, 3.0).is_nan());
    assert_eq!(f_sf(0.0, 2.0, 10.0).to_bits(), 1.0f64.to_bits());
    assert_eq!(f_sf(f64::INFINITY, 2.0, 10.0).to_bits(), 0.0f64.to_bits());
    assert!(f_sf(f64::NAN, 2.0, 10.0).is_nan());
    // A perfect extended fit (rss1 = 0) is infinitely significant, as before.
    assert_eq!(f_test(1.0, 0.0, 2, 100, 5).1.to_bits(), 0.0f64.to_bits());
}

/// The former chi-square tail, unchanged (its log-gamma function is the one the F tail still
/// uses).
mod reference {
    use super::beta::lentz_step;
    use super::beta::ln_gamma;

    /// Regularised upper incomplete gamma Q(a, x) = 1 - P(a, x).
    pub fn gamma_q(a: f64, x: f64) -> f64 {
        if x <= 0.0 {
            return 1.0;
        }
        let gln = ln_gamma(a);
        if x < a + 1.0 {
            // Series for P.
            let (mut ap, mut sum, mut del) = (a, 1.0 / a, 1.0 / a);
            for _ in 0..1000 {
                ap += 1.0;
                del *= x / ap;
                sum += del;
                if del.abs() < sum.abs() * 1e-16 {
                    break;
                }
            }
            1.0 - sum * (-x + a * x.ln() - gln).exp()
        } else {
            // Continued fraction for Q.
            let tiny = 1e-300;
            let mut b = x + 1.0 - a;
            let mut c = 1.0 / tiny;
            let mut d = 1.0 / b;
            let mut h = d;
            for i in 1..1000 {
                let an = -(i as f64) * (i as f64 - a);
                b += 2.0;
                let del = lentz_step(an, b, &mut c, &mut d);
                h *= del;
                if (del - 1.0).abs() < 1e-16 {
                    break;
                }
            }
            (-x + a * x.ln() - gln).exp() * h
        }
    }
}

#[test]
fn known_values() {
    let ln_gamma = statrs::function::gamma::ln_gamma;
    assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-12);
    assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-12);
    // chi-square 95 % points: 3.841 (1 dof), 31.410 (20 dof).
    assert!((chi2_sf(3.841_458_820_694_124, 1.0) - 0.05).abs() < 1e-9);
    assert!((chi2_sf(31.410_432_844_230_918, 20.0) - 0.05).abs() < 1e-9);
    // F 95 % points: F(1, 100) = 3.936, F(3, 1000) = 2.6138.
    assert!((f_sf(3.936_142_812_995_198, 1.0, 100.0) - 0.05).abs() < 1e-6);
    // F(3, d2) tends to chi-square(3) / 3 as d2 grows.
    assert!((f_sf(7.814_727_903_251_178 / 3.0, 3.0, 1e9) - 0.05).abs() < 1e-6);
    assert!((chi2_sf(7.814_727_903_251_178, 3.0) - 0.05).abs() < 1e-9);
    let beta_reg = statrs::function::beta::beta_reg;
    assert!((beta_reg(2.0, 3.0, 0.4) - 0.5248).abs() < 1e-12);
}

#[test]
fn white_noise_passes_and_a_sine_fails_ljung_box() {
    let mut s = 7u64;
    let noise: Vec<f64> = (0..400)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect();
    assert!(ljung_box(&noise, 20).1 > 0.01);
    let sine: Vec<f64> = (0..400).map(|i| (i as f64 * 0.05).sin()).collect();
    assert!(ljung_box(&sine, 20).1 < 1e-10);
}
