//! A scenario's tables set up at its flight Mach (docs/model.md section 3, "Tabulated
//! coefficients"): Mach axes interpolated once, constants gathered, the rest handed to
//! [`PreparedTables`] for the force evaluation. It lives with the model, which knows scenarios,
//! so that `crate::table` depends on nothing of `crate::scenario` (the dependency runs one way:
//! scenario -> table).

use crate::scenario::Scenario;
use crate::table::{Coefficient, PreparedTables, Target};

/// The freestream database's constants at the flight Mach: the scenario's constants, and its
/// derivative tables (and a CA table over Mach only) interpolated at the Mach. A derivative
/// left out (a static table replaces it) is 0; a CA tabulated over alpha or beta is 0 here and
/// interpolated at each force evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
#[allow(missing_docs)]
pub struct AeroAtMach {
    pub ca0: f64,
    pub cz_alpha_per_rad: f64,
    pub cy_beta_per_rad: f64,
    pub cm_alpha_per_rad: f64,
    pub cn_beta_per_rad: f64,
    pub cl_p_per_rad: f64,
    pub cm_q_per_rad: f64,
    pub cn_r_per_rad: f64,
}

/// A scenario's tables set up at its flight Mach (docs/model.md section 3): the constants of
/// the freestream database, the constant interference increments at carriage (0 for a
/// tabulated one) and the tables the force evaluation interpolates.
pub fn prepare(scenario: &Scenario) -> (AeroAtMach, [f64; 6], PreparedTables) {
    let mach = scenario.flight.mach;
    let mut p = PreparedTables::default();
    let a = &scenario.aero;
    let unread = "a validated scenario holds no unread table files";
    let derivative = |p: &mut PreparedTables, name: &str, c: Option<&Coefficient>| match c {
        None => 0.0,
        Some(Coefficient::Constant(v)) => *v,
        Some(Coefficient::Table(t)) => p.slice_mach(name, t, mach).2[0],
        Some(Coefficient::File(_)) => unreachable!("{unread}"),
    };
    let mut consts = AeroAtMach {
        ca0: 0.0,
        cz_alpha_per_rad: derivative(
            &mut p,
            "aero.cz_alpha_per_rad",
            a.cz_alpha_per_rad.as_ref().map(|c| &c.value),
        ),
        cy_beta_per_rad: derivative(
            &mut p,
            "aero.cy_beta_per_rad",
            a.cy_beta_per_rad.as_ref().map(|c| &c.value),
        ),
        cm_alpha_per_rad: derivative(
            &mut p,
            "aero.cm_alpha_per_rad",
            a.cm_alpha_per_rad.as_ref().map(|c| &c.value),
        ),
        cn_beta_per_rad: derivative(
            &mut p,
            "aero.cn_beta_per_rad",
            a.cn_beta_per_rad.as_ref().map(|c| &c.value),
        ),
        cl_p_per_rad: derivative(&mut p, "aero.cl_p_per_rad", Some(&a.cl_p_per_rad.value)),
        cm_q_per_rad: derivative(&mut p, "aero.cm_q_per_rad", Some(&a.cm_q_per_rad.value)),
        cn_r_per_rad: derivative(&mut p, "aero.cn_r_per_rad", Some(&a.cn_r_per_rad.value)),
    };
    let statics = [
        ("aero.ca0", Some(&a.ca0)),
        ("aero.cy", a.cy.as_ref()),
        ("aero.cz", a.cz.as_ref()),
        ("aero.cl", a.cl.as_ref()),
        ("aero.cm", a.cm.as_ref()),
        ("aero.cn", a.cn.as_ref()),
    ];
    for (k, (name, c)) in statics.into_iter().enumerate() {
        match c.map(|c| &c.value) {
            None => {}
            Some(Coefficient::Constant(v)) if k == 0 => consts.ca0 = *v,
            Some(Coefficient::Constant(v)) => {
                p.add_constant(k, *v);
            }
            Some(Coefficient::Table(t)) => {
                let (id, axes, values) = p.slice_mach(name, t, mach);
                if k == 0 && axes.is_empty() {
                    // CA over Mach only: a constant of the run, as the contract's CA0.
                    consts.ca0 = values[0];
                } else {
                    p.add_runtime(id, Target::Static(k), axes, values);
                }
            }
            Some(Coefficient::File(_)) => unreachable!("{unread}"),
        }
    }
    let mut increments = [0.0; 6];
    for (k, (name, c)) in scenario.interference.increments().into_iter().enumerate() {
        match &c.value {
            Coefficient::Constant(v) => increments[k] = *v,
            Coefficient::Table(t) => {
                let (id, axes, values) = p.slice_mach(name, t, mach);
                p.add_runtime(id, Target::Interference(k), axes, values);
            }
            Coefficient::File(_) => unreachable!("{unread}"),
        }
    }
    (consts, increments, p)
}
