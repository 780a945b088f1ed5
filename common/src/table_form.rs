//! A constant-form scenario written as tables: the starting point `sepval scenario --tables`
//! writes for users who bring their own tabulated data.
//!
//! Source: `docs/model.md` section 1 ("Tables"). The linear terms of section 3 become static
//! tables over Mach, alpha and beta (CA = CA0, CY = CY_beta beta, CZ = CZ_alpha alpha, Cl = 0,
//! Cm = Cm_alpha alpha, Cn = Cn_beta beta), constant in Mach; the damping derivatives become
//! tables over Mach; and (optionally) each interference increment becomes a table over distance
//! sampled from dC0 f(s).
//!
//! Choices made here:
//! - alpha and beta from -45 to 45 deg every 5 deg: a linear function is interpolated exactly
//!   (to rounding) on any grid, so the aerodynamic tables reproduce the constant form to
//!   rounding; the grid is there to be edited.
//! - Mach breakpoints 0.4, 0.8, 1.2 and 1.6, widened to contain the flight Mach.
//! - The interference grid is graded: every 0.01 m to 1 m, every 0.05 m to 3 m, every 0.25 m to
//!   s_end, then s_end (where f = 0) and 100 m (still 0), so that the event never leaves it. The
//!   linear interpolation of f(s) between breakpoints 0.01 m apart near carriage differs from
//!   the exponential by at most 0.01^2 / (8 lambda^2) = 3.5e-5 of dC0 there (the trajectory
//!   difference this makes is measured by the test `default_as_tables_*`).

use std::path::{Path, PathBuf};

use sepval_core::atomic_file::write_atomically;

use crate::model::InterferenceDecay;
use crate::scenario::Scenario;
use crate::table::{Axis, Coefficient, DerivativeCoefficient, TableFile, Variable, write_csv};

/// A scenario in table form: the TOML's scenario (referring to its files) and the files, each
/// with its path relative to the scenario file.
#[derive(Debug, Clone)]
pub struct TableForm {
    /// The scenario, its tables as file references.
    pub scenario: Scenario,
    /// (relative path, CSV text) of each table file.
    pub files: Vec<(PathBuf, String)>,
}

fn file<K>(path: &str, column: &str) -> crate::table::Tabulated<K>
where
    K: crate::table::TableKind,
{
    let mut c = crate::table::Tabulated::<K>::constant(0.0);
    c.value = Coefficient::File(TableFile {
        csv: PathBuf::from(path),
        column: Some(column.to_string()),
    });
    c
}

fn grid(from: f64, to: f64, step: f64) -> Vec<f64> {
    let n = ((to - from) / step).round() as usize;
    (0..=n).map(|k| from + k as f64 * step).collect()
}

/// The value of a coefficient that is a constant (the scenario was checked to have no tables).
fn constant(c: &Coefficient) -> f64 {
    match c {
        Coefficient::Constant(v) => *v,
        _ => unreachable!("checked: no tables"),
    }
}

/// The slope of a derivative that may be absent (zero then).
fn slope(c: &Option<DerivativeCoefficient>) -> f64 {
    c.as_ref().map_or(0.0, |c| constant(&c.value))
}

/// The Mach breakpoints of the tables: 0.4 to 1.6, widened to the flight's Mach.
fn mach_breakpoints(mach_flight: f64) -> Vec<f64> {
    let mut mach = vec![0.4, 0.8, 1.2, 1.6];
    if mach_flight < mach[0] {
        mach.insert(0, mach_flight);
    }
    if mach_flight > mach[mach.len() - 1] {
        mach.push(mach_flight);
    }
    mach
}

/// The static coefficients over Mach, alpha and beta (-45 to 45 deg by 5), as CSV.
fn static_table(a: &crate::scenario::Aero, mach: &[f64]) -> String {
    let angles = grid(-45.0, 45.0, 5.0);
    let axes = vec![
        Axis {
            variable: Variable::Mach,
            breakpoints: mach.to_vec(),
        },
        Axis {
            variable: Variable::Alpha,
            breakpoints: angles.clone(),
        },
        Axis {
            variable: Variable::Beta,
            breakpoints: angles.clone(),
        },
    ];
    let (ca0, cy_b, cz_a, cm_a, cn_b) = (
        constant(&a.ca0.value),
        slope(&a.cy_beta_per_rad),
        slope(&a.cz_alpha_per_rad),
        slope(&a.cm_alpha_per_rad),
        slope(&a.cn_beta_per_rad),
    );
    let mut columns: [Vec<f64>; 6] = Default::default();
    for _ in mach {
        for al in &angles {
            for be in &angles {
                let (al, be) = (al.to_radians(), be.to_radians());
                for (c, v) in [ca0, cy_b * be, cz_a * al, 0.0, cm_a * al, cn_b * be]
                    .into_iter()
                    .enumerate()
                {
                    columns[c].push(v);
                }
            }
        }
    }
    write_csv(
        &axes,
        &[
            ("ca", "-", &columns[0]),
            ("cy", "-", &columns[1]),
            ("cz", "-", &columns[2]),
            ("cl", "-", &columns[3]),
            ("cm", "-", &columns[4]),
            ("cn", "-", &columns[5]),
        ],
    )
}

/// The damping derivatives over Mach, as CSV.
fn damping_table(a: &crate::scenario::Aero, mach: &[f64]) -> String {
    let mach_axis = [Axis {
        variable: Variable::Mach,
        breakpoints: mach.to_vec(),
    }];
    let damping: Vec<Vec<f64>> = [&a.cl_p_per_rad, &a.cm_q_per_rad, &a.cn_r_per_rad]
        .iter()
        .map(|c| vec![constant(&c.value); mach.len()])
        .collect();
    write_csv(
        &mach_axis,
        &[
            ("cl_p", "1/rad", &damping[0]),
            ("cm_q", "1/rad", &damping[1]),
            ("cn_r", "1/rad", &damping[2]),
        ],
    )
}

/// Names of the interference increments' columns.
const INTERFERENCE_COLUMNS: [&str; 6] = ["dcx", "dcy", "dcz", "dcl", "dcm", "dcn"];

/// The graded distances \[m\] an interference increment is sampled at when written as a table
/// (the choice in this module's documentation): every 0.01 m to 1 m, 0.05 m to 3 m, 0.25 m to
/// `s_end_m`, then `s_end_m` and 100 m (or 1 m beyond `s_end_m`).
pub fn interference_distances(s_end_m: f64) -> Vec<f64> {
    let mut d = grid(0.0, 1.0, 0.01);
    d.extend(grid(1.0, 3.0, 0.05).into_iter().skip(1));
    d.extend(
        grid(3.0, s_end_m, 0.25)
            .into_iter()
            .skip(1)
            .filter(|&x| x < s_end_m),
    );
    d.retain(|&x| x < s_end_m);
    d.extend([s_end_m, (s_end_m + 1.0).max(100.0)]);
    d
}

/// The interference increments sampled over distance from carriage (finely near the aircraft),
/// as CSV.
fn interference_table(i: &crate::scenario::Interference) -> String {
    let decay = InterferenceDecay::new(i.lambda_m, i.s_end_m);
    let d = interference_distances(i.s_end_m);
    let values: Vec<Vec<f64>> = i
        .increments()
        .iter()
        .map(|(_, c)| {
            let c0 = constant(&c.value);
            d.iter().map(|&s| c0 * decay.factor(s)).collect()
        })
        .collect();
    let cols: Vec<(&str, &str, &[f64])> = INTERFERENCE_COLUMNS
        .iter()
        .zip(&values)
        .map(|(n, v)| (*n, "-", v.as_slice()))
        .collect();
    write_csv(
        &[Axis {
            variable: Variable::Distance,
            breakpoints: d,
        }],
        &cols,
    )
}

/// Writes the constant coefficients of `scenario` (without tables) as tables; the interference
/// too when `interference` is set. Refuses a scenario that already has tables, or a flowfield.
pub fn table_form(scenario: &Scenario, interference: bool) -> Result<TableForm, TableFormError> {
    if scenario.has_tables() {
        return Err(TableFormError::HasTables);
    }
    if scenario.flowfield.is_some() {
        return Err(TableFormError::Flowfield);
    }
    let mach = mach_breakpoints(scenario.flight.mach);
    let static_csv = static_table(&scenario.aero, &mach);
    let derivatives_csv = damping_table(&scenario.aero, &mach);

    let mut s = scenario.clone();
    s.description = format!(
        "{} (written as tables by `sepval scenario --tables`)",
        scenario.description
    );
    s.aero.ca0 = file::<crate::table::StaticKind>("tables/aero_static.csv", "ca");
    s.aero.cy = Some(file("tables/aero_static.csv", "cy"));
    s.aero.cz = Some(file("tables/aero_static.csv", "cz"));
    s.aero.cl = Some(file("tables/aero_static.csv", "cl"));
    s.aero.cm = Some(file("tables/aero_static.csv", "cm"));
    s.aero.cn = Some(file("tables/aero_static.csv", "cn"));
    s.aero.cy_beta_per_rad = None;
    s.aero.cz_alpha_per_rad = None;
    s.aero.cm_alpha_per_rad = None;
    s.aero.cn_beta_per_rad = None;
    s.aero.cl_p_per_rad = file("tables/aero_damping.csv", "cl_p");
    s.aero.cm_q_per_rad = file("tables/aero_damping.csv", "cm_q");
    s.aero.cn_r_per_rad = file("tables/aero_damping.csv", "cn_r");
    let mut files = vec![
        (PathBuf::from("tables/aero_static.csv"), static_csv),
        (PathBuf::from("tables/aero_damping.csv"), derivatives_csv),
    ];
    if interference {
        files.push((
            PathBuf::from("tables/interference.csv"),
            interference_table(&scenario.interference),
        ));
        let increments = s.interference.increments_mut();
        for ((_, c), n) in increments.into_iter().zip(INTERFERENCE_COLUMNS) {
            *c = file::<crate::table::InterferenceKind>("tables/interference.csv", n);
        }
    }
    Ok(TableForm { scenario: s, files })
}

/// A scenario whose table form is not written.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum TableFormError {
    /// A scenario with tables already.
    #[error("the scenario already has tables: only a constant form is written as tables")]
    HasTables,
    /// A scenario with an aircraft flowfield.
    #[error(
        "the scenario has a [flowfield], which acts through the store's slopes CZ_alpha and CY_beta (docs/model.md section 3b): the table form writes them as static tables over alpha and beta, so it is written for a scenario without a field only"
    )]
    Flowfield,
}

/// Why a scenario in table form could not be written into its directory. Nothing was written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TableDirError {
    /// The directory exists.
    #[error("{}: exists; choose a new directory (nothing was written)", .0.display())]
    Exists(PathBuf),
    /// A file or directory that cannot be made.
    #[error("cannot write {}", path.display())]
    Io {
        /// Where.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A file that cannot be written.
    #[error(transparent)]
    Write(#[from] sepval_core::atomic_file::WriteError),
    /// What was written does not read back (a defect: what sepval writes it must read).
    #[error("the scenario written as tables does not read back (a defect; nothing was written)")]
    ReadBack(#[source] crate::scenario::ScenarioError),
    /// What was written reads back as another scenario (a defect).
    #[error(
        "{}: the scenario written does not read back as it was (a defect; nothing was written)",
        .0.display()
    )]
    Differs(PathBuf),
}

impl TableForm {
    /// Writes the form into the new directory `dir` (refused if anything is there already):
    /// `dir/scenario.toml` (the scenario, after `header`, a comment ending in a newline) and
    /// each table file, staged in a temporary directory beside `dir`, read back (and, with
    /// `expected`, compared with it), then renamed into place, so that a refusal or a failure
    /// leaves nothing (no partial file, no partial directory).
    pub fn write_new_dir(
        &self,
        dir: &Path,
        header: &str,
        expected: Option<&Scenario>,
    ) -> Result<(), TableDirError> {
        if dir.exists() {
            return Err(TableDirError::Exists(dir.to_path_buf()));
        }
        let parent = match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| TableDirError::Io { path, source }
        };
        let stage = sepval_core::atomic_file::staging(0o777)
            .tempdir_in(parent)
            .map_err(io(dir))?;
        for (p, text) in &self.files {
            let path = stage.path().join(p);
            if let Some(d) = path.parent() {
                std::fs::create_dir_all(d).map_err(io(d))?;
            }
            write_atomically(&path, text.as_bytes())?;
        }
        let toml = stage.path().join("scenario.toml");
        let text = format!("{header}{}", self.scenario.to_toml_string());
        write_atomically(&toml, text.as_bytes())?;
        let back = Scenario::load(&toml).map_err(TableDirError::ReadBack)?;
        if expected.is_some_and(|s| &back != s) {
            return Err(TableDirError::Differs(dir.to_path_buf()));
        }
        let staged = stage.keep();
        std::fs::rename(&staged, dir).map_err(|e| {
            let _ = std::fs::remove_dir_all(&staged);
            TableDirError::Io {
                path: dir.to_path_buf(),
                source: e,
            }
        })
    }
}
