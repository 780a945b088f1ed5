//! What `sepval diagnose` says on the terminal: the answer, its causes and terms, the fit
//! before and after, whether the noise is reached, the rivals, the releases predicted, and
//! where the files are. The whole story is on the page (`page`) and in diagnosis.json.

use std::path::Path;

use crate::verdict::fmt_discovered_brief;
use crate::{Diagnosis, rival_name};

/// The terminal summary of `d`, written in `out`: a few lines (at most 12), each at most 160
/// characters.
pub fn summary(d: &Diagnosis, out: &Path) -> String {
    let mut s = String::new();
    if !d.baseline_verdict.converged() {
        s.push_str(&format!(
            "UNRELIABLE: the baseline fit failed (J_pos {:.0}, J_att {:.0} sigma): no cause below is reliable\n",
            d.baseline.j_pos_m / d.sigma_pos_m,
            d.baseline.j_att_deg / d.sigma_att_deg
        ));
    }
    let answer = if !d.discovered.is_empty() {
        "terms found beyond the catalogue"
    } else if !d.causes.is_empty() {
        "catalogue effects"
    } else {
        "nothing named"
    };
    s.push_str(&format!("answer:    {answer}\n"));
    for c in &d.causes {
        let values: Vec<String> = d
            .parameters
            .get(c)
            .map(|v| {
                v.iter()
                    .map(|p| match p.std_error {
                        Some(se) => format!("{} = {:.4} ± {:.2}", p.name, p.value, se),
                        None => format!("{} = {:.4}", p.name, p.value),
                    })
                    .collect()
            })
            .unwrap_or_default();
        s.push_str(&format!("cause:     {c} ({})\n", values.join(", ")));
    }
    for t in &d.discovered {
        s.push_str(&format!("found:     {}\n", fmt_discovered_brief(t)));
        s.push_str(&format!("           {}\n", t.reading));
    }
    s.push_str(&format!(
        "fit:       J_pos {:.4} -> {:.4} m, J_att {:.3} -> {:.3} deg (noise {:.4} m, {:.3} deg)\n",
        d.baseline.j_pos_m,
        d.extended.j_pos_m,
        d.baseline.j_att_deg,
        d.extended.j_att_deg,
        d.sigma_pos_m,
        d.sigma_att_deg
    ));
    let explained = match &d.extension {
        Some(x) if x.answer => x.explained,
        _ => d.explained,
    };
    s.push_str(&format!(
        "explained: {} ({} simulations, {:.1} s)\n",
        if explained {
            "yes, to the noise"
        } else {
            "no, structure remains"
        },
        d.evaluations,
        d.wall_s
    ));
    if !d.rivals.is_empty() {
        s.push_str(&rivals_line(d));
    }
    for v in &d.validation {
        let f = |v: Option<f64>, p: usize| {
            v.map_or("-".to_string(), |v| format!("{v:.prec$}", prec = p))
        };
        s.push_str(&format!(
            "predicts:  {}: J_pos {} -> {} m, J_att {} -> {} deg\n",
            v.event,
            f(v.baseline_j_pos_m, 4),
            f(v.extended_j_pos_m, 4),
            f(v.baseline_j_att_deg, 3),
            f(v.extended_j_att_deg, 3)
        ));
        for a in &v.alternatives {
            let kind = a.model.split(':').next().unwrap_or("alternative");
            s.push_str(&format!(
                "           the {kind} alternative would give J_pos {:.4} m, J_att {:.3} deg\n",
                a.j_pos_m, a.j_att_deg
            ));
        }
    }
    if let Some(caution) = &d.caution {
        s.push_str(&format!("caution:   {caution}\n"));
    }
    if d.extension.as_ref().is_some_and(|x| x.answer) {
        s.push_str(&format!(
            "extension: {} with factors {}\n",
            out.join("extension.toml").display(),
            out.join("factors.json").display()
        ));
    }
    s.push_str(&format!(
        "report:    {}\n",
        out.join("report.html").display()
    ));
    s
}

/// The line that says what the data cannot tell from the answer, at most 160 characters.
fn rivals_line(d: &Diagnosis) -> String {
    const WIDTH: usize = 160;
    let mut line = "rivals:    the data cannot tell it from".to_string();
    for (k, r) in d.rivals.iter().enumerate() {
        let item = format!(
            "{} {} (BIC {:+.1})",
            if k == 0 { "" } else { "," },
            rival_name(r),
            r.delta_bic
        );
        let rest = format!(" ... ({} in all, see diagnosis.json)", d.rivals.len());
        if line.chars().count() + item.chars().count() + rest.chars().count() > WIDTH {
            line.push_str(&rest);
            break;
        }
        line.push_str(&item);
    }
    line.push('\n');
    line
}
