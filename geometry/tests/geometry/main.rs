//! The integration tests of sepval-geometry: distances against analytic values and an
//! independent brute-force computation, the STL reader, every refusal, and the example files.

mod analytic;
mod examples;
mod fixtures;
mod meshes;
mod refusals;
mod stl_bytes;
