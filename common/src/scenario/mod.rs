//! Scenarios: the store, its ejector, aerodynamics, interference, flight condition, integrator
//! settings and factor table, loaded from TOML.
//!
//! Source: `docs/model.md` section 1 (the embedded default, `scenarios/eglin_default.toml`)
//! and section 4 (the factor table). Files are SI (m, kg, N, s) with angles in degrees, like
//! every file sepval reads; each field name carries its unit.
//!
//! Choices docs/model.md leaves open, made here:
//! - `[factors]` may list any subset of the 17 factors; the rest keep Anderson's Table 1.
//! - `[initial]` (optional) sets the store's velocity relative to the launch frame and its body
//!   rates at t = 0 (docs/model.md section 2: "All zero at t = 0 unless a scenario says otherwise").
//!   Position and attitude at t = 0 are the carriage position and attitude by definition of the
//!   launch frame.
//! - The atmosphere is the ISA troposphere of section 1; a flight condition above 11 000 m is
//!   refused instead of extrapolated.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use crate::table::{
    Coefficient, DerivativeCoefficient, InterferenceCoefficient, StaticCoefficient, TableError,
};
use sepval_core::factors::{Factor, FactorSpec, FactorTable};
use sepval_core::input_file::read_string;
use sepval_core::limits::MAX_SCENARIO_BYTES;

/// The embedded default scenario text (docs/model.md section 1).
pub const DEFAULT_SCENARIO_TOML: &str = include_str!("../../scenarios/eglin_default.toml");

/// Mass properties and ejector geometry of the store (docs/model.md section 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Store {
    /// Mass \[kg\].
    pub mass_kg: f64,
    /// Roll inertia about the CG [kg m^2].
    pub ixx_kg_m2: f64,
    /// Pitch inertia about the CG [kg m^2].
    pub iyy_kg_m2: f64,
    /// Yaw inertia about the CG [kg m^2].
    pub izz_kg_m2: f64,
    /// Reference diameter d \[m\]; the reference area is pi d^2 / 4.
    pub diameter_m: f64,
    /// Body x of the forward ejector foot \[m\], positive ahead of the CG.
    pub fwd_foot_x_m: f64,
    /// Body x of the aft ejector foot \[m\], negative aft of the CG.
    pub aft_foot_x_m: f64,
    /// Ejector stroke \[m\].
    pub stroke_m: f64,
}

/// The nominal ejector force curve per foot (docs/model.md section 1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Ejector {
    /// (stroke displacement \[m\], force \[N\]) points, displacement strictly increasing, linear
    /// between points, covering [0, stroke].
    pub curve: Vec<[f64; 2]>,
}

/// Freestream aerodynamic database, body axes (docs/model.md section 1). Each field is a
/// constant or a table ([`crate::table`]): static coefficients over Mach, local alpha and local
/// beta, derivatives over Mach.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Aero {
    /// Axial force coefficient CA (CX = -CA): a constant CA0 or a table CA(M, alpha, beta).
    pub ca0: StaticCoefficient,
    /// CZ_alpha [1/rad]; may be left out when `cz` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cz_alpha_per_rad: Option<DerivativeCoefficient>,
    /// CY_beta [1/rad]; may be left out when `cy` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cy_beta_per_rad: Option<DerivativeCoefficient>,
    /// Cm_alpha [1/rad]; may be left out when `cm` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cm_alpha_per_rad: Option<DerivativeCoefficient>,
    /// Cn_beta [1/rad]; may be left out when `cn` is given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cn_beta_per_rad: Option<DerivativeCoefficient>,
    /// Roll damping, per rad of p d / 2V.
    pub cl_p_per_rad: DerivativeCoefficient,
    /// Pitch damping, per rad of q d / 2V.
    pub cm_q_per_rad: DerivativeCoefficient,
    /// Yaw damping, per rad of r d / 2V.
    pub cn_r_per_rad: DerivativeCoefficient,
    /// Static side-force coefficient CY(M, alpha, beta), added to CY_beta beta (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cy: Option<StaticCoefficient>,
    /// Static normal-force coefficient CZ(M, alpha, beta), added to CZ_alpha alpha (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cz: Option<StaticCoefficient>,
    /// Static rolling-moment coefficient Cl(M, alpha, beta) (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cl: Option<StaticCoefficient>,
    /// Static pitching-moment coefficient Cm(M, alpha, beta), added to Cm_alpha alpha (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cm: Option<StaticCoefficient>,
    /// Static yawing-moment coefficient Cn(M, alpha, beta), added to Cn_beta beta (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cn: Option<StaticCoefficient>,
}

/// Aircraft interference increments and their decay (docs/model.md section 1). Each increment
/// is a constant at carriage, decaying as f(s), or a table over distance (and local alpha and
/// lateral offset), used as it is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct Interference {
    pub dcx0: InterferenceCoefficient,
    pub dcy0: InterferenceCoefficient,
    pub dcz0: InterferenceCoefficient,
    pub dcl0: InterferenceCoefficient,
    pub dcm0: InterferenceCoefficient,
    pub dcn0: InterferenceCoefficient,
    /// Decay length lambda \[m\] (of the constant increments).
    pub lambda_m: f64,
    /// Distance beyond which the constant increments' interference is zero \[m\].
    pub s_end_m: f64,
}

impl Aero {
    /// Every field that can be a table, with its TOML path (fields left out are omitted).
    pub fn fields(&self) -> Vec<(&'static str, &Coefficient)> {
        let mut v = vec![("aero.ca0", &self.ca0.value)];
        for (name, c) in [
            ("aero.cz_alpha_per_rad", self.cz_alpha_per_rad.as_ref()),
            ("aero.cy_beta_per_rad", self.cy_beta_per_rad.as_ref()),
            ("aero.cm_alpha_per_rad", self.cm_alpha_per_rad.as_ref()),
            ("aero.cn_beta_per_rad", self.cn_beta_per_rad.as_ref()),
            ("aero.cl_p_per_rad", Some(&self.cl_p_per_rad)),
            ("aero.cm_q_per_rad", Some(&self.cm_q_per_rad)),
            ("aero.cn_r_per_rad", Some(&self.cn_r_per_rad)),
        ] {
            if let Some(c) = c {
                v.push((name, &c.value));
            }
        }
        for (name, c) in [
            ("aero.cy", self.cy.as_ref()),
            ("aero.cz", self.cz.as_ref()),
            ("aero.cl", self.cl.as_ref()),
            ("aero.cm", self.cm.as_ref()),
            ("aero.cn", self.cn.as_ref()),
        ] {
            if let Some(c) = c {
                v.push((name, &c.value));
            }
        }
        v
    }

    /// Every field that can be a table, with its TOML path (fields left out are omitted).
    pub fn fields_mut(&mut self) -> Vec<(&'static str, TabulatedMut<'_>)> {
        let mut v: Vec<(&'static str, TabulatedMut<'_>)> =
            vec![("aero.ca0", TabulatedMut::Static(&mut self.ca0))];
        for (name, c) in [
            ("aero.cz_alpha_per_rad", self.cz_alpha_per_rad.as_mut()),
            ("aero.cy_beta_per_rad", self.cy_beta_per_rad.as_mut()),
            ("aero.cm_alpha_per_rad", self.cm_alpha_per_rad.as_mut()),
            ("aero.cn_beta_per_rad", self.cn_beta_per_rad.as_mut()),
            ("aero.cl_p_per_rad", Some(&mut self.cl_p_per_rad)),
            ("aero.cm_q_per_rad", Some(&mut self.cm_q_per_rad)),
            ("aero.cn_r_per_rad", Some(&mut self.cn_r_per_rad)),
        ] {
            if let Some(c) = c {
                v.push((name, TabulatedMut::Derivative(c)));
            }
        }
        for (name, c) in [
            ("aero.cy", self.cy.as_mut()),
            ("aero.cz", self.cz.as_mut()),
            ("aero.cl", self.cl.as_mut()),
            ("aero.cm", self.cm.as_mut()),
            ("aero.cn", self.cn.as_mut()),
        ] {
            if let Some(c) = c {
                v.push((name, TabulatedMut::Static(c)));
            }
        }
        v
    }
}

impl Interference {
    /// The six increments (dCX, dCY, dCZ, dCl, dCm, dCn) with their TOML paths.
    pub fn increments(&self) -> [(&'static str, &InterferenceCoefficient); 6] {
        [
            ("interference.dcx0", &self.dcx0),
            ("interference.dcy0", &self.dcy0),
            ("interference.dcz0", &self.dcz0),
            ("interference.dcl0", &self.dcl0),
            ("interference.dcm0", &self.dcm0),
            ("interference.dcn0", &self.dcn0),
        ]
    }

    /// [`Interference::increments`], mutable.
    pub fn increments_mut(&mut self) -> [(&'static str, &mut InterferenceCoefficient); 6] {
        [
            ("interference.dcx0", &mut self.dcx0),
            ("interference.dcy0", &mut self.dcy0),
            ("interference.dcz0", &mut self.dcz0),
            ("interference.dcl0", &mut self.dcl0),
            ("interference.dcm0", &mut self.dcm0),
            ("interference.dcn0", &mut self.dcn0),
        ]
    }
}

/// A mutable aerodynamic field of either kind.
#[allow(missing_docs)]
pub enum TabulatedMut<'a> {
    Static(&'a mut StaticCoefficient),
    Derivative(&'a mut DerivativeCoefficient),
}

impl TabulatedMut<'_> {
    fn resolve(&mut self, dir: &Path) -> Result<(), crate::table::TableError> {
        match self {
            TabulatedMut::Static(c) => c.resolve(dir),
            TabulatedMut::Derivative(c) => c.resolve(dir),
        }
    }
}

/// Flight condition of the aircraft at release (docs/model.md sections 1 and 2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Flight {
    /// Free-stream Mach number.
    pub mach: f64,
    /// Altitude \[m\] (ISA troposphere).
    pub altitude_m: f64,
    /// Aircraft angle of attack \[deg\].
    #[serde(default)]
    pub alpha_deg: f64,
    /// Aircraft sideslip \[deg\].
    #[serde(default)]
    pub beta_deg: f64,
    /// Flight-path angle \[deg\].
    #[serde(default)]
    pub gamma_deg: f64,
}

/// Integrator and telemetry settings (docs/model.md sections 1 and 3a).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Integrator {
    /// Fixed RK4 step \[s\].
    pub dt_s: f64,
    /// Event length \[s\].
    pub t_end_s: f64,
    /// Telemetry rate of simulated trajectories \[Hz\].
    pub rate_hz: f64,
}

/// Initial motion relative to the launch frame (optional; zero by default).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Initial {
    /// Velocity relative to the launch frame, L axes [m/s].
    #[serde(default)]
    pub velocity_m_s: [f64; 3],
    /// Body rates (p, q, r) [deg/s].
    #[serde(default)]
    pub rates_deg_s: [f64; 3],
}

/// A complete scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Short name (used in reports).
    pub name: String,
    /// One line on what this scenario is.
    #[serde(default)]
    pub description: String,
    /// Mass properties and ejector geometry.
    pub store: Store,
    /// Ejector force curve.
    pub ejector: Ejector,
    /// Freestream aerodynamic database.
    pub aero: Aero,
    /// Interference model.
    pub interference: Interference,
    /// The aircraft's flowfield (docs/model.md section 3b), in place of the decay increments.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flowfield: Option<FlowfieldSpec>,
    /// Flight condition.
    pub flight: Flight,
    /// Integrator settings.
    pub integrator: Integrator,
    /// Initial motion.
    #[serde(default, skip_serializing_if = "is_default_initial")]
    pub initial: Initial,
    /// Factor table overrides by factor name.
    #[serde(default, with = "factor_table_serde")]
    pub factors: FactorTable,
    /// Model-extension terms (docs/discovery.md), written as `[[extension]]` tables.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub extension: Vec<crate::extension::TermRecord>,
    /// Corrections whose values each candidate carries (docs/update.md), written as
    /// `[[correction]]` tables; `sepval update` sets them, and the store it writes has none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub correction: Vec<crate::correction::CorrectionRecord>,
}

fn is_default_initial(i: &Initial) -> bool {
    *i == Initial::default()
}

mod factor_table_serde {
    use super::*;

    pub fn serialize<S: serde::Serializer>(t: &FactorTable, s: S) -> Result<S::Ok, S::Error> {
        let map: BTreeMap<&str, FactorSpec> = Factor::ALL
            .iter()
            .map(|f| (f.name(), *t.spec(*f)))
            .collect();
        map.serialize(s)
    }

    pub fn deserialize<'de, D: serde::Deserializer<'de>>(d: D) -> Result<FactorTable, D::Error> {
        let map = BTreeMap::<String, FactorSpec>::deserialize(d)?;
        let mut table = FactorTable::default();
        for (name, spec) in map {
            let factor = Factor::from_name(&name).ok_or_else(|| {
                serde::de::Error::custom(format!(
                    "unknown factor `{name}` (expected one of: {})",
                    Factor::NAMES.join(", ")
                ))
            })?;
            table.0[factor.index()] = spec;
        }
        Ok(table)
    }
}

/// Errors loading or validating a scenario.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("cannot read scenario {path}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The path is not a regular file, or the file is over its byte limit.
    #[error(transparent)]
    Input(Box<sepval_core::input_file::InputFileError>),
    /// The TOML does not parse or does not have the expected fields.
    #[error("scenario {origin}: {message}")]
    Parse {
        /// The file, or "embedded default".
        origin: String,
        /// The parser's message (it names line and column).
        message: String,
    },
    /// A table file that cannot be used (its error, the source, names its file, line and
    /// column; it is not repeated here, so that a printed cause chain says it once).
    #[error("scenario {origin}: `{field}`")]
    Table {
        /// The scenario file.
        origin: String,
        /// The field, as a TOML path.
        field: String,
        /// The cause (boxed: it is large and rare).
        source: Box<TableError>,
    },
    /// A value is out of its physical range.
    #[error("scenario {origin}: `{field}` {reason}")]
    Invalid {
        /// The file, or "embedded default".
        origin: String,
        /// The field, as a TOML path.
        field: String,
        /// What is wrong.
        reason: String,
    },
}

impl Scenario {
    /// The embedded default scenario (docs/model.md section 1).
    pub fn embedded_default() -> Scenario {
        Scenario::from_toml_str(DEFAULT_SCENARIO_TOML, "embedded default")
            .expect("the embedded default scenario is valid (checked by tests)")
    }

    /// Parses and validates scenario TOML; `origin` names the source in errors. Tables must be
    /// inline (a table file needs [`Scenario::load`], which reads it relative to the scenario).
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Scenario, ScenarioError> {
        Scenario::from_toml_str_in(text, origin, None)
    }

    /// Parses scenario TOML, reads its table files relative to `dir` (when given) into inline
    /// tables, and validates it.
    pub fn from_toml_str_in(
        text: &str,
        origin: &str,
        dir: Option<&Path>,
    ) -> Result<Scenario, ScenarioError> {
        let mut scenario: Scenario = toml::from_str(text).map_err(|e| ScenarioError::Parse {
            origin: origin.to_string(),
            message: sections::misformed(text)
                .unwrap_or_else(|| sepval_core::toml_error::one_line(text, &e)),
        })?;
        if let Some(dir) = dir {
            scenario.resolve_tables(dir, origin)?;
        }
        scenario.validate(origin)?;
        Ok(scenario)
    }

    /// Reads every table file the scenario references (relative to `dir`) into inline tables,
    /// so that the scenario carries its tables' contents (the content hash covers them, and a
    /// worker never needs the files).
    pub fn resolve_tables(&mut self, dir: &Path, origin: &str) -> Result<(), ScenarioError> {
        let wrap = |field: &str, source: TableError| ScenarioError::Table {
            origin: origin.to_string(),
            field: field.to_string(),
            source: Box::new(source),
        };
        for (field, mut c) in self.aero.fields_mut() {
            c.resolve(dir).map_err(|e| wrap(field, e))?;
        }
        for (field, c) in self.interference.increments_mut() {
            c.resolve(dir).map_err(|e| wrap(field, e))?;
        }
        if let Some(f) = self.flowfield.as_mut() {
            f.resolve_tables(dir)
                .map_err(|(field, e)| wrap(&field, e))?;
        }
        Ok(())
    }

    /// Whether any coefficient is a table.
    pub fn has_tables(&self) -> bool {
        self.aero
            .fields()
            .iter()
            .any(|(_, c)| !matches!(c, Coefficient::Constant(_)))
            || self
                .interference
                .increments()
                .iter()
                .any(|(_, c)| !matches!(c.value, Coefficient::Constant(_)))
    }

    /// Loads and validates a scenario file (its table files are read relative to it).
    pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
        let text =
            read_string(path, "scenario", MAX_SCENARIO_BYTES).map_err(|e| match e.into_io() {
                Ok(source) => ScenarioError::Io {
                    path: path.to_path_buf(),
                    source,
                },
                Err(refused) => ScenarioError::Input(Box::new(refused)),
            })?;
        let dir = path.parent().unwrap_or(Path::new(""));
        Scenario::from_toml_str_in(&text, &path.display().to_string(), Some(dir))
    }

    /// The table files the scenario file at `path` names (each `csv = "..."` in it, relative
    /// to its directory as [`Scenario::load`] reads them): what a run that loads it reads
    /// besides the file itself, so that no output may be written over them. None when the file
    /// cannot be read or parsed (loading it says why).
    pub fn table_files(path: &Path) -> Vec<std::path::PathBuf> {
        fn collect(v: &toml::Value, out: &mut Vec<String>) {
            match v {
                toml::Value::Table(t) => {
                    if let Some(toml::Value::String(f)) = t.get("csv") {
                        out.push(f.clone());
                    }
                    t.values().for_each(|x| collect(x, out));
                }
                toml::Value::Array(a) => a.iter().for_each(|x| collect(x, out)),
                _ => {}
            }
        }
        let Ok(text) = read_string(path, "scenario", MAX_SCENARIO_BYTES) else {
            return Vec::new();
        };
        let Ok(value) = toml::from_str::<toml::Value>(&text) else {
            return Vec::new();
        };
        let mut names = Vec::new();
        collect(&value, &mut names);
        let dir = path.parent().unwrap_or(Path::new(""));
        names.sort();
        names.dedup();
        names.into_iter().map(|n| dir.join(n)).collect()
    }

    /// The scenario as TOML (values round-trip exactly).
    pub fn to_toml_string(&self) -> String {
        toml::to_string(self).expect("a scenario always serialises")
    }

    /// The extension's terms (checked by [`Scenario::validate`]).
    pub fn extension_terms(&self) -> crate::extension::TermSet {
        let terms: Vec<crate::extension::Term> = self
            .extension
            .iter()
            .filter_map(|r| r.term().ok())
            .collect();
        crate::extension::TermSet::of(&terms).unwrap_or_default()
    }

    /// The corrections (checked by [`Scenario::validate`]).
    pub fn corrections(&self) -> Vec<crate::correction::Correction> {
        crate::correction::check_all(&self.correction).unwrap_or_default()
    }

    /// SHA-256 of the scenario's canonical form (its JSON serialisation), hex. Two scenarios
    /// with the same content have the same hash whatever their file layout or comments.
    pub fn content_hash(&self) -> String {
        let json = serde_json::to_vec(self).expect("a scenario always serialises");
        hex_sha256(&json)
    }
}

/// SHA-256 of `bytes`, lower-case hex.
pub fn hex_sha256(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

mod flowfield;
mod same_store;
mod sections;
mod validate;

pub use flowfield::{
    FlowfieldSpec, MAX_SHAPE_POINTS, MAX_STATIONS, MachScaling, POSITION_FIELDS, ShapeTable,
};

pub use same_store::StoreDifference;
