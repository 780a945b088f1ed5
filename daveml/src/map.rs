//! Which DAVE-ML variable is which sepval input or field: the default map for the usual names
//! and a user's map file (`--map MAP.toml`), whose entries are added to the default's (an entry
//! for a name the default has replaces it). docs/daveml.md lists the default map.
//!
//! A variable is looked up by its `varID`, then by its `name` (case matters: `Cl` is the
//! rolling moment, `CL` the lift, `Cn` the yawing moment, `CN` the normal force). The default
//! map knows the usual short names and the AIAA standard variable names S-119 recommends
//! (`angleOfAttack`, `aeroBodyForceCoefficient_X`, ...: body axes, X forward, Z down, the
//! moments positive right wing down, nose up and nose right, as sepval's).
//!
//! The map file (TOML):
//!
//! ```toml
//! [inputs]            # DAVE-ML variable = sepval input: mach, alpha, beta, distance, lateral
//! alpdeg = "alpha"
//! [outputs]           # DAVE-ML variable = sepval field (negate: the field is minus the variable)
//! CN_basic = { field = "aero.cz", negate = true }
//! [ignore]            # DAVE-ML outputs left out of the scenario on purpose
//! variables = ["CL", "CD"]
//! ```

use std::collections::BTreeMap;

use sepval_common::correction::Target;
use sepval_common::table::Variable;
use serde::Deserialize;

use crate::error::DavemlError;

/// A sepval field a DAVE-ML variable gives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Output {
    /// The field.
    pub target: Target,
    /// Whether the field is minus the variable (CX = -CA, CN = -CZ).
    pub negate: bool,
}

/// What a DAVE-ML variable is to sepval.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// One of the inputs of sepval's tables.
    Input(Variable),
    /// One of the scenario's fields.
    Output(Output),
    /// Left out of the scenario on purpose (the map's `[ignore]`).
    Ignore,
}

/// The map: a role per DAVE-ML name.
#[derive(Debug, Clone, PartialEq)]
pub struct Map {
    roles: BTreeMap<String, Role>,
}

/// The default map's inputs: (DAVE-ML names, sepval input).
const DEFAULT_INPUTS: [(&[&str], Variable); 5] = [
    (&["mach", "Mach", "MACH", "M"], Variable::Mach),
    (
        &[
            "alpha",
            "alpdeg",
            "alpha_deg",
            "alprad",
            "ALPHA",
            "AOA",
            "angleOfAttack",
        ],
        Variable::Alpha,
    ),
    (
        &[
            "beta",
            "betdeg",
            "beta_deg",
            "betrad",
            "BETA",
            "AOS",
            "angleOfSideslip",
        ],
        Variable::Beta,
    ),
    (&["distance", "distance_m", "s"], Variable::Distance),
    (&["lateral", "lateral_m"], Variable::Lateral),
];

/// The default map's outputs: (DAVE-ML names, sepval field, negate).
const DEFAULT_OUTPUTS: [(&[&str], &str, bool); 21] = [
    (&["CA"], "aero.ca0", false),
    (&["CX", "aeroBodyForceCoefficient_X"], "aero.ca0", true),
    (&["CY", "aeroBodyForceCoefficient_Y"], "aero.cy", false),
    (&["CZ", "aeroBodyForceCoefficient_Z"], "aero.cz", false),
    (&["CN"], "aero.cz", true),
    (&["Cl", "aeroBodyMomentCoefficient_Roll"], "aero.cl", false),
    (&["Cm", "aeroBodyMomentCoefficient_Pitch"], "aero.cm", false),
    (&["Cn", "aeroBodyMomentCoefficient_Yaw"], "aero.cn", false),
    (&["CZalpha", "CZa"], "aero.cz_alpha_per_rad", false),
    (&["CYbeta", "CYb"], "aero.cy_beta_per_rad", false),
    (&["Cmalpha", "Cma"], "aero.cm_alpha_per_rad", false),
    (&["Cnbeta", "Cnb"], "aero.cn_beta_per_rad", false),
    (&["Clp"], "aero.cl_p_per_rad", false),
    (&["Cmq"], "aero.cm_q_per_rad", false),
    (&["Cnr"], "aero.cn_r_per_rad", false),
    (&["dCX", "dCX0"], "interference.dcx0", false),
    (&["dCY", "dCY0"], "interference.dcy0", false),
    (&["dCZ", "dCZ0"], "interference.dcz0", false),
    (&["dCl", "dCl0"], "interference.dcl0", false),
    (&["dCm", "dCm0"], "interference.dcm0", false),
    (&["dCn", "dCn0"], "interference.dcn0", false),
];

/// The map file's form.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MapFile {
    #[serde(default)]
    inputs: BTreeMap<String, String>,
    #[serde(default)]
    outputs: BTreeMap<String, OutputEntry>,
    #[serde(default)]
    ignore: IgnoreEntry,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct OutputEntry {
    field: String,
    #[serde(default)]
    negate: bool,
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct IgnoreEntry {
    #[serde(default)]
    variables: Vec<String>,
}

/// The sepval input named `key` in a map file (its CSV name, or its TOML key).
fn input_named(key: &str) -> Option<Variable> {
    Variable::ALL
        .into_iter()
        .find(|v| v.csv_name() == key || v.key() == key)
}

impl Default for Map {
    fn default() -> Self {
        let mut roles = BTreeMap::new();
        for (names, v) in DEFAULT_INPUTS {
            for n in names {
                roles.insert(n.to_string(), Role::Input(v));
            }
        }
        for (names, field, negate) in DEFAULT_OUTPUTS {
            let target = Target::of_field(field).expect("the default map names fields");
            for n in names {
                roles.insert(n.to_string(), Role::Output(Output { target, negate }));
            }
        }
        Map { roles }
    }
}

impl Map {
    /// The default map with the entries of the map file `text` (named `file` in messages).
    pub fn with_file(text: &str, file: &str) -> Result<Map, DavemlError> {
        let err = |message: String| DavemlError::Map {
            file: file.to_string(),
            message,
        };
        let parsed: MapFile = toml::from_str(text).map_err(|e| err(e.message().to_string()))?;
        let mut map = Map::default();
        for (name, input) in parsed.inputs {
            let v = input_named(&input).ok_or_else(|| {
                err(format!(
                    "[inputs] {name} = \"{input}\": expected mach, alpha, beta, distance or lateral"
                ))
            })?;
            map.roles.insert(name, Role::Input(v));
        }
        for (name, o) in parsed.outputs {
            let target = Target::table_of_field(&o.field).ok_or_else(|| {
                err(format!(
                    "[outputs] {name}: field `{}` is not a field of the scenario's tables (aero.ca0, aero.cy ... aero.cn, aero.cz_alpha_per_rad ... aero.cn_r_per_rad, interference.dcx0 ... interference.dcn0)",
                    o.field
                ))
            })?;
            let negate = o.negate;
            map.roles
                .insert(name, Role::Output(Output { target, negate }));
        }
        for name in parsed.ignore.variables {
            map.roles.insert(name, Role::Ignore);
        }
        Ok(map)
    }

    /// The role of the variable with `var_id` and `name`, if the map knows either.
    pub fn role(&self, var_id: &str, name: &str) -> Option<Role> {
        self.roles
            .get(var_id)
            .or_else(|| self.roles.get(name))
            .copied()
    }
}
