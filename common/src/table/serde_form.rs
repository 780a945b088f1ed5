//! The TOML forms of a coefficient (docs/model.md section 1, "Tables"): a number, an inline
//! table (`{ mach = [..], alpha_deg = [..], values = [[..], ..] }`, `values` nested one array
//! per axis) or a file reference (`{ csv = "tables/cz.csv", column = "cz" }`), read and written
//! by serde.

use std::fmt;
use std::marker::PhantomData;
use std::path::PathBuf;

use serde::de::{self, MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::{Axis, Coefficient, Kind, Table, TableFile, TableKind, Tabulated, Variable};

impl<K> Serialize for Tabulated<K> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match &self.value {
            Coefficient::Constant(v) => s.serialize_f64(*v),
            Coefficient::File(f) => f.serialize(s),
            Coefficient::Table(t) => {
                let mut m = s.serialize_map(Some(t.axes.len() + 1))?;
                for a in &t.axes {
                    m.serialize_entry(a.variable.key(), &a.breakpoints)?;
                }
                let shape = t.shape();
                match shape.len() {
                    1 => m.serialize_entry("values", &t.values)?,
                    2 => {
                        let rows: Vec<&[f64]> = t.values.chunks(shape[1]).collect();
                        m.serialize_entry("values", &rows)?
                    }
                    _ => {
                        let planes: Vec<Vec<&[f64]>> = t
                            .values
                            .chunks(shape[1] * shape[2])
                            .map(|p| p.chunks(shape[2]).collect())
                            .collect();
                        m.serialize_entry("values", &planes)?
                    }
                }
                m.end()
            }
        }
    }
}

/// The fields an inline table or file reference may have.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTable {
    csv: Option<PathBuf>,
    column: Option<String>,
    mach: Option<Vec<f64>>,
    alpha_deg: Option<Vec<f64>>,
    beta_deg: Option<Vec<f64>>,
    distance_m: Option<Vec<f64>>,
    lateral_m: Option<Vec<f64>>,
    x_m: Option<Vec<f64>>,
    y_m: Option<Vec<f64>>,
    z_m: Option<Vec<f64>>,
    values: Option<Nested>,
}

/// `values` nested one array per axis.
#[derive(Deserialize)]
#[serde(untagged)]
enum Nested {
    D1(Vec<f64>),
    D2(Vec<Vec<f64>>),
    D3(Vec<Vec<Vec<f64>>>),
}

impl RawTable {
    fn into_coefficient(self, kind: Kind) -> Result<Coefficient, InlineTableError> {
        let axes = self.axes(kind);
        if let Some(csv) = self.csv {
            if !axes.is_empty() || self.values.is_some() {
                return Err(InlineTableError::FileAndInline);
            }
            return Ok(Coefficient::File(TableFile {
                csv,
                column: self.column,
            }));
        }
        if self.column.is_some() {
            return Err(InlineTableError::ColumnWithoutFile);
        }
        let Some(values) = self.values else {
            return Err(InlineTableError::NoValues { kind });
        };
        // Every axis is checked first, so that a ragged `values` is reported against a good
        // grid.
        let shape: Vec<usize> = axes.iter().map(|a| a.breakpoints.len()).collect();
        Table::new(axes.clone(), vec![0.0; shape.iter().product()], kind)?;
        let last_axis = axes[shape.len() - 1].variable.csv_name();
        let flat = values.flatten(&shape, last_axis)?;
        Ok(Coefficient::Table(Table::new(axes, flat, kind)?))
    }

    /// The axes given, in the kind's nesting order (a variable it may not span goes last, to
    /// be refused).
    fn axes(&self, kind: Kind) -> Vec<Axis> {
        let mut axes: Vec<Axis> = [
            (Variable::Mach, &self.mach),
            (Variable::Alpha, &self.alpha_deg),
            (Variable::Beta, &self.beta_deg),
            (Variable::Distance, &self.distance_m),
            (Variable::Lateral, &self.lateral_m),
            (Variable::X, &self.x_m),
            (Variable::Y, &self.y_m),
            (Variable::Z, &self.z_m),
        ]
        .into_iter()
        .filter_map(|(variable, b)| {
            b.clone().map(|breakpoints| Axis {
                variable,
                breakpoints,
            })
        })
        .collect();
        axes.sort_by_key(|a| {
            kind.allowed()
                .iter()
                .position(|&v| v == a.variable)
                .unwrap_or(usize::MAX)
        });
        axes
    }
}

impl Nested {
    /// The values, row-major, checked against the grid's `shape` (one array per axis, one value
    /// per breakpoint; `last_axis` names the innermost axis in a message).
    fn flatten(
        self,
        shape: &[usize],
        last_axis: &'static str,
    ) -> Result<Vec<f64>, InlineTableError> {
        let ragged = |plane: Option<usize>, row: usize, found: usize, expected: usize| {
            Err(InlineTableError::Ragged {
                plane,
                row,
                found,
                expected,
                last_axis,
            })
        };
        match (self, shape) {
            (Nested::D1(v), [n]) => {
                if v.len() != *n {
                    return Err(InlineTableError::Count {
                        found: v.len(),
                        expected: *n,
                        of: "values",
                    });
                }
                Ok(v)
            }
            (Nested::D2(rows), [n0, n1]) => {
                if rows.len() != *n0 {
                    return Err(InlineTableError::Count {
                        found: rows.len(),
                        expected: *n0,
                        of: "rows",
                    });
                }
                let mut flat = Vec::with_capacity(n0 * n1);
                for (k, r) in rows.into_iter().enumerate() {
                    if r.len() != *n1 {
                        return ragged(None, k, r.len(), *n1);
                    }
                    flat.extend(r);
                }
                Ok(flat)
            }
            (Nested::D3(planes), [n0, n1, n2]) => {
                if planes.len() != *n0 {
                    return Err(InlineTableError::Count {
                        found: planes.len(),
                        expected: *n0,
                        of: "planes",
                    });
                }
                let mut flat = Vec::with_capacity(n0 * n1 * n2);
                for (k, p) in planes.into_iter().enumerate() {
                    if p.len() != *n1 {
                        return Err(InlineTableError::PlaneRows {
                            plane: k,
                            found: p.len(),
                            expected: *n1,
                        });
                    }
                    for r in p {
                        if r.len() != *n2 {
                            return ragged(Some(k), 0, r.len(), *n2);
                        }
                        flat.extend(r);
                    }
                }
                Ok(flat)
            }
            (v, s) => {
                let depth = match v {
                    Nested::D1(_) => 1,
                    Nested::D2(_) => 2,
                    Nested::D3(_) => 3,
                };
                Err(InlineTableError::Depth {
                    depth,
                    axes: s.len(),
                })
            }
        }
    }
}

impl<'de, K: TableKind> Deserialize<'de> for Tabulated<K> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<K>(PhantomData<K>);
        impl<'de, K: TableKind> Visitor<'de> for V<K> {
            type Value = Tabulated<K>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(
                    f,
                    "a number, an inline table over {} or {{ csv = \"FILE.csv\" }}",
                    K::KIND.allowed_list(", ")
                )
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
                Ok(Tabulated::constant(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
                Ok(Tabulated::constant(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
                Ok(Tabulated::constant(v as f64))
            }
            fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
                let raw = RawTable::deserialize(de::value::MapAccessDeserializer::new(map))?;
                let value = raw.into_coefficient(K::KIND).map_err(de::Error::custom)?;
                Ok(Tabulated {
                    value,
                    kind: PhantomData,
                })
            }
        }
        d.deserialize_any(V(PhantomData))
    }
}

/// What makes an inline table (or a table's `csv` reference) in a scenario unusable; serde
/// reports it at the table's place in the file.
#[derive(Debug, thiserror::Error)]
enum InlineTableError {
    /// Both a file and inline values.
    #[error("a table is either a file (`csv`) or inline (axes and `values`), not both")]
    FileAndInline,
    /// A column without a file.
    #[error("`column` names a column of a `csv` file; there is none")]
    ColumnWithoutFile,
    /// Breakpoints without values.
    #[error(
        "an inline table needs its breakpoints ({}) and `values`",
        kind.allowed()
            .iter()
            .map(|v| format!("`{}`", v.key()))
            .collect::<Vec<_>>()
            .join(", ")
    )]
    NoValues {
        /// What the table tabulates.
        kind: Kind,
    },
    /// The outermost array of `values` not one entry per breakpoint of the first axis.
    #[error(
        "`values` has {found} {of}, expected {expected}{}",
        if *of == "values" { " (one per breakpoint)" } else { "" }
    )]
    Count {
        /// The entries given.
        found: usize,
        /// The breakpoints of the first axis.
        expected: usize,
        /// What the entries are: "values", "rows" or "planes".
        of: &'static str,
    },
    /// A plane of a three-axis table without one row per breakpoint of the second axis.
    #[error("`values` plane {plane} has {found} rows, expected {expected}")]
    PlaneRows {
        /// The plane.
        plane: usize,
        /// Its rows.
        found: usize,
        /// The breakpoints of the second axis.
        expected: usize,
    },
    /// A row without one value per breakpoint of the last axis.
    #[error(
        "`values`{} row {row} has {found} values, expected {expected} (one per breakpoint of the {last_axis} axis)",
        plane.map(|k| format!(" plane {k}")).unwrap_or_default()
    )]
    Ragged {
        /// Its plane, in a table of three axes.
        plane: Option<usize>,
        /// The row (0 in a plane: the message says which plane).
        row: usize,
        /// Its values.
        found: usize,
        /// The breakpoints of the last axis.
        expected: usize,
        /// The last axis.
        last_axis: &'static str,
    },
    /// `values` nested to another depth than the axes.
    #[error("`values` is nested {depth} deep for a table of {axes} axes: nest one array per axis")]
    Depth {
        /// Its depth.
        depth: usize,
        /// The axes.
        axes: usize,
    },
    /// Axes or values the table refuses.
    #[error(transparent)]
    Shape(#[from] super::TableShapeError),
}
