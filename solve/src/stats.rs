//! Distribution functions and tests used by the diagnosis.
//!
//! Sources: the regularised incomplete gamma and beta functions by series and continued
//! fractions (W. H. Press et al., "Numerical Recipes", 3rd ed., sections 6.2 and 6.4, modified
//! Lentz's method), the log-gamma function by the Lanczos approximation (ibid. 6.1); the F test
//! of nested least-squares models; the Ljung-Box portmanteau statistic
//! Q = N (N + 2) sum_{k=1}^{h} rho_k^2 / (N - k) (G. M. Ljung and G. E. P. Box, Biometrika 65,
//! 1978), chi-square with h degrees of freedom for white residuals.
//!
//! These run on the coordinator only, after the simulations, so they use the standard library's
//! elementary functions (`exp`, `ln`, ...); the simulation itself uses none (docs/model.md
//! section 9, `sepval_common::elementary`).

/// ln Gamma(x), x > 0 (Lanczos, g = 7, n = 9).
pub fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        return (std::f64::consts::PI / (std::f64::consts::PI * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

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

/// Survival function of the chi-square distribution with `dof` degrees of freedom.
pub fn chi2_sf(x: f64, dof: f64) -> f64 {
    gamma_q(0.5 * dof, 0.5 * x)
}

/// One step of the modified Lentz algorithm for a continued fraction with partial numerator
/// `a_n` and partial denominator `b_n` (Press et al., Numerical Recipes, 3rd ed., section 5.2):
/// updates `c` and `d` and returns the factor `c d` the approximant is multiplied by.
fn lentz_step(a_n: f64, b_n: f64, c: &mut f64, d: &mut f64) -> f64 {
    const TINY: f64 = 1e-300;
    *d = a_n * *d + b_n;
    if d.abs() < TINY {
        *d = TINY;
    }
    *c = b_n + a_n / *c;
    if c.abs() < TINY {
        *c = TINY;
    }
    *d = 1.0 / *d;
    *d * *c
}

fn beta_cf(a: f64, b: f64, x: f64) -> f64 {
    let tiny = 1e-300;
    let (qab, qap, qam) = (a + b, a + 1.0, a - 1.0);
    let mut c = 1.0;
    let mut d = 1.0 - qab * x / qap;
    if d.abs() < tiny {
        d = tiny;
    }
    d = 1.0 / d;
    let mut h = d;
    for m in 1..10_000 {
        let m = m as f64;
        let m2 = 2.0 * m;
        let aa = m * (b - m) * x / ((qam + m2) * (a + m2));
        h *= lentz_step(aa, 1.0, &mut c, &mut d);
        let aa = -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2));
        let del = lentz_step(aa, 1.0, &mut c, &mut d);
        h *= del;
        if (del - 1.0).abs() < 1e-15 {
            break;
        }
    }
    h
}

/// Regularised incomplete beta I_x(a, b).
pub fn beta_inc(a: f64, b: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    if x >= 1.0 {
        return 1.0;
    }
    let bt = (ln_gamma(a + b) - ln_gamma(a) - ln_gamma(b) + a * x.ln() + b * (1.0 - x).ln()).exp();
    if x < (a + 1.0) / (a + b + 2.0) {
        bt * beta_cf(a, b, x) / a
    } else {
        1.0 - bt * beta_cf(b, a, 1.0 - x) / b
    }
}

/// Survival function of the F distribution with (d1, d2) degrees of freedom.
pub fn f_sf(f: f64, d1: f64, d2: f64) -> f64 {
    if f <= 0.0 {
        return 1.0;
    }
    beta_inc(0.5 * d2, 0.5 * d1, d2 / (d2 + d1 * f))
}

/// The F test of a nested extension: `q` more parameters lowered the residual sum of squares
/// from `rss0` to `rss1`, with `m` residuals and `p1` parameters in the extended model.
/// Returns (F, p-value).
pub fn f_test(rss0: f64, rss1: f64, q: usize, m: usize, p1: usize) -> (f64, f64) {
    let d2 = (m.saturating_sub(p1)).max(1) as f64;
    let f = ((rss0 - rss1).max(0.0) / q as f64) / (rss1 / d2);
    (f, f_sf(f, q as f64, d2))
}

/// Autocorrelation of `x` at lags 1..=h.
pub fn autocorrelation(x: &[f64], h: usize) -> Vec<f64> {
    let n = x.len();
    let mean = x.iter().sum::<f64>() / n as f64;
    let c0: f64 = x.iter().map(|v| (v - mean) * (v - mean)).sum();
    (1..=h)
        .map(|k| {
            if k >= n || c0 <= 0.0 {
                return 0.0;
            }
            (0..n - k)
                .map(|i| (x[i] - mean) * (x[i + k] - mean))
                .sum::<f64>()
                / c0
        })
        .collect()
}

/// The Ljung-Box statistic and its p-value (chi-square, h degrees of freedom).
pub fn ljung_box(x: &[f64], h: usize) -> (f64, f64) {
    let n = x.len() as f64;
    let rho = autocorrelation(x, h);
    let q = n
        * (n + 2.0)
        * rho
            .iter()
            .enumerate()
            .map(|(k, r)| r * r / (n - (k + 1) as f64))
            .sum::<f64>();
    (q, chi2_sf(q, h as f64))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_values() {
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
        assert!((beta_inc(2.0, 3.0, 0.4) - 0.5248).abs() < 1e-12);
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
}
