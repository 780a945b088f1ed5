//! The envelope's outputs: DIR/figures/envelope.png (the probability of failing to clear over
//! the map's two axes, with the allowed probability's contour and the releases flown),
//! DIR/report.html (the answer first, the private module `page`), DIR/envelope.csv (one row
//! per condition, [`crate::row`]) and DIR/envelope.json (the record), in that order,
//! envelope.json last. Each file is written atomically and the cancellation flag is checked
//! before each ([`sepval_report::Written`]): a failed or interrupted envelope leaves no
//! partial file.

use std::path::{Path, PathBuf};

use sepval_report::figures::{EnvelopeMap, MapAxis, Safety, envelope_map};
use sepval_run::conditions::Quantity;

use crate::grid::Grid;
use crate::record::EnvelopeFile;
use crate::row::csv;

pub use sepval_report::OutputError;
use sepval_report::Written;

/// Writes the figure, the page, envelope.csv and envelope.json into `out`; returns the files
/// written.
pub fn write_outputs(
    grid: &Grid,
    file: &EnvelopeFile,
    out: &Path,
) -> Result<Vec<PathBuf>, OutputError> {
    let mut w = Written::into(out);
    let figures = w.figures()?;
    w.figure(figures.join("envelope.png"), |path| map(grid, file, path))?;
    let html = crate::page::render(file, "figures/envelope.png")?;
    w.file("report.html", html.as_bytes())?;
    w.file("envelope.csv", csv(&file.rows).as_bytes())?;
    w.json("envelope.json", file)?;
    Ok(w.done())
}

/// DIR/figures/envelope.png: the worst probability of failing to clear in each cell.
fn map(grid: &Grid, file: &EnvelopeFile, path: &Path) -> Result<(), OutputError> {
    let axes = grid.map_axes();
    let one = [grid.flight(0).mach];
    let (xq, xv) = axes.first().copied().unwrap_or((Quantity::Mach, &one));
    let ny = axes.get(1).map_or(1, |(_, v)| v.len());
    let mut cells = vec![vec![f64::NAN; xv.len()]; ny];
    for r in &file.rows {
        let (ix, iy) = grid.cell(r.index);
        let cell = &mut cells[iy][ix];
        if !(cell.is_finite() && *cell >= r.p_fail) {
            *cell = r.p_fail;
        }
    }
    let title = format!(
        "Probability of coming within {} mm of the aircraft or diverging",
        file.criterion_mm
    );
    let criterion_label = format!(
        "{:.0} % allowed (cleared inside)",
        100.0 * file.allowed_probability
    );
    let x = MapAxis {
        label: xq.label(),
        values: xv,
    };
    let y = axes.get(1).map(|(q, v)| MapAxis {
        label: q.label(),
        values: v,
    });
    envelope_map(
        path,
        &EnvelopeMap {
            title: &title,
            x,
            y,
            cells: &cells,
            value_label: "probability of failing to clear",
            safety: Safety::LowIsSafe,
            criterion: file.allowed_probability,
            criterion_label: &criterion_label,
            flown: &file.flown,
        },
    )?;
    Ok(())
}
