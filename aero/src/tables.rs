//! The estimate in the scenario's table form (docs/model.md section 1, "Tables"): the seven
//! derivatives and CA0 as tables over Mach, and the part of CN that is not linear in alpha
//! (the body's viscous crossflow and the fins' vortex lift), as the static tables `cz`, `cm`
//! over alpha and `cy`, `cn` over beta (section 3 adds them to the linear terms). Neither
//! depends on Mach here (subcritical c_dc; Polhamus' incompressible K_p), so those tables have
//! no Mach axis. With each table its band: one
//! standard deviation per value, the stated uncertainty ([`crate::buildup::ACCURACY`]), for
//! DAVE-ML's `uncertainty` (docs/daveml.md) through `sepval-daveml`'s export.

use sepval_common::correction::{Derivative, Target};
use sepval_common::scenario::{Aero, Scenario};
use sepval_common::table::{Axis, Kind, Table, TableKind, Tabulated, Variable};
use sepval_daveml::Band;

use crate::buildup::{Estimated, MachPoint};
use crate::{AeroError, Estimate};

fn table<K: TableKind>(
    field: &str,
    axes: Vec<Axis>,
    values: Vec<f64>,
    kind: Kind,
) -> Result<Tabulated<K>, AeroError> {
    let what = |what: String| AeroError::Table {
        field: field.to_string(),
        what,
    };
    let t = Table::new(axes, values, kind).map_err(|e| what(e.to_string()))?;
    Tabulated::<K>::table(t).map_err(|e| what(e.to_string()))
}

fn mach_axis(e: &Estimate) -> Vec<Axis> {
    vec![Axis {
        variable: Variable::Mach,
        breakpoints: e.points.iter().map(|p| p.mach).collect(),
    }]
}

/// The seven derivatives' values and sigmas over Mach, in [`Derivative::ALL`]'s order.
fn derivatives(e: &Estimate) -> Vec<(Derivative, Vec<f64>, Vec<f64>)> {
    let of = |f: &dyn Fn(&MachPoint) -> Estimated, sign: f64| {
        let v: Vec<f64> = e.points.iter().map(|p| sign * f(p).value).collect();
        let s: Vec<f64> = e.points.iter().map(|p| f(p).sigma).collect();
        (v, s)
    };
    let cn = of(&|p| p.cn_alpha_per_rad, -1.0);
    let cm = of(&|p| p.cm_alpha_per_rad, 1.0);
    let cn_beta = of(&|p| p.cm_alpha_per_rad, -1.0);
    let cl_p = of(&|p| p.cl_p_per_rad, 1.0);
    let cm_q = of(&|p| p.cm_q_per_rad, 1.0);
    vec![
        (Derivative::CzAlpha, cn.0.clone(), cn.1.clone()),
        (Derivative::CyBeta, cn.0, cn.1),
        (Derivative::CmAlpha, cm.0, cm.1),
        (Derivative::CnBeta, cn_beta.0, cn_beta.1),
        (Derivative::ClP, cl_p.0, cl_p.1),
        (Derivative::CmQ, cm_q.0.clone(), cm_q.1.clone()),
        (Derivative::CnR, cm_q.0, cm_q.1),
    ]
}

/// The scenario's `[aero]` of the estimate, and the band of each of its tables.
pub fn aero(e: &Estimate) -> Result<(Aero, Vec<Band>), AeroError> {
    let mut bands = Vec::new();
    let d = derivatives(e);
    let mut tab = |i: usize| -> Result<_, AeroError> {
        let (which, values, sigma) = &d[i];
        bands.push(Band {
            target: Target::Derivative(*which),
            sigma: sigma.clone(),
            correlations: Vec::new(),
        });
        table(
            &Target::Derivative(*which).field(),
            mach_axis(e),
            values.clone(),
            Kind::Derivative,
        )
    };
    let (cz_a, cy_b, cm_a, cn_b, cl_p, cm_q, cn_r) = (
        tab(0)?,
        tab(1)?,
        tab(2)?,
        tab(3)?,
        tab(4)?,
        tab(5)?,
        tab(6)?,
    );
    let ca: Vec<f64> = e.points.iter().map(|p| p.ca0.value).collect();
    bands.push(Band {
        target: Target::Static(0),
        sigma: e.points.iter().map(|p| p.ca0.sigma).collect(),
        correlations: Vec::new(),
    });
    let ca0 = table("aero.ca0", mach_axis(e), ca, Kind::Static)?;
    let angle = |variable| {
        vec![Axis {
            variable,
            breakpoints: e.alpha_deg.clone(),
        }]
    };
    let cn_vis: Vec<f64> = e.crossflow.iter().map(|c| c.0).collect();
    let cm_vis: Vec<f64> = e.crossflow.iter().map(|c| c.1).collect();
    let neg = |v: &[f64]| v.iter().map(|x| -x).collect::<Vec<f64>>();
    let cn_band: Vec<f64> = e.crossflow_sigma.iter().map(|c| c.0).collect();
    let cm_band: Vec<f64> = e.crossflow_sigma.iter().map(|c| c.1).collect();
    for (i, v) in [(1, &cn_band), (2, &cn_band), (4, &cm_band), (5, &cm_band)] {
        bands.push(Band {
            target: Target::Static(i),
            sigma: v.clone(),
            correlations: Vec::new(),
        });
    }
    let static_table = |field: &str, variable, values: Vec<f64>| {
        table(field, angle(variable), values, Kind::Static).map(Some)
    };
    let aero = Aero {
        ca0,
        cz_alpha_per_rad: Some(cz_a),
        cy_beta_per_rad: Some(cy_b),
        cm_alpha_per_rad: Some(cm_a),
        cn_beta_per_rad: Some(cn_b),
        cl_p_per_rad: cl_p,
        cm_q_per_rad: cm_q,
        cn_r_per_rad: cn_r,
        cy: static_table("aero.cy", Variable::Beta, neg(&cn_vis))?,
        cz: static_table("aero.cz", Variable::Alpha, neg(&cn_vis))?,
        cl: None,
        cm: static_table("aero.cm", Variable::Alpha, cm_vis.clone())?,
        cn: static_table("aero.cn", Variable::Beta, neg(&cm_vis))?,
    };
    Ok((aero, bands))
}

/// The text of `aero.toml`: the `[aero]` table a scenario takes in place of its own, with a
/// header saying what it is.
pub fn aero_toml(e: &Estimate, aero: &Aero) -> Result<String, AeroError> {
    #[derive(serde::Serialize)]
    struct Section<'a> {
        aero: &'a Aero,
    }
    let body = toml::to_string(&Section { aero }).map_err(|err| AeroError::Table {
        field: "aero".into(),
        what: err.to_string(),
    })?;
    Ok(format!(
        "# The freestream aerodynamics of {} estimated from its shape by component build-up\n\
         # (sepval aero, docs/aero.md): reference diameter {} m, moments about the CG {} m\n\
         # behind the nose tip. Put this [aero] table in a scenario in place of its own\n\
         # (docs/model.md section 1, \"Tables\"); store.dml holds the same with uncertainties.\n{body}",
        e.config.source, e.config.diameter_m, e.config.cg_m
    ))
}

/// A scenario carrying the estimate: the embedded default with this `[aero]`, the store's
/// diameter and no interference (a freestream estimate), for the DAVE-ML export.
pub fn scenario(e: &Estimate, aero: Aero) -> Scenario {
    let mut s = Scenario::embedded_default();
    s.name = "aero-estimate".into();
    s.description = format!(
        "freestream aerodynamics of {} from its shape",
        e.config.source
    );
    s.store.diameter_m = e.config.diameter_m;
    s.aero = aero;
    for (_, c) in s.interference.increments_mut() {
        *c = Tabulated::constant(0.0);
    }
    s
}
