//! The prediction's outputs: DIR/figures/prediction.png (the six channels with their bands and
//! the flown release over them), DIR/report.html (the answer first, the private module
//! `page`), DIR/bands.csv and DIR/prediction.json (its record, [`crate::record`]), in that
//! order, prediction.json last. Each file is written atomically and the cancellation flag is
//! checked before each: a failed or interrupted prediction leaves no partial file.

use std::path::{Path, PathBuf};

use sepval_report::figures::{Band, band_figure};

use crate::Prediction;
use crate::record::{PredictionFile, bands_csv};

pub use sepval_report::OutputError;
use sepval_report::Written;

/// Writes the figure, the page, bands.csv and prediction.json into `out`; returns the files
/// written.
pub fn write_outputs(
    prediction: &Prediction,
    file: &PredictionFile,
    out: &Path,
) -> Result<Vec<PathBuf>, OutputError> {
    let mut w = Written::into(out);
    let figures = w.figures()?;
    let ch = file.channels();
    let bands: [Band; 6] = std::array::from_fn(|c| Band {
        lo: &ch[c].lo,
        mid: &ch[c].mid,
        hi: &ch[c].hi,
    });
    let label = match &file.check {
        Some(c) => format!("flown: {}", c.data),
        None => String::new(),
    };
    let data = prediction.flown.as_deref().map(|d| (label.as_str(), d));
    let c = &file.condition;
    let title = format!(
        "Predicted release at Mach {}, {} m, alpha {} deg, beta {} deg: {:.0} % bands",
        crate::page::number(c.mach),
        crate::page::number(c.altitude_m),
        crate::page::number(c.alpha_deg),
        crate::page::number(c.beta_deg),
        100.0 * file.level
    );
    let band = format!("{:.0} % band", 100.0 * file.level);
    w.figure(figures.join("prediction.png"), |path| {
        band_figure(path, &file.t_s, &bands, data, &band, &title)
    })?;
    let html = crate::page::render(file, "figures/prediction.png")?;
    w.file("report.html", html.as_bytes())?;
    w.file("bands.csv", bands_csv(file).as_bytes())?;
    w.json("prediction.json", file)?;
    Ok(w.done())
}
