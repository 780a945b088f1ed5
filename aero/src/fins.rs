//! The fins: the panel pair's lift-curve slope over Mach, its centre of pressure, the body-fin
//! interference factors, and the fins' roll damping.
//!
//! - **Subsonic lift-curve slope** (Helmbold's equation as generalised by Diederich, USAF
//!   DATCOM section 4.1.3.2, eq. 4.1.3.2-a, with the section slope ratio kappa = 1):
//!   CL_alpha = 2 pi A / (2 + sqrt(4 + A^2 (beta^2 + tan^2 Lambda_c/2))), beta^2 = 1 - M^2,
//!   for M <= [`M_SUBSONIC_END`]. DATCOM gives it within a few percent of test data on
//!   straight-tapered planforms below the critical Mach number.
//! - **Supersonic lift-curve slope** (Ackeret's two-dimensional 4 / beta, beta^2 = M^2 - 1,
//!   with the loss of lift in the tip Mach cones of linear theory for a rectangular wing,
//!   CL_alpha = (4 / beta) (1 - 1 / (2 A beta)) for A beta >= 1; R. T. Jones and D. Cohen,
//!   *High Speed Wing Theory*, Princeton 1960, section 8): from M_sup = max(1.1, sqrt(1 +
//!   1/A^2)) up. On tapered and swept panels this is an approximation (docs/aero.md).
//! - **Transonic bridge**: between M_SUBSONIC_END and M_sup the slope is the straight line
//!   between the two methods' values. It is a bridge, not a method: its stated uncertainty is
//!   wider (docs/aero.md).
//! - **Centre of pressure** of a panel, behind its root leading edge: subsonic, Barrowman's
//!   x = (x_t / 3) (c_r + 2 c_t) / (c_r + c_t) + (c_r + c_t - c_r c_t / (c_r + c_t)) / 6
//!   (J. S. Barrowman, M.S. thesis 1967, section 3.3; the quarter chord of the mean
//!   aerodynamic chord); supersonic, each chordwise strip's half chord (Ackeret's flat plate)
//!   weighted by its chord, the planform's centroid; bridged as the slope is.
//! - **Interference** (W. C. Pitts, J. N. Nielsen and G. E. Kaattari, NACA Report 1307, 1957,
//!   slender-body theory, tau = r / (r + s)): the panel's lift in the presence of the body
//!   K_W(B) = (2/pi) [(1 + tau^4)(atan((1/tau - tau) / 2) / 2 + pi/4) -
//!   tau^2 ((1/tau - tau) + 2 atan(tau))] / (1 - tau)^2, and the body's lift carried over from the panels
//!   K_B(W) = (1 + tau)^2 - K_W(B) (the combination's total in the same theory). Report 1307
//!   finds the build-up within about 10 % of measured lift on wing-body combinations from
//!   subsonic to supersonic speeds; the slender-body K_B(W) is used at every Mach number here
//!   (the report's supersonic charts, lower for short afterbodies, are not carried).
//! - **Vortex lift at larger angles** (E. C. Polhamus' leading-edge suction analogy, NASA TN
//!   D-3767, 1966, and J. Aircraft 8(4), 1971, as commonly quoted; the papers not opened here):
//!   a sharp swept leading edge's lost suction reappears as normal force, CN = K_p sin a cos a +
//!   K_v sin^2 a, with K_v = (K_p - K_p^2 K_i) / cos Lambda_LE, K_i = 1 / (pi A) the potential
//!   induced-drag factor and K_p the pair's slope (Helmbold-Diederich at Mach 0, as his
//!   incompressible K_p). Only the vortex term is carried, the potential one staying linear as
//!   in the derivatives; a panel at roll phi meets sin(a_phi) = sin(a) cos(phi) and its normal
//!   force projects by cos(phi), so N equally spaced panels give, averaged over roll (the build-up
//!   is roll-independent), (4 N / 3 pi) K_v S_p sin(a) abs(sin(a)), at the planform's centroid.
//! - **Roll damping** (strip theory, Barrowman 1967 section 3.6): a strip at radius y of a
//!   panel rolling at p meets the flow at p y / V, so, per rad of p d / 2V,
//!   Cl_p = -(2 N CL_alpha / (S_ref d^2)) integral over the exposed span of c(y) y^2 dy.

use crate::config::Panel;

/// The subsonic method's last Mach number (DATCOM's Helmbold-Diederich slope, below the
/// critical Mach number of thin panels).
pub const M_SUBSONIC_END: f64 = 0.8;
/// The supersonic method's first Mach number, at least (the tip-cone correction also needs
/// A beta >= 1).
pub const M_SUPERSONIC_FLOOR: f64 = 1.1;

/// Which method gave a Mach number's values.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Regime {
    /// Helmbold-Diederich (DATCOM 4.1.3.2), M <= 0.8.
    Subsonic,
    /// The straight-line bridge between the two methods.
    Bridge,
    /// Ackeret with linear theory's tip correction, M >= M_sup.
    Supersonic,
}

impl Regime {
    /// Its name in the summary.
    pub fn name(self) -> &'static str {
        match self {
            Regime::Subsonic => "subsonic (Helmbold-Diederich)",
            Regime::Bridge => "transonic bridge (a straight line, not a method)",
            Regime::Supersonic => "supersonic (Ackeret, linear-theory tip correction)",
        }
    }
}

/// The first Mach number of the supersonic method for panel pairs of aspect ratio `a`.
pub fn m_supersonic(a: f64) -> f64 {
    (1.0 + 1.0 / (a * a)).sqrt().max(M_SUPERSONIC_FLOOR)
}

/// The regime at `mach` for aspect ratio `a` (without fins: that of a unit pair).
pub fn regime(mach: f64, a: f64) -> Regime {
    if mach <= M_SUBSONIC_END {
        Regime::Subsonic
    } else if mach < m_supersonic(a) {
        Regime::Bridge
    } else {
        Regime::Supersonic
    }
}

fn helmbold(p: &Panel, mach: f64) -> f64 {
    let a = p.aspect_ratio;
    let beta2 = 1.0 - mach * mach;
    2.0 * std::f64::consts::PI * a
        / (2.0 + (4.0 + a * a * (beta2 + p.tan_half_chord * p.tan_half_chord)).sqrt())
}

fn ackeret(p: &Panel, mach: f64) -> f64 {
    let beta = (mach * mach - 1.0).sqrt();
    (4.0 / beta) * (1.0 - 1.0 / (2.0 * p.aspect_ratio * beta))
}

/// The weight of the supersonic end in the bridge at `mach` (0 subsonic, 1 supersonic).
fn bridge_weight(p: &Panel, mach: f64) -> f64 {
    let hi = m_supersonic(p.aspect_ratio);
    ((mach - M_SUBSONIC_END) / (hi - M_SUBSONIC_END)).clamp(0.0, 1.0)
}

/// The panel pair's lift-curve slope on the pair's area 2 S_p \[1/rad\].
pub fn cl_alpha_per_rad(p: &Panel, mach: f64) -> f64 {
    match regime(mach, p.aspect_ratio) {
        Regime::Subsonic => helmbold(p, mach),
        Regime::Supersonic => ackeret(p, mach),
        Regime::Bridge => {
            let w = bridge_weight(p, mach);
            let lo = helmbold(p, M_SUBSONIC_END);
            let hi = ackeret(p, m_supersonic(p.aspect_ratio));
            lo + w * (hi - lo)
        }
    }
}

/// The panel's centre of pressure behind its root leading edge \[m\].
pub fn x_cp_from_root_le_m(p: &Panel, mach: f64) -> f64 {
    let (cr, ct, xt) = (p.root_chord_m, p.tip_chord_m, p.sweep_m);
    let sum = cr + ct;
    let subsonic = xt / 3.0 * (cr + 2.0 * ct) / sum + (sum - cr * ct / sum) / 6.0;
    let supersonic = centroid_from_root_le_m(p);
    subsonic + bridge_weight(p, mach) * (supersonic - subsonic)
}

/// The panel's planform centroid behind its root leading edge \[m\]: strips at eta = y/s have
/// chord c_r - (c_r - c_t) eta and leading edge x_t eta; the integral of c (x_le + c/2) over
/// the integral of c, in closed form.
pub fn centroid_from_root_le_m(p: &Panel) -> f64 {
    let (cr, ct, xt) = (p.root_chord_m, p.tip_chord_m, p.sweep_m);
    let dc = cr - ct;
    let int_c = cr - 0.5 * dc;
    let int_c_xle = xt * (0.5 * cr - dc / 3.0);
    let int_c2 = cr * cr - cr * dc + dc * dc / 3.0;
    (int_c_xle + 0.5 * int_c2) / int_c
}

/// Polhamus' vortex-lift factor K_v of the panel pair (module docs).
pub fn polhamus_kv(p: &Panel) -> f64 {
    let kp = helmbold(p, 0.0);
    let cos_le = 1.0 / (1.0 + (p.sweep_m / p.span_m).powi(2)).sqrt();
    (kp - kp * kp / (std::f64::consts::PI * p.aspect_ratio)) / cos_le
}

/// The fins' vortex lift on `area_ref_m2` at `alpha_rad`, averaged over roll (module docs).
pub fn vortex_cn(p: &Panel, area_ref_m2: f64, alpha_rad: f64) -> f64 {
    let s = alpha_rad.sin();
    4.0 * f64::from(p.count) / (3.0 * std::f64::consts::PI) * polhamus_kv(p) * p.area_m2
        / area_ref_m2
        * s
        * s.abs()
}

/// Pitts, Nielsen and Kaattari's K_W(B) and K_B(W) at `tau` = r / (r + s).
pub fn interference(tau: f64) -> (f64, f64) {
    let pi = std::f64::consts::PI;
    let k_wb = if tau <= 0.0 {
        1.0
    } else {
        let u = 1.0 / tau - tau;
        (2.0 / pi)
            * ((1.0 + tau.powi(4)) * (0.5 * (0.5 * u).atan() + 0.25 * pi)
                - tau * tau * (u + 2.0 * tau.atan()))
            / (1.0 - tau).powi(2)
    };
    (k_wb, (1.0 + tau).powi(2) - k_wb)
}

/// The fins' roll damping per rad of p d / 2V, on S_ref and d, with the pair's slope
/// `cl_alpha` and body radius `r_m`.
pub fn roll_damping_per_rad(p: &Panel, cl_alpha: f64, r_m: f64, area_ref_m2: f64, d_m: f64) -> f64 {
    // integral from r to r + s of c(y) y^2 dy, c = cr - (cr - ct) (y - r) / s, exactly.
    let (cr, k, s) = (
        p.root_chord_m,
        (p.root_chord_m - p.tip_chord_m) / p.span_m,
        p.span_m,
    );
    let y1 = r_m + s;
    let cube = |y: f64| y.powi(3) / 3.0;
    let quart = |y: f64| y.powi(4) / 4.0;
    let integral = (cr + k * r_m) * (cube(y1) - cube(r_m)) - k * (quart(y1) - quart(r_m));
    -2.0 * f64::from(p.count) * cl_alpha * integral / (area_ref_m2 * d_m * d_m)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Polhamus by hand: a delta pair of aspect ratio 1 (span 1, root chord 4, no tip chord)
    /// has tan Lambda_LE = 4 and a half-chord sweep of tan 2, so Helmbold-Diederich at Mach 0
    /// gives K_p = 2 pi / (2 + sqrt(4 + 1 + 4)) = 2 pi / 5, K_p^2 / (pi A) = 4 pi / 25 and
    /// K_v = (6 pi / 25) sqrt(17) = 3.1087, near slender-wing theory's pi as a delta should be;
    /// four such panels on S_ref = 8 at 30 deg carry (16 / 3 pi) K_v (2 / 8) (1/4).
    #[test]
    fn polhamus_by_hand() {
        let p = Panel {
            count: 4,
            root_chord_m: 4.0,
            tip_chord_m: 0.0,
            span_m: 1.0,
            thickness_m: 0.1,
            leading_edge_m: 0.0,
            sweep_m: 4.0,
            area_m2: 2.0,
            aspect_ratio: 1.0,
            tan_half_chord: 2.0,
            tau: 0.0,
            mac_m: 8.0 / 3.0,
        };
        let kv = 6.0 * std::f64::consts::PI / 25.0 * 17f64.sqrt();
        assert!((polhamus_kv(&p) - kv).abs() < 1e-12, "{}", polhamus_kv(&p));
        let cn = 16.0 / (3.0 * std::f64::consts::PI) * kv * 0.25 * 0.25;
        let got = vortex_cn(&p, 8.0, 30f64.to_radians());
        assert!((got - cn).abs() < 1e-12, "{got} {cn}");
        assert!((vortex_cn(&p, 8.0, -30f64.to_radians()) + cn).abs() < 1e-12);
    }
}
