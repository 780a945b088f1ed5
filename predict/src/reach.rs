//! Model form away from the releases (docs/model.md, "Model form away from the releases"): the
//! model-form band of a prediction widened with the distance of its condition from the nearest
//! release flown, so that a condition far from every release is not cleared on the factors'
//! spread alone.
//!
//! The rule: r the reach of the condition ([`sepval_run::domain::reach`]: 0 at a release, 1
//! as far as 0.1 in Mach), r_h the reach the held-out releases cover
//! ([`sepval_run::domain::covered_reach`]: the farthest a release was predicted without being
//! fitted; 0 with one release and none validated), m_c(t) = |ybar_c(t) - ybar_c(0)| the
//! store's own motion on channel c (ybar the mean of the samples that ran), and
//!
//! delta_c(t)^2 <- delta_c(t)^2 + (RHO_c min(max(0, r - r_h), MAX_REACH) m_c(t))^2,
//!
//! delta the discrepancy calibrated at the releases ([`crate::discrepancy`]), whose held-out
//! releases measure how the model's form carries as far as they were predicted (their
//! departures at the condition, step 3). Beyond that nothing measured it: a model whose form is
//! right at the releases may be wrong elsewhere by a share of the motion it predicts there that
//! grows with the distance, RHO_c per unit of reach. With nothing flown the reach is
//! [`UNFLOWN_REACH`]. [`RHO`] was calibrated on our own cases (docs/model.md gives the cases,
//! the seeds and the coverage): a model fitted at one condition with a hidden cause inside or
//! outside the catalogue, predicted at conditions 0.5 to 4 units away.

use crate::simulate::GridTrajectory;

/// The share of the store's own motion on each channel (x, y, z, roll, pitch, yaw) that the
/// model's form may get wrong per unit of reach, one standard deviation: the 95th percentile of
/// what the calibration's points needed on that channel (docs/model.md section 10a), rounded
/// up. Pitch needs most: a cause the model lacks changes the pitch the store takes far more
/// than its translation, for the same share of its motion.
pub const RHO: [f64; 6] = [0.015, 0.06, 0.025, 0.06, 0.5, 0.085];
/// The reach beyond which the band grows no more (the model's form is then as unknown as the
/// rule can say: MAX_REACH RHO of the motion).
pub const MAX_REACH: f64 = 10.0;
/// The reach of every condition when nothing was flown: a model never checked against a release
/// is taken as uncertain as one checked 0.3 in Mach away. Measured on 2026-11-27 under the
/// default prior against the example aircraft (Mach 0.6-1.2, alpha -6 to 10 deg, 25.4 mm, 400
/// samples): with 3, all 25 conditions cleared, the largest P(fail) 0.0225; with 6, 5 were
/// undecided (P(fail) up to 0.19) and a hidden cubic pitch stiffness was still cleared where it
/// fails (docs/campaign.md, "Known gaps"): a larger reach for the prior does not mend that.
pub const UNFLOWN_REACH: f64 = 3.0;

/// The reach beyond what the held-out releases cover: max(0, `reach` - `covered`), infinite
/// when nothing was flown.
pub fn uncovered(reach: f64, covered: f64) -> f64 {
    if reach.is_infinite() {
        reach
    } else {
        (reach - covered.max(0.0)).max(0.0)
    }
}

/// The reach the band uses: `reach` capped at [`MAX_REACH`], [`UNFLOWN_REACH`] when nothing was
/// flown (`reach` infinite).
pub fn effective(reach: f64) -> f64 {
    if reach.is_infinite() {
        UNFLOWN_REACH
    } else {
        reach.clamp(0.0, MAX_REACH)
    }
}

/// The store's motion m_c(t) on each channel at each band point: the mean of `ran` less its
/// first point, in absolute value (zeros when nothing ran).
pub fn motion(ran: &[&GridTrajectory]) -> Vec<[f64; 6]> {
    let Some(first) = ran.first() else {
        return Vec::new();
    };
    let n = ran.len() as f64;
    let mean: Vec<[f64; 6]> = (0..first.len())
        .map(|k| std::array::from_fn(|c| ran.iter().map(|t| t[k][c]).sum::<f64>() / n))
        .collect();
    let start = mean.first().copied().unwrap_or([0.0; 6]);
    mean.iter()
        .map(|p| std::array::from_fn(|c| (p[c] - start[c]).abs()))
        .collect()
}

/// `sd` (the discrepancy at each band point) widened for `reach` (module docs); points beyond
/// `motion`'s are left as they are.
pub fn widen(sd: &mut [[f64; 6]], motion: &[[f64; 6]], reach: f64) {
    let r = effective(reach);
    for (d, m) in sd.iter_mut().zip(motion) {
        for c in 0..6 {
            d[c] = d[c].hypot(RHO[c] * r * m[c]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_band_grows_with_the_reach_and_not_at_a_release() {
        let t: GridTrajectory = vec![[0.0; 6], [1.0, 0.0, 2.0, 0.0, 10.0, 0.0]];
        let m = motion(&[&t]);
        let mut at_release = vec![[0.5; 6]; 2];
        widen(&mut at_release, &m, 0.0);
        assert_eq!(at_release, vec![[0.5; 6]; 2]);
        let mut away = vec![[0.0; 6]; 2];
        widen(&mut away, &m, 3.0);
        assert!((away[1][2] - 3.0 * RHO[2] * 2.0).abs() < 1e-12);
        assert!((away[1][4] - 3.0 * RHO[4] * 10.0).abs() < 1e-12);
        assert!(
            away[0].iter().all(|v| v.abs() < 1e-15),
            "no motion at release"
        );
        let mut none = vec![[0.0; 6]; 2];
        widen(&mut none, &m, f64::INFINITY);
        assert!((none[1][2] - UNFLOWN_REACH * RHO[2] * 2.0).abs() < 1e-12);
    }
}
