//! A body (the store or the aircraft): named parts read from an STL file (one part per solid)
//! or a TOML file of primitives, or the default store. docs/geometry.md gives the formats.

use std::path::{Path, PathBuf};

use crate::domain;
use crate::input::{MAX_FILE_BYTES, MAX_TRIANGLES, read_capped};
use crate::parts::{self, MeshRefusal, Part, PartProblem};
use crate::primitives::Primitives;
use crate::stl::{self, StlProblem};
use crate::store::StoreSpec;
use crate::{GeometryError, Stop};

/// Which body a file describes: it decides the TOML format and the frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The store, in its body frame (origin at the CG): a store TOML or an STL.
    Store,
    /// The aircraft, in the launch frame: an aircraft TOML or an STL.
    Aircraft,
}

/// The store or the aircraft: where it came from and its named parts.
#[derive(Clone)]
pub struct Body {
    source: String,
    pub(crate) parts: Vec<Part>,
}

impl std::fmt::Debug for Body {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Body")
            .field("source", &self.source)
            .field("parts", &self.part_names())
            .finish()
    }
}

impl Body {
    /// Reads `path` as an STL (`.stl`) or a TOML (`.toml`) file of the body `role`, refusing
    /// bad geometry with an error that names the file, the line or field, and what is wrong.
    pub fn read(path: &Path, role: Role) -> Result<Body, GeometryError> {
        Body::read_until(path, role, &|| false)
    }

    /// [`Body::read`], asking `stop` every few milliseconds while a mesh is read and built
    /// ([`GeometryError::Interrupted`] when it says stop).
    pub fn read_until(path: &Path, role: Role, stop: Stop) -> Result<Body, GeometryError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let parts = match ext.as_deref() {
            Some("stl") => read_stl(path, stop)?,
            Some("toml") => read_toml(path, role)?,
            _ => {
                return Err(GeometryError::UnknownFormat {
                    path: path.to_path_buf(),
                });
            }
        };
        Body::from_parts(path.display().to_string(), parts)
            .map_err(|(field, what)| invalid(path, field, what))
    }

    /// The Eglin benchmark store scaled to `diameter_m` (every length in proportion; at
    /// 0.508 m exactly examples/geometry/store.toml). Refuses a diameter outside the domain of
    /// a size, or one that makes a length of the store leave it (over 10 km long: a diameter
    /// over 1.68 km).
    pub fn default_store(diameter_m: f64) -> Result<Body, GeometryError> {
        let source = format!("default store, diameter {diameter_m} m");
        let path = PathBuf::from("<default store>");
        domain::size("diameter_m", diameter_m).map_err(|(f, w)| invalid(&path, f, w))?;
        let parts = StoreSpec::eglin(diameter_m).parts().map_err(|(f, w)| {
            invalid(
                &path,
                "diameter_m".into(),
                format!(
                    "{} m: the store scaled to this diameter has {f}: {w}",
                    domain::number(diameter_m)
                ),
            )
        })?;
        Body::from_parts(source, parts).map_err(|(f, w)| invalid(&path, f, w))
    }

    /// The names of the parts, in order: part `i` of a [`crate::Closest`] is `part_names()[i]`.
    pub fn part_names(&self) -> Vec<&str> {
        self.parts.iter().map(|p| p.name.as_str()).collect()
    }

    /// Where the body came from: the file's path or "default store, diameter D m".
    pub fn source(&self) -> &str {
        &self.source
    }

    fn from_parts(source: String, parts: Vec<Part>) -> Result<Body, PartProblem> {
        if parts.is_empty() {
            return Err(("parts".into(), "no part".into()));
        }
        for (i, p) in parts.iter().enumerate() {
            if parts[..i].iter().any(|q| q.name == p.name) {
                return Err((
                    format!("part \"{}\"", p.name),
                    "the name is used twice".into(),
                ));
            }
        }
        Ok(Body { source, parts })
    }
}

fn invalid(path: &Path, field: String, what: String) -> GeometryError {
    if field == "parts" {
        return GeometryError::Empty {
            path: path.to_path_buf(),
            what,
        };
    }
    GeometryError::Invalid {
        path: path.to_path_buf(),
        field,
        what,
    }
}

fn read_stl(path: &Path, stop: Stop) -> Result<Vec<Part>, GeometryError> {
    let interrupted = || GeometryError::Interrupted {
        what: format!("reading {}", path.display()),
    };
    let bytes = read_capped(path, MAX_FILE_BYTES)?;
    let solids = stl::parse(&bytes, MAX_TRIANGLES, stop).map_err(|p| match p {
        StlProblem::Malformed { line, what } => GeometryError::Stl {
            path: path.to_path_buf(),
            line,
            what,
        },
        StlProblem::TooMany { count } => GeometryError::TooManyTriangles {
            path: path.to_path_buf(),
            count,
            limit: MAX_TRIANGLES,
        },
        StlProblem::Stopped => interrupted(),
    })?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut out = Vec::new();
    for (i, solid) in solids.iter().enumerate() {
        let name = match (solid.name.is_empty(), solids.len()) {
            (false, _) => solid.name.clone(),
            (true, 1) => stem.clone(),
            (true, _) => format!("{stem} {}", i + 1),
        };
        let field = format!("solid {} \"{name}\"", i + 1);
        if solid.triangles.is_empty() {
            return Err(GeometryError::Empty {
                path: path.to_path_buf(),
                what: format!("{field} has no triangle"),
            });
        }
        out.push(
            parts::mesh(name, &field, &solid.triangles, stop).map_err(|r| match r {
                MeshRefusal::Problem((f, w)) => invalid(path, f, w),
                MeshRefusal::Stopped => interrupted(),
            })?,
        );
    }
    if out.is_empty() {
        return Err(GeometryError::Empty {
            path: path.to_path_buf(),
            what: "no solid".into(),
        });
    }
    Ok(out)
}

fn read_toml(path: &Path, role: Role) -> Result<Vec<Part>, GeometryError> {
    let bytes = read_capped(path, MAX_FILE_BYTES)?;
    let text = std::str::from_utf8(&bytes).map_err(|e| GeometryError::Toml {
        path: path.to_path_buf(),
        message: format!("not UTF-8 text: {e}"),
    })?;
    let toml_error = |e: toml::de::Error| GeometryError::Toml {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let parts = match role {
        Role::Store => toml::from_str::<StoreSpec>(text)
            .map_err(toml_error)?
            .parts(),
        Role::Aircraft => toml::from_str::<Primitives>(text)
            .map_err(toml_error)?
            .parts(true),
    };
    parts.map_err(|(f, w)| invalid(path, f, w))
}
