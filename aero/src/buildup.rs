//! The component build-up at one Mach number (Missile DATCOM's approach: W. B. Blake, *Missile
//! DATCOM User's Manual, 1997 FORTRAN 90 Revision*, AFRL-VA-WP-TR-1998-3009; Barrowman 1967):
//! the body's and the fins' normal forces summed with the interference factors, the centre of
//! pressure their moment over their sum, and from it and the fins' lift at their arm the
//! derivatives in docs/model.md's conventions:
//!
//! - CZ_alpha = -CN_alpha; CY_beta = -CN_alpha (a body of revolution with 3 or 4 fins);
//! - Cm_alpha = -CN_alpha (x_cp - x_cg) / d (nose up positive, stable negative), Cn_beta =
//!   -Cm_alpha (stable positive);
//! - Cm_q = Cn_r = body's + fins' -2 CN_alpha,fins (K_W(B) + K_B(W)) ((x_fin - x_cg) / d)^2,
//!   per rad of q d / 2V (a pitch rate q meets the fins at q (x_fin - x_cg) / V);
//! - Cl_p from the fins' strip theory ([`crate::fins::roll_damping_per_rad`]).
//!
//! Each value carries its stated uncertainty ([`Accuracy`], docs/aero.md): the fraction of the
//! value (or, for the centre of pressure, of the body's length) its method's validation gives,
//! and where a part is outside its method's domain more, by a stated rule (ours): the
//! boattail's slender-body lift and fins whose roots reach onto a boattail as independent
//! errors of those parts' CN_alpha at their centres of pressure, propagated to CN_alpha, x_cp
//! and Cm_alpha; CA0 wider by what a misplaced drag rise and the fins' unmodelled transonic
//! drag can change ([`drag_rise_sigma`]).

use sepval_common::atmosphere::AirState;

use crate::body::{self, BodyTerms};
use crate::config::Configuration;
use crate::drag::{self, AxialParts};
use crate::fins::{self, Regime};

/// The stated accuracies, as fractions (docs/aero.md says where each comes from). The bands
/// written with the estimate read each as one standard deviation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accuracy {
    /// CN_alpha, subsonic and supersonic: 10 % (Missile DATCOM's goal, as commonly quoted).
    pub cn_alpha: f64,
    /// CN_alpha in the transonic bridge: 25 % (ours: the bridge is not a method).
    pub cn_alpha_bridge: f64,
    /// The centre of pressure, as a fraction of the body's length: 4 % (DATCOM's goal).
    pub x_cp_of_length: f64,
    /// Cm_q and Cn_r: 30 % (ours, from the Basic Finner comparison of docs/aero.md).
    pub damping: f64,
    /// Cl_p: 20 % (ours, from the Basic Finner comparison of docs/aero.md).
    pub roll_damping: f64,
    /// CA0: 20 % (DATCOM's goal), 30 % in the bridge (ours).
    pub axial: f64,
    /// CA0 in the bridge.
    pub axial_bridge: f64,
    /// The viscous crossflow term: 30 % (ours, after Jorgensen 1977's comparisons).
    pub crossflow: f64,
    /// Outside the domain: the boattail's slender-body CN_alpha, 50 % of it (ours: the
    /// inviscid loss, which the viscous flow can only reduce; none to all of it read as +-2
    /// sigma).
    pub boattail_lift: f64,
    /// Outside the domain: the fins' CN_alpha when their roots reach onto the boattail, 30 %
    /// of it (ours, from the Arcas model: its fins carry 22 % less than estimated).
    pub fins_on_boattail: f64,
}

/// How far in Mach the estimate may misplace the drag rise, read as one sigma (ours: the
/// half-width of the transonic band 0.8 to 1.2 in which a store's drag rises; docs/aero.md
/// "The stated uncertainty of each").
pub const DRAG_RISE_SHIFT_MACH: f64 = 0.1;

/// The accuracies this crate states.
pub const ACCURACY: Accuracy = Accuracy {
    cn_alpha: 0.10,
    cn_alpha_bridge: 0.25,
    x_cp_of_length: 0.04,
    damping: 0.30,
    roll_damping: 0.20,
    axial: 0.20,
    axial_bridge: 0.30,
    crossflow: 0.30,
    boattail_lift: 0.50,
    fins_on_boattail: 0.30,
};

/// A value and its stated uncertainty (one standard deviation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimated {
    /// The estimate.
    pub value: f64,
    /// Its stated uncertainty.
    pub sigma: f64,
}

/// Everything estimated at one Mach number.
#[derive(Debug, Clone, PartialEq)]
pub struct MachPoint {
    /// Mach number.
    pub mach: f64,
    /// Which fin method gave it.
    pub regime: Regime,
    /// CN_alpha of the whole store \[1/rad\].
    pub cn_alpha_per_rad: Estimated,
    /// The fins' part of it, with interference \[1/rad\].
    pub cn_alpha_fins_per_rad: f64,
    /// K_W(B) and K_B(W).
    pub interference: (f64, f64),
    /// Centre of pressure behind the nose tip \[m\].
    pub x_cp_m: Estimated,
    /// Cm_alpha about the CG \[1/rad\].
    pub cm_alpha_per_rad: Estimated,
    /// Cm_q = Cn_r, per rad of q d / 2V.
    pub cm_q_per_rad: Estimated,
    /// Cl_p, per rad of p d / 2V.
    pub cl_p_per_rad: Estimated,
    /// CA0 and its parts.
    pub ca0: Estimated,
    /// CA0's parts.
    pub axial_parts: AxialParts,
}

/// The build-up of `c` (body terms `b`) at `mach` in `air`.
pub fn at_mach(c: &Configuration, b: &BodyTerms, mach: f64, air: &AirState) -> MachPoint {
    let d = c.diameter_m;
    let r = 0.5 * d;
    let cn_body = b.cn_alpha_nose_per_rad + b.cn_alpha_boattail_per_rad;
    let moment_body =
        b.cn_alpha_nose_per_rad * b.x_cp_nose_m + b.cn_alpha_boattail_per_rad * b.x_cp_boattail_m;
    let (mut cn, mut moment, mut cm_q, mut cl_p) = (cn_body, moment_body, b.cm_q_per_rad, 0.0);
    let (mut cn_fins, mut k, mut x_fin) = (0.0, (1.0, 0.0), 0.0);
    let regime = match &c.fins {
        None => fins::regime(mach, 1.0),
        Some(p) => {
            let cl_alpha = fins::cl_alpha_per_rad(p, mach);
            k = fins::interference(p.tau);
            // N/2 panels' worth of the pair's slope (Barrowman 1967 section 3.3), on S_ref.
            let cn_panels = 0.5 * f64::from(p.count) * cl_alpha * p.area_m2 / c.area_ref_m2;
            cn_fins = cn_panels * (k.0 + k.1);
            x_fin = p.leading_edge_m + fins::x_cp_from_root_le_m(p, mach);
            cn += cn_fins;
            moment += cn_fins * x_fin;
            cm_q += -2.0 * cn_fins * ((x_fin - c.cg_m) / d).powi(2);
            cl_p = fins::roll_damping_per_rad(p, cl_alpha, r, c.area_ref_m2, d);
            fins::regime(mach, p.aspect_ratio)
        }
    };
    let x_cp = moment / cn;
    let cm_alpha = -cn * (x_cp - c.cg_m) / d;
    let bridge = regime == Regime::Bridge;
    let a = ACCURACY;
    let frac = if bridge {
        a.cn_alpha_bridge
    } else {
        a.cn_alpha
    };
    // Outside the domain: independent errors of a part's CN_alpha at its centre of pressure.
    let mut outside = vec![(
        a.boattail_lift * b.cn_alpha_boattail_per_rad.abs(),
        b.x_cp_boattail_m,
    )];
    if c.fins_on_boattail {
        outside.push((a.fins_on_boattail * cn_fins.abs(), x_fin));
    }
    let (sigma_cn, sigma_x, sigma_cm) = spread(c, cn, x_cp, frac, &outside);
    let parts = drag::axial(c, mach, air, b.wetted_m2);
    let ca0 = parts.total();
    let ca_frac = if bridge { a.axial_bridge } else { a.axial };
    let sigma_ca = (ca_frac * ca0).hypot(drag_rise_sigma(c, b, mach, air));
    MachPoint {
        mach,
        regime,
        cn_alpha_per_rad: Estimated {
            value: cn,
            sigma: sigma_cn,
        },
        cn_alpha_fins_per_rad: cn_fins,
        interference: k,
        x_cp_m: Estimated {
            value: x_cp,
            sigma: sigma_x,
        },
        cm_alpha_per_rad: Estimated {
            value: cm_alpha,
            sigma: sigma_cm,
        },
        cm_q_per_rad: Estimated {
            value: cm_q,
            sigma: a.damping * cm_q.abs(),
        },
        cl_p_per_rad: Estimated {
            value: cl_p,
            sigma: a.roll_damping * cl_p.abs(),
        },
        ca0: Estimated {
            value: ca0,
            sigma: sigma_ca,
        },
        axial_parts: parts,
    }
}

/// The sigmas of CN_alpha, x_cp and Cm_alpha of `c` (CN_alpha `cn`, centre of pressure
/// `x_cp`): in the domain `frac` of CN_alpha and [`Accuracy::x_cp_of_length`], Cm_alpha's
/// from both; each of `outside`'s (sigma of a part's CN_alpha, its centre of pressure) added
/// in quadrature as an independent error of that part: to CN_alpha itself, to Cm_alpha at
/// its arm from the CG and to x_cp at its arm from x_cp (the first-order propagation of
/// x_cp = sum CN_i x_i / sum CN_i). A statically marginal store keeps the whole of x_cp's
/// error in Cm_alpha's sigma, so the sign is undetermined where |Cm_alpha| < 2 sigma.
fn spread(
    c: &Configuration,
    cn: f64,
    x_cp: f64,
    frac: f64,
    outside: &[(f64, f64)],
) -> (f64, f64, f64) {
    let d = c.diameter_m;
    let sigma_cn0 = frac * cn.abs();
    let sigma_x0 = ACCURACY.x_cp_of_length * c.length_m;
    let mut cn2 = sigma_cn0.powi(2);
    let mut x2 = sigma_x0.powi(2);
    let mut cm2 = (sigma_cn0 * (x_cp - c.cg_m) / d).powi(2) + (cn * sigma_x0 / d).powi(2);
    for &(s, x) in outside {
        cn2 += s * s;
        x2 += (s * (x - x_cp) / cn).powi(2);
        cm2 += (s * (x - c.cg_m) / d).powi(2);
    }
    (cn2.sqrt(), x2.sqrt(), cm2.sqrt())
}

/// The part of CA0's sigma for what the methods leave out near the drag rise (ours,
/// docs/aero.md): the Mach number at which a store's drag rises is what the methods place least
/// well (McCoy's critical Mach number fitted to projectiles, his fixed 0.85 for a boattail, a
/// step at Mach 1), so CA0 at `mach` is uncertain by the largest change of the estimate's CA0
/// within [`DRAG_RISE_SHIFT_MACH`] of it (sampled every 0.005, not below Mach 0.3): large in the
/// rise, small where the drag is flat. In quadrature, where the fins' wave drag is bridged
/// (0.8 < M < M_sup), its whole value at M_sup: their transonic drag is not modelled.
pub fn drag_rise_sigma(c: &Configuration, b: &BodyTerms, mach: f64, air: &AirState) -> f64 {
    let at = |m: f64| drag::axial(c, m, air, b.wetted_m2).total();
    let here = at(mach);
    let shift = (-20..=20)
        .map(|i| mach + DRAG_RISE_SHIFT_MACH * f64::from(i) / 20.0)
        .filter(|m| *m >= 0.3)
        .map(|m| (at(m) - here).abs())
        .fold(0.0, f64::max);
    let fins = match &c.fins {
        Some(p) if mach > fins::M_SUBSONIC_END && mach < fins::m_supersonic(p.aspect_ratio) => {
            drag::fin_wave_at_m_sup(c, p)
        }
        _ => 0.0,
    };
    shift.hypot(fins)
}

/// The normal force and pitching moment about the CG at `alpha_rad` that are not linear in
/// alpha: the body's viscous crossflow and the fins' vortex lift (Polhamus, at their planform's
/// centroid; [`fins::vortex_cn`]): (CN, Cm), and each one's band, the crossflow accuracy
/// (30 %) of each part added in absolute value (the parts' errors not known independent; ours).
pub fn crossflow(c: &Configuration, b: &BodyTerms, alpha_rad: f64) -> ((f64, f64), (f64, f64)) {
    let d = c.diameter_m;
    let cn_body = body::crossflow_cn(b, c.area_ref_m2, alpha_rad);
    let cm_body = -cn_body * (b.x_planform_m - c.cg_m) / d;
    let (cn_fins, cm_fins) = c.fins.as_ref().map_or((0.0, 0.0), |p| {
        let cn = fins::vortex_cn(p, c.area_ref_m2, alpha_rad);
        let x = p.leading_edge_m + fins::centroid_from_root_le_m(p);
        (cn, -cn * (x - c.cg_m) / d)
    });
    let f = ACCURACY.crossflow;
    (
        (cn_body + cn_fins, cm_body + cm_fins),
        (
            f * (cn_body.abs() + cn_fins.abs()),
            f * (cm_body.abs() + cm_fins.abs()),
        ),
    )
}
