//! Stage 5, **write**: the imported scenario as a directory in table form (`scenario.toml` and
//! `tables/*.csv`, docs/model.md section 1 "Tables"), staged in a temporary directory beside
//! the target, read back and compared, then renamed into place by
//! [`TableForm::write_new_dir`]: a refusal or a failure leaves nothing (no partial file, no
//! partial directory).

use std::path::{Path, PathBuf};

use sepval_common::correction::Target;
use sepval_common::scenario::Scenario;
use sepval_common::table::{Coefficient, Kind, TableFile, write_csv};
use sepval_common::table_form::TableForm;

use crate::assemble::{field, set_field};
use crate::error::DavemlError;
use crate::import::kind_of;

/// The field's key within its section, e.g. `cz` or `dcz0`.
fn key(t: Target) -> String {
    let f = t.field();
    f.split_once('.').map_or(f.clone(), |(_, k)| k.to_string())
}

/// Every table of `s` as a file of its own, `tables/<field>.csv`.
pub fn table_dir(s: &Scenario) -> TableForm {
    let mut scenario = s.clone();
    let mut files = Vec::new();
    for t in Target::all() {
        let Some(Coefficient::Table(table)) = field(s, t) else {
            continue;
        };
        let k = key(t);
        let path = PathBuf::from(format!("tables/{k}.csv"));
        let unit = match kind_of(t) {
            Kind::Derivative => "1/rad",
            _ => "-",
        };
        files.push((
            path.clone(),
            write_csv(table.axes(), &[(&k, unit, table.values())]),
        ));
        let reference = Coefficient::File(TableFile {
            csv: path,
            column: Some(k),
        });
        set_field(&mut scenario, t, Some(reference));
    }
    TableForm { scenario, files }
}

/// Writes `s` in table form into the new directory `dir` (refused if it exists and is not
/// empty), with a header naming `source`; the directory appears only once complete and read
/// back equal to `s` ([`TableForm::write_new_dir`]).
pub fn write_table_dir(s: &Scenario, dir: &Path, source: &str) -> Result<TableForm, DavemlError> {
    let form = table_dir(s);
    let header = format!(
        "# sepval scenario (SI units, angles in degrees) imported from the DAVE-ML model {source}\n# (docs/daveml.md); docs/model.md section 1 describes each field, CSV files are relative to this file.\n"
    );
    form.write_new_dir(dir, &header, Some(s))?;
    Ok(form)
}
