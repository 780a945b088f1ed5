//! A field's uncertainty as a DAVE-ML file gives it (DAVE-ML 2.0 reference manual / ANSI/AIAA
//! S-119-2011 section 5.7: an `uncertainty` holds a `normalPDF` whose `bounds` are `numSigmas`
//! standard deviations, or a `uniformPDF`), read into one standard deviation per value of the
//! field in the scenario's units, for a reader that takes the store's uncertainty in (`sepval
//! campaign init --prior-daveml`); what cannot be read so is kept with the reason.

use crate::error::Place;
use crate::parse::{Pdf, PdfKind};
use crate::units::Conversion;

/// A field's uncertainty as the file gives it: a `normalPDF`'s bounds divided by its
/// `numSigmas` (DAVE-ML 2.0 section 5.7), one standard deviation per value of the field.
#[derive(Debug, Clone, PartialEq)]
pub struct Spread {
    /// One standard deviation per value of the field, in its table's order (one for a
    /// constant or when the file gives one for the whole table), in the scenario's units;
    /// empty when unusable.
    pub sd: Vec<f64>,
    /// Why it cannot be read as standard deviations (a `uniformPDF`, no `numSigmas`, bounds
    /// of another shape than the table's, or not given as numbers).
    pub unusable: Option<String>,
    /// Where its PDF is.
    pub place: Place,
}

/// The spread of `pdf` over a field of `points` values in the file's order, its bounds
/// converted by `c`.
pub(crate) fn spread_of(pdf: &Pdf, points: usize, c: Conversion) -> Spread {
    let unusable = |why: String| Spread {
        sd: Vec::new(),
        unusable: Some(why),
        place: pdf.place.clone(),
    };
    if pdf.kind == PdfKind::Uniform {
        return unusable(
            "a uniformPDF: only a normalPDF gives a mean and standard deviation".into(),
        );
    }
    let Some(k) = pdf.num_sigmas.filter(|k| *k > 0.0) else {
        return unusable("a normalPDF without a numSigmas above 0: its bounds are not a known number of standard deviations".into());
    };
    let n = pdf.bounds.len();
    if n != 1 && n != points {
        return unusable(format!(
            "a normalPDF with {n} bounds for a field of {points} values: expected one, or one per value"
        ));
    }
    if pdf.bounds.iter().any(|b| *b < 0.0) {
        return unusable("a normalPDF with a negative bound".into());
    }
    Spread {
        sd: pdf.bounds.iter().map(|b| c.apply(*b).abs() / k).collect(),
        unusable: None,
        place: pdf.place.clone(),
    }
}
