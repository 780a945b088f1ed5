//! The estimate's directory: `aero.toml` (the scenario's `[aero]` in table form, inline),
//! `store.dml` (DAVE-ML 2.0 with each table's band as its `uncertainty`, `sepval-daveml`'s
//! export) and `summary.txt` (the derivatives at each Mach number with their uncertainties and
//! methods). Staged in a temporary directory beside the target and renamed into place once
//! complete, after the `[aero]` table has been read back into a scenario equal to the one
//! written: a refusal or a failure leaves nothing (no partial file, no partial directory).

use std::fmt::Write as _;
use std::path::Path;

use sepval_common::scenario::Scenario;
use sepval_core::atomic_file::write_atomically;
use sepval_daveml::{Provenance, to_daveml};

use crate::{AeroError, Estimate, tables};

/// The files of an estimate: (name, text).
pub fn files(e: &Estimate) -> Result<Vec<(&'static str, String)>, AeroError> {
    let (aero, bands) = tables::aero(e)?;
    let toml = tables::aero_toml(e, &aero)?;
    let scenario = tables::scenario(e, aero);
    // The [aero] text must read back as written, in the scenario it was made for.
    let mut text = Scenario::embedded_default().to_toml_string();
    let at = text.find("\n[aero]").map_or(0, |i| i + 1);
    let end = text[at + 1..]
        .find("\n[")
        .map_or(text.len(), |i| at + 2 + i);
    text.replace_range(at..end, &toml);
    let back = Scenario::from_toml_str(&text, "aero.toml").map_err(|err| AeroError::Table {
        field: "aero".into(),
        what: format!("does not read back: {err}"),
    })?;
    if back.aero != scenario.aero {
        return Err(AeroError::Table {
            field: "aero".into(),
            what: "reads back different from what was written".into(),
        });
    }
    let prov = Provenance::now(
        format!(
            "sepval aero --store-shape {} (docs/aero.md)",
            e.config.source
        ),
        Vec::new(),
    );
    let dml = to_daveml(&scenario, &bands, &prov).map_err(|e| AeroError::Table {
        field: "DAVE-ML".into(),
        what: e.to_string(),
    })?;
    Ok(vec![
        ("aero.toml", toml),
        ("store.dml", dml),
        ("summary.txt", summary(e)),
    ])
}

/// Writes the estimate into the new directory `dir` (refused if it exists).
pub fn write_dir(e: &Estimate, dir: &Path) -> Result<(), AeroError> {
    let fail = |path: &Path, what: String| AeroError::Output {
        path: path.to_path_buf(),
        what,
    };
    if dir.exists() {
        return Err(fail(dir, "exists: give a new directory".into()));
    }
    let files = files(e)?;
    let parent = match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let stage = sepval_core::atomic_file::staging(0o777)
        .tempdir_in(parent)
        .map_err(|err| fail(dir, format!("cannot stage the directory: {err}")))?;
    for (name, text) in &files {
        let path = stage.path().join(name);
        write_atomically(&path, text.as_bytes()).map_err(|err| fail(&path, err.to_string()))?;
    }
    let staged = stage.keep();
    std::fs::rename(&staged, dir).map_err(|err| {
        let _ = std::fs::remove_dir_all(&staged);
        fail(
            dir,
            format!("cannot move the staged directory into place: {err}"),
        )
    })
}

/// The summary: the configuration, then one line per Mach number.
pub fn summary(e: &Estimate) -> String {
    let c = &e.config;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{}: d = {} m, length {} m, CG {} m behind the nose tip, nose {:?} {} m",
        c.source, c.diameter_m, c.length_m, c.cg_m, c.nose, c.nose_length_m
    );
    if let Some(p) = &c.fins {
        let (kwb, kbw) = crate::fins::interference(p.tau);
        let _ = writeln!(
            s,
            "fins: {} panels, pair aspect ratio {:.3}, r/(r+s) = {:.3}, K_W(B) = {kwb:.3}, \
             K_B(W) = {kbw:.3}",
            p.count, p.aspect_ratio, p.tau
        );
    }
    if c.fins_on_boattail {
        let _ = writeln!(
            s,
            "warning: the fins' roots reach onto the boattail, outside the interference \
             factors' domain (a panel on a cylinder): expect CN_alpha and x_cp beyond their \
             stated accuracy (docs/aero.md, the Arcas model)"
        );
    }
    if c.extra_parts > 0 {
        let _ = writeln!(
            s,
            "{} extra parts of the file are not in the estimate",
            c.extra_parts
        );
    }
    let _ = writeln!(
        s,
        "per rad, moments about the CG, damping per rad of q d/2V; +- one stated sigma \
         (docs/aero.md); altitude {} m",
        e.altitude_m
    );
    let _ = writeln!(
        s,
        "{:>5} {:>15} {:>13} {:>15} {:>15} {:>13} {:>13}  method",
        "Mach", "CN_alpha", "x_cp [m]", "Cm_alpha", "Cm_q = Cn_r", "Cl_p", "CA0"
    );
    let pm = |v: crate::Estimated, w: usize| {
        format!("{:>w$}", format!("{:.3}+-{:.3}", v.value, v.sigma))
    };
    for p in &e.points {
        let _ = writeln!(
            s,
            "{:>5.2} {} {} {} {} {} {}  {}",
            p.mach,
            pm(p.cn_alpha_per_rad, 15),
            pm(p.x_cp_m, 13),
            pm(p.cm_alpha_per_rad, 15),
            pm(p.cm_q_per_rad, 15),
            pm(p.cl_p_per_rad, 13),
            pm(p.ca0, 13),
            p.regime.name()
        );
    }
    let marginal: Vec<String> = e
        .points
        .iter()
        .filter(|p| p.cm_alpha_per_rad.value.abs() < 2.0 * p.cm_alpha_per_rad.sigma)
        .map(|p| format!("{:.2}", p.mach))
        .collect();
    if !marginal.is_empty() {
        let _ = writeln!(
            s,
            "warning: Cm_alpha's sign is not determined (|Cm_alpha| < 2 sigma) at Mach {}",
            marginal.join(", ")
        );
    }
    s
}
