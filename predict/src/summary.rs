//! What `sepval predict` says on the terminal: the prediction at its last time with its bands,
//! the sources of their width, the post-flight check and the clearance, and where the files are.

use std::path::Path;

use crate::record::PredictionFile;

/// The terminal summary of the record written in `out`: a few lines.
pub fn summary(file: &PredictionFile, out: &Path) -> String {
    let k = file.t_s.len().saturating_sub(1);
    let ch = file.channels();
    let mut s = file
        .extrapolation
        .as_ref()
        .map_or(String::new(), |w| format!("warning:   {w}\n"));
    s.push_str(&format!(
        "predict:   t = {:.3} s: x {:.3} m [{:.3}, {:.3}], z {:.3} m [{:.3}, {:.3}], pitch {:.2} deg [{:.2}, {:.2}] ({:.0} % bands)\n",
        file.t_s.get(k).copied().unwrap_or(f64::NAN),
        ch[0].mid[k],
        ch[0].lo[k],
        ch[0].hi[k],
        ch[2].mid[k],
        ch[2].lo[k],
        ch[2].hi[k],
        ch[4].mid[k],
        ch[4].lo[k],
        ch[4].hi[k],
        100.0 * file.level
    ));
    let src = &file.sources;
    s.push_str(&format!(
        "sources:   factors {:.0} %, model form {:.0} %, measurement {:.0} % (most: {})\n",
        100.0 * src.factors.share,
        100.0 * src.model_form.share,
        100.0 * src.measurement.share,
        src.dominant.replace('_', " ")
    ));
    if let Some(c) = &file.check {
        s.push_str(&format!("check:     {}\n", c.verdict));
    }
    if let Some(c) = &file.clearance {
        s.push_str(&format!("clearance: {}\n", crate::clearance::words(c)));
    }
    s.push_str(&format!(
        "samples:   {} ({} ran), {} simulations, {:.1} s\n",
        file.samples, file.samples_used, file.evaluations, file.wall_s
    ));
    s.push_str(&format!(
        "report:    {}\n",
        out.join("report.html").display()
    ));
    s
}
