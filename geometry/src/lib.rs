//! The clearance between a released store and the aircraft (issue 24: "will the store hit the
//! aircraft?").
//!
//! A [`Body`] is the store or the aircraft as named convex parts and triangle meshes, read from
//! an STL file or a small TOML file of primitives ([`Body::read`]), or the Eglin benchmark store
//! scaled to a diameter ([`Body::default_store`]). A [`Geometry`] holds the two, refuses a store
//! that intersects the aircraft at carriage by more than [`CARRIAGE_TOLERANCE_M`], and answers
//! the smallest distance between the store's surface and the aircraft's at a store [`Pose`]
//! ([`Geometry::clearance`]) and along a trajectory ([`Geometry::trace`]). MIL-STD-1289D asks
//! for at least [`MIL_STD_1289D_CLEARANCE_M`] (25.4 mm) between store and aircraft.
//!
//! Frames are those of docs/model.md section 2: the launch frame L (origin at the store's CG at
//! carriage, x forward, y right, z down), fixed to the aircraft, in which the aircraft is given;
//! the store's body frame B (the same axes at t = 0, origin at the CG), in which the store is
//! given; attitude as 3-2-1 Euler angles, C_LB = Rz(psi) Ry(theta) Rx(phi). The format, the
//! rule for the smallest clearance and the sources are in docs/geometry.md.
//!
//! Distances are parry's (`parry3d-f64`, <https://parry.rs>): GJK and EPA between convex parts
//! (E. G. Gilbert, D. W. Johnson and S. S. Keerthi, IEEE J. Robotics and Automation 4 (1988);
//! G. van den Bergen, *Collision Detection in Interactive 3D Environments*, 2003), bounding-
//! volume trees inside meshes. No parry or glam type appears in this crate's public API.
#![deny(clippy::float_cmp)]

mod body;
mod clearance;
mod domain;
mod error;
mod frames;
mod input;
mod mesh_distance;
mod parts;
mod primitives;
mod shape;
mod stl;
mod store;
mod trace;

pub use body::{Body, Role};
pub use clearance::{CARRIAGE_TOLERANCE_M, Closest, Geometry, Pose};
pub use domain::{MAX_ANGLE_DEG, MAX_COORDINATE_M, MAX_SIZE_M, MIN_SIZE_M};
pub use error::{CarriageOverlap, GeometryError};
pub use input::{MAX_FILE_BYTES, MAX_TRIANGLES};
pub use shape::{FinShape, Nose, RevolutionShape, StoreShape};
pub use trace::{Smallest, Trace};

/// What asks a long computation of this crate to stop (reading and building a mesh, the
/// check at carriage, the clearance along a trajectory): asked every few milliseconds of work,
/// `true` ends the computation with [`GeometryError::Interrupted`]. The binaries pass their
/// cancellation flag (SIGINT, SIGTERM); `&|| false` never stops.
pub type Stop<'a> = &'a (dyn Fn() -> bool + Sync);

/// The smallest clearance between store and aircraft that MIL-STD-1289D (Department of Defense
/// Interface Standard, "Airborne stores ejection clearance", 2003) asks for: 1 inch.
pub const MIL_STD_1289D_CLEARANCE_M: f64 = 0.0254;
