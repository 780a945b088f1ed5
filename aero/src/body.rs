//! The body of revolution: its normal force, centre of pressure and pitch damping from
//! slender-body theory, and the viscous crossflow that adds to them at angle of attack.
//!
//! - **Slender-body theory** (M. M. Munk, NACA Report 184, 1924; J. N. Nielsen, *Missile
//!   Aerodynamics*, McGraw-Hill 1960, ch. 3): a section whose area S(x) grows carries a normal
//!   force per length dN/dx = 2 qbar alpha dS/dx, whatever the Mach number. So the body's
//!   CN_alpha = 2 (S_base / S_ref) [per rad], the nose's 2 at x_cp = L_n - V_n / S_ref (V_n its
//!   volume: 2 L_n / 3 for a cone), a boattail's 2 (S_base - S_ref) / S_ref (negative) at
//!   x_cp = (x_2 S_2 - x_1 S_1 - V_bt) / (S_2 - S_1). A pitch rate q adds the local angle
//!   q (x - x_cg) / V, so the body's pitch damping per rad of q d / 2V is
//!   Cm_q = -(4 / (S_ref d^2)) integral of dS/dx (x - x_cg)^2 dx (the same theory; e.g.
//!   Nielsen ch. 11). Domain: slender bodies at small angles; Nielsen finds the normal-force
//!   slope within about 10 % of measurements on ogive-cylinders up to low supersonic Mach.
//! - **Viscous crossflow** (H. J. Allen and E. W. Perkins, NACA Report 1048, 1951; L. H.
//!   Jorgensen, NASA TR R-474, 1977): the crossflow drag of the body's planform,
//!   CN_vis = eta c_dc (A_p / S_ref) sin(alpha) |sin(alpha)|, at the planform's centroid, with
//!   c_dc = 1.2 (a circular cylinder below the critical crossflow Mach number, M sin alpha <
//!   0.4) and eta the ratio of a finite cylinder's drag to an infinite one's, after Allen and
//!   Perkins' table as Jorgensen reproduces it ([`ETA_BY_FINENESS`], read from the figure).
//!   Jorgensen's comparisons put the sum within about 10 to 20 % of measured CN up to
//!   alpha = 30 deg; we state 30 % for this term alone (docs/aero.md).

use crate::config::Configuration;

/// Integration intervals over the body (midpoint rule; the profile is smooth on each part).
const STEPS: usize = 2000;
/// Crossflow drag coefficient of a circular cylinder, subcritical (Allen and Perkins 1951).
pub const CDC_SUBCRITICAL: f64 = 1.2;
/// eta against fineness L/d (Allen and Perkins 1951 as reproduced by Jorgensen 1977; read
/// from the figure to about 0.02).
pub const ETA_BY_FINENESS: [(f64, f64); 8] = [
    (1.0, 0.53),
    (2.0, 0.57),
    (4.0, 0.62),
    (8.0, 0.67),
    (12.0, 0.70),
    (20.0, 0.75),
    (40.0, 0.82),
    (1.0e9, 1.0),
];

/// The body's slender-body and crossflow quantities, referred to S_ref and d.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyTerms {
    /// The nose's CN_alpha \[1/rad\] (2 for a nose that reaches the full diameter).
    pub cn_alpha_nose_per_rad: f64,
    /// The nose's centre of pressure behind the tip \[m\].
    pub x_cp_nose_m: f64,
    /// The boattail's CN_alpha \[1/rad\] (0 without one, negative with one).
    pub cn_alpha_boattail_per_rad: f64,
    /// The boattail's centre of pressure \[m\] (its start without one).
    pub x_cp_boattail_m: f64,
    /// The body's pitch damping about the CG, per rad of q d / 2V.
    pub cm_q_per_rad: f64,
    /// Planform area A_p = integral of 2 r dx [m^2].
    pub planform_m2: f64,
    /// The planform's centroid behind the tip \[m\].
    pub x_planform_m: f64,
    /// eta of the body's fineness.
    pub eta: f64,
    /// The body's wetted area [m^2] (the lateral surface).
    pub wetted_m2: f64,
}

/// eta at fineness `l_over_d`, linear between the table's points.
pub fn eta(l_over_d: f64) -> f64 {
    let t = &ETA_BY_FINENESS;
    if l_over_d <= t[0].0 {
        return t[0].1;
    }
    for w in t.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if l_over_d <= x1 {
            return y0 + (y1 - y0) * (l_over_d - x0) / (x1 - x0);
        }
    }
    1.0
}

/// The body's terms of `c`.
pub fn terms(c: &Configuration) -> BodyTerms {
    let pi = std::f64::consts::PI;
    let s_ref = c.area_ref_m2;
    let d = c.diameter_m;
    let area = |x: f64| pi * c.radius_m(x).powi(2);
    let dx = c.length_m / STEPS as f64;
    let (mut planform, mut moment, mut wetted, mut damping) = (0.0, 0.0, 0.0, 0.0);
    for i in 0..STEPS {
        let (x0, x1) = (i as f64 * dx, (i + 1) as f64 * dx);
        let xm = 0.5 * (x0 + x1);
        let (r0, r1) = (c.radius_m(x0), c.radius_m(x1));
        let rm = c.radius_m(xm);
        planform += 2.0 * rm * dx;
        moment += 2.0 * rm * dx * xm;
        // Lateral surface of the frustum between the two stations.
        wetted += pi * (r0 + r1) * (dx * dx + (r1 - r0) * (r1 - r0)).sqrt();
        damping += (area(x1) - area(x0)) * (xm - c.cg_m).powi(2);
    }
    let l_n = c.nose_length_m;
    let nose_volume_m3 = integrate(0.0, l_n, area);
    let s_nose = area(l_n);
    let start = c.length_m - c.boattail_length_m;
    let (cn_bt, x_bt) = if c.boattail_length_m > 0.0 {
        let (s1, s2) = (area(start), area(c.length_m));
        let volume = integrate(start, c.length_m, area);
        (
            2.0 * (s2 - s1) / s_ref,
            (c.length_m * s2 - start * s1 - volume) / (s2 - s1),
        )
    } else {
        (0.0, start)
    };
    BodyTerms {
        cn_alpha_nose_per_rad: 2.0 * s_nose / s_ref,
        x_cp_nose_m: l_n - nose_volume_m3 / s_nose,
        cn_alpha_boattail_per_rad: cn_bt,
        x_cp_boattail_m: x_bt,
        cm_q_per_rad: -4.0 * damping / (s_ref * d * d),
        planform_m2: planform,
        x_planform_m: moment / planform,
        eta: eta(c.length_m / d),
        wetted_m2: wetted,
    }
}

/// The crossflow normal force coefficient at `alpha_rad` (odd in alpha).
pub fn crossflow_cn(b: &BodyTerms, area_ref_m2: f64, alpha_rad: f64) -> f64 {
    let s = alpha_rad.sin();
    b.eta * CDC_SUBCRITICAL * (b.planform_m2 / area_ref_m2) * s * s.abs()
}

/// Simpson's rule with [`STEPS`] intervals.
fn integrate(a: f64, b: f64, f: impl Fn(f64) -> f64) -> f64 {
    let h = (b - a) / STEPS as f64;
    let mut sum = f(a) + f(b);
    for i in 1..STEPS {
        let w = if i % 2 == 1 { 4.0 } else { 2.0 };
        sum += w * f(a + i as f64 * h);
    }
    sum * h / 3.0
}
