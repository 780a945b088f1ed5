//! DIR/report.html: the prediction as a page for people, the answer first (where the store
//! will be, how sure, and the post-flight check's verdict when a flown release was given), then
//! the band at the end of the release, the sources' shares, the figure and how it was computed.
//! The page is the template `templates/prediction.html` in sepval-report's layout
//! (`sepval_report::html`); this module turns a [`PredictionFile`] into its context.

use sepval_report::html::{HtmlError, PageTemplate, render_page};
use sepval_report::words::{condition, decimals};
use serde::Serialize;

use crate::check::CHANNEL_WORDS;
use crate::record::PredictionFile;

/// The page's template.
const PREDICTION: PageTemplate = PageTemplate {
    name: "prediction.html",
    source: include_str!("../templates/prediction.html"),
};

#[derive(Serialize)]
struct Page {
    headline: String,
    clearance: String,
    check: String,
    check_data: String,
    sources_words: String,
    t_end: String,
    checked: bool,
    channels: Vec<ChannelRow>,
    sources: Vec<SourceRow>,
    calibration: String,
    figure: String,
    method: String,
    models: Vec<ModelRow>,
    held_out: Vec<HeldRow>,
    noise: String,
    samples: String,
    evaluations: u64,
    wall_s: String,
    from: String,
}

#[derive(Serialize)]
struct ChannelRow {
    name: String,
    lo: String,
    mid: String,
    hi: String,
    inside: String,
    leaves: String,
}

#[derive(Serialize)]
struct SourceRow {
    name: &'static str,
    share: String,
    channels: Vec<String>,
}

#[derive(Serialize)]
struct ModelRow {
    name: String,
    role: &'static str,
    delta_bic: String,
    weight: String,
    samples: usize,
}

#[derive(Serialize)]
struct HeldRow {
    release: String,
    how: String,
    err_pos: String,
    band_pos: String,
    err_att: String,
    band_att: String,
    note: String,
}

/// A number as the page shows it: one decimal from 100, three from 1, four below
/// ([`decimals`]).
pub(crate) fn number(v: f64) -> String {
    let n = if v.abs() >= 100.0 {
        1
    } else if v.abs() >= 1.0 {
        3
    } else {
        4
    };
    decimals(v, n)
}

fn percent(v: f64) -> String {
    format!("{:.0} %", 100.0 * v)
}

/// The condition in words ([`sepval_report::words::condition`]).
pub(crate) fn condition_words(f: &PredictionFile) -> String {
    let c = &f.condition;
    condition(c.mach, c.altitude_m, c.alpha_deg, c.beta_deg, c.gamma_deg)
}

/// The answer in one sentence: where the store is at the end, with the band.
fn headline(f: &PredictionFile) -> String {
    let k = f.t_s.len().saturating_sub(1);
    let t = f.t_s.get(k).copied().unwrap_or(f64::NAN);
    let ch = f.channels();
    let at = |c: usize, unit: &str| {
        format!(
            "{} {} {unit} ({} to {})",
            CHANNEL_WORDS[c],
            number(ch[c].mid[k]),
            number(ch[c].lo[k]),
            number(ch[c].hi[k])
        )
    };
    let far = f
        .extrapolation
        .as_ref()
        .map_or(String::new(), |w| format!("{w} "));
    format!(
        "{far}At {}, {} s after release the store is predicted at {}, {}, {} and {} ({:.0} % bands).",
        condition_words(f),
        number(t),
        at(0, "m"),
        at(2, "m"),
        at(4, "deg"),
        at(3, "deg"),
        100.0 * f.level
    )
}

/// The page of `file`, its figure at `figure` (relative to the page).
pub fn render(file: &PredictionFile, figure: &str) -> Result<String, HtmlError> {
    let k = file.t_s.len().saturating_sub(1);
    let s = &file.sources;
    let row = |name: &'static str, share: f64, channels: &[f64; 6]| SourceRow {
        name,
        share: percent(share),
        channels: channels.iter().map(|v| percent(*v)).collect(),
    };
    let rivals = if file.models.iter().any(|m| !m.answer) {
        format!(" ({} from the rivals)", percent(s.model_form.rivals))
    } else {
        String::new()
    };
    let page = Page {
        headline: headline(file),
        clearance: file
            .clearance
            .as_ref()
            .map_or(String::new(), crate::clearance::words),
        check: file
            .check
            .as_ref()
            .map_or(String::new(), |c| c.verdict.clone()),
        check_data: file
            .check
            .as_ref()
            .map_or(String::new(), |c| c.data.clone()),
        sources_words: format!(
            "The band's width comes mostly from {}. Factors {}, model form {}{rivals}, measurement {}{}.",
            s.why,
            percent(s.factors.share),
            percent(s.model_form.share),
            percent(s.measurement.share),
            if s.measurement_included {
                ""
            } else {
                " (not included: the bands are for the noise-free trajectory; --with-noise adds it)"
            }
        ),
        t_end: number(file.t_s.get(k).copied().unwrap_or(f64::NAN)),
        checked: file.check.is_some(),
        channels: (0..6)
            .map(|c| {
                let b = file.channels()[c];
                let chk = file.check.as_ref().map(|x| &x.channels[c]);
                ChannelRow {
                    name: CHANNEL_WORDS[c].to_string(),
                    lo: number(b.lo[k]),
                    mid: number(b.mid[k]),
                    hi: number(b.hi[k]),
                    inside: chk.map_or(String::new(), |x| percent(x.inside)),
                    leaves: chk.map_or(String::new(), |x| x.leaves_at_s.map_or("-".into(), number)),
                }
            })
            .collect(),
        sources: vec![
            row("factors", s.factors.share, &s.factors.channels),
            row("model form", s.model_form.share, &s.model_form.channels),
            row("measurement", s.measurement.share, &s.measurement.channels),
        ],
        calibration: format!("Model form: {}.", s.model_form.calibration),
        figure: figure.to_string(),
        method: method(file),
        models: file
            .models
            .iter()
            .map(|m| ModelRow {
                name: m.name.clone(),
                role: if m.answer { "answer" } else { "rival" },
                delta_bic: number(m.delta_bic),
                weight: number(m.weight),
                samples: m.samples,
            })
            .collect(),
        held_out: held_rows(file),
        noise: format!(
            "{} m, {} deg",
            number(file.sigma_pos_m),
            number(file.sigma_att_deg)
        ),
        samples: format!("{} samples, {} ran", file.samples, file.samples_used),
        evaluations: file.evaluations,
        wall_s: number(file.wall_s),
        from: format!(
            "{} (the output of sepval {})",
            file.from,
            if file.from_kind == "fit" {
                "fit"
            } else {
                "diagnose"
            }
        ),
    };
    render_page(&PREDICTION, &page)
}

/// The rows of the releases held out.
fn held_rows(file: &PredictionFile) -> Vec<HeldRow> {
    let rms3 = |v: &[f64; 6], from: usize| {
        number((v[from..from + 3].iter().map(|x| x * x).sum::<f64>() / 3.0).sqrt())
    };
    file.sources
        .model_form
        .held_out
        .iter()
        .map(|h| HeldRow {
            release: h.release.clone(),
            how: h.how.clone(),
            err_pos: rms3(&h.rms_error, 0),
            band_pos: rms3(&h.rms_factor_sd, 0),
            err_att: rms3(&h.rms_error, 3),
            band_att: rms3(&h.rms_factor_sd, 3),
            note: h.note.clone(),
        })
        .collect()
}

fn method(file: &PredictionFile) -> String {
    format!(
        "Each sample draws a model by its weight (exp(-delta BIC / 2), normalised) and the answer's \
         parameters from the covariance of its refit (correlations included, redrawn when outside \
         their bounds; a rival takes the same deviations of the 17 factors), and is simulated at \
         the condition. A discrepancy calibrated on the releases held out is added to each sample \
         as a smooth error, and the measurement noise when it is included. The bands are the \
         pointwise {:.1} % and {:.1} % quantiles of the samples, the middle their median. A \
         source's share is its variance alone over the sum of the sources' variances, summed over \
         time, averaged over the channels. See docs/prediction.md.",
        50.0 * (1.0 - file.level),
        50.0 * (1.0 + file.level)
    )
}
