//! `sepval scenario`: a scenario written as TOML (the embedded default to start your own), or
//! with `--tables` as a directory of TOML and CSV tables (docs/model.md section 1, "Tables");
//! `--from-daveml` and `--to-daveml` read and write the store's aerodynamics as DAVE-ML
//! (docs/daveml.md, the crate `sepval_daveml`); `--from-shape` puts the store's `[aero]`
//! estimated from its shape in the scenario (docs/aero.md, `sepval_aero::start`).

use anyhow::{Context, Result};
use sepval_common::scenario::Scenario;
use sepval_core::atomic_file::write_atomically;
use sepval_run::inputs;
use sepval_run::out_dir::Input;

use crate::cli::ScenarioArgs;

const HEADER: &str = "# sepval scenario (SI units, angles in degrees); docs/model.md section 1 describes each field.\n";

/// The scenario as `sepval scenario` writes it: TOML, with a header comment.
pub fn toml_text(scenario: &Scenario) -> String {
    format!("{HEADER}{}", scenario.to_toml_string())
}

/// Runs `sepval scenario`.
pub fn run(args: ScenarioArgs) -> Result<()> {
    if let Some(model) = &args.from_daveml {
        return from_daveml(&args, model);
    }
    if !args.tables {
        // The file written may be neither the scenario read nor a table it names.
        let mut read = super::scenario_inputs(args.scenario.as_ref(), None);
        read.extend(Input::files("--from-shape", args.from_shape.as_ref()));
        super::out_file_apart(&args.out, &read)?;
    }
    let mut scenario = inputs::scenario(args.scenario.as_deref(), None)?;
    if let Some(shape) = &args.from_shape {
        let base = scenario.factors;
        scenario = sepval_aero::start::scenario_from_shape(shape, &scenario)?;
        widened_note(&base, &scenario);
    }
    if args.to_daveml {
        let prov = sepval_daveml::Provenance::now(
            inputs::scenario_name(args.scenario.as_deref()),
            Vec::new(),
        );
        sepval_daveml::write_model(&args.out, &scenario, &[], &prov)?;
        note!("wrote {} (DAVE-ML 2.0)", args.out.display());
        return Ok(());
    }
    if !args.tables {
        let text = toml_text(&scenario);
        write_atomically(&args.out, text.as_bytes())?;
        note!("wrote {}", args.out.display());
        return Ok(());
    }
    let form = sepval_common::table_form::table_form(&scenario, args.interference_tables)
        .map_err(anyhow::Error::msg)
        .context("--tables")?;
    let dir = &args.out;
    let header = format!(
        "{HEADER}# Tables: docs/model.md section 1 (\"Tables\"); CSV files are relative to this file.\n"
    );
    form.write_new_dir(dir, &header, None)
        .with_context(|| format!("--out {}", dir.display()))?;
    let toml_path = dir.join("scenario.toml");
    note!(
        "wrote {} and {} table files in {}",
        toml_path.display(),
        form.files.len(),
        dir.join("tables").display()
    );
    Ok(())
}

/// Says which factors' ranges `--from-shape` widened to the estimate's band (docs/aero.md,
/// "The estimate as a starting point").
fn widened_note(base: &sepval_core::factors::FactorTable, scenario: &Scenario) {
    for f in sepval_aero::start::widened(base, &scenario.factors) {
        let (was, now) = (base.spec(f), scenario.factors.spec(f));
        note!(
            "factors: {} range {:.4} to {:.4} (was {} to {}): {} of the estimate's sigmas at Mach {}",
            f.name(),
            now.min,
            now.max,
            was.min,
            was.max,
            sepval_aero::start::RANGE_SIGMAS,
            scenario.flight.mach
        );
    }
}

/// `--from-daveml`: the model read into the scenario, its checkData passed, written in table
/// form into a new directory (nothing written when it is refused).
fn from_daveml(args: &ScenarioArgs, model: &std::path::Path) -> Result<()> {
    let base = inputs::scenario(args.scenario.as_deref(), None)?;
    let map = sepval_daveml::load_map(args.map.as_deref())?;
    let imported = sepval_daveml::read_model(model, &map, &base)?;
    let form = sepval_daveml::output::write_table_dir(
        &imported.scenario,
        &args.out,
        &model.display().to_string(),
    )?;
    for n in &imported.notes {
        note!("note: {n}");
    }
    say!(
        "read {}: {} ({} check outputs matched)",
        model.display(),
        imported.fields.join(", "),
        imported.checked
    );
    note!(
        "wrote {} and {} table files in {}",
        args.out.join("scenario.toml").display(),
        form.files.len(),
        args.out.join("tables").display()
    );
    Ok(())
}
