//! Why the files of a command's output directory could not be written: one error for every
//! command that writes figures, a page and records (`sepval plan`, `sepval predict`).

use std::path::PathBuf;

use crate::figures::FigureError;
use crate::html::HtmlError;

/// Outputs that could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OutputError {
    /// A file.
    #[error("cannot write {}", .0.path.display())]
    Write(#[source] sepval_common::atomic_file::WriteError),
    /// A directory.
    #[error("cannot create {}: {source}", path.display())]
    Dir {
        /// The directory.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// A figure.
    #[error(transparent)]
    Figure(#[from] FigureError),
    /// The page.
    #[error(transparent)]
    Page(#[from] HtmlError),
    /// A signal asked the process to stop.
    #[error("interrupted by a signal")]
    Interrupted,
}
