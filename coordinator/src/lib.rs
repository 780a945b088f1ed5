//! The sepval coordinator: everything the `sepval` command does beyond the model itself.
//! The binary (`src/main.rs`) is only the command line; the logic lives here.

#![warn(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod inputs;
