//! The ejector force-versus-displacement table.
//!
//! Source: `docs/model.md` section 1 ("nominal ejector force curve"): a table of
//! (s_m, force_N) points, linear between them, covering [0, stroke]. The force of foot i is
//! `fac_i * F_ej(clamp(s_i, 0, stroke))` (section 3); the clamp is the caller's.

/// A piecewise-linear force curve. Built once per scenario; lookups do not allocate.
#[derive(Debug, Clone, PartialEq)]
pub struct EjectorCurve {
    s_m: Vec<f64>,
    force_n: Vec<f64>,
}

impl EjectorCurve {
    /// A curve through validated points (displacements strictly increasing; see
    /// [`crate::scenario::Scenario::validate`]).
    pub fn new(points: &[[f64; 2]]) -> Self {
        EjectorCurve {
            s_m: points.iter().map(|p| p[0]).collect(),
            force_n: points.iter().map(|p| p[1]).collect(),
        }
    }

    /// Force at displacement `s_m` \[N\], linear between points, constant beyond the ends.
    #[inline(always)]
    pub fn force_n(&self, s_m: f64) -> f64 {
        let n = self.s_m.len();
        if s_m <= self.s_m[0] {
            return self.force_n[0];
        }
        if s_m >= self.s_m[n - 1] {
            return self.force_n[n - 1];
        }
        // Tables are short (a few points): a linear scan beats a binary search.
        let mut j = 1;
        while self.s_m[j] < s_m {
            j += 1;
        }
        let (s0, s1) = (self.s_m[j - 1], self.s_m[j]);
        let (f0, f1) = (self.force_n[j - 1], self.force_n[j]);
        f0 + (f1 - f0) * (s_m - s0) / (s1 - s0)
    }
}
