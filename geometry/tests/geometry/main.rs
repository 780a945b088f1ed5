//! The integration tests of sepval-geometry: distances against analytic values and an
//! independent brute-force computation, the STL reader, every refusal, the example files, and
//! random finite numbers in every reader (no panic).

mod analytic;
mod examples;
mod fixtures;
mod fuzz;
mod meshes;
mod refusals;
mod stl_bytes;
