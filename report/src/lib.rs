//! What sepval writes for people: figures as PNG files ([`figures`]), drawn from plain
//! data, and HTML pages ([`html`]) in one layout and one stylesheet, each page from its own
//! template, with numbers and conditions in the same [`words`] everywhere. Fits, diagnoses and the commands to come describe what to show; this crate knows
//! nothing of how it was computed.

#![deny(clippy::float_cmp)]

pub mod figures;
pub mod html;
mod output_error;
pub mod words;
mod written;

pub use output_error::OutputError;
pub use written::Written;
