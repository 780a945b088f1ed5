//! What `sepval plan` says on the terminal: the release recommended, what it separates, its
//! information gain, and where the files are.

use std::path::Path;

use crate::record::PlanFile;

/// The terminal summary of the record written in `out`: a few lines.
pub fn summary(file: &PlanFile, out: &Path) -> String {
    let mut s = String::new();
    match file.conditions.first() {
        Some(c) => {
            s.push_str(&format!(
                "recommend: Mach {}, altitude {} m, alpha {} deg, beta {} deg, gamma {} deg\n",
                c.mach, c.altitude_m, c.alpha_deg, c.beta_deg, c.gamma_deg
            ));
            if file.ranked_by == "separation" {
                s.push_str(&format!(
                    "separates: {} of {} pair(s) (separation {:.1}, threshold {})\n",
                    c.separates.len(),
                    c.pairs.len(),
                    c.separation.unwrap_or(f64::NAN),
                    file.threshold
                ));
            } else {
                s.push_str("rivals:    none: planned for information alone\n");
            }
            s.push_str(&format!(
                "gain:      {:.3} in ln det of the answer's information\n",
                c.information_gain.unwrap_or(f64::NAN)
            ));
        }
        None => s.push_str("recommend: nothing (no condition)\n"),
    }
    s.push_str(&format!(
        "plan:      {} conditions, {} simulations, {:.1} s\n",
        file.conditions.len(),
        file.evaluations,
        file.wall_s
    ));
    s.push_str(&format!("report:    {}\n", out.join("plan.html").display()));
    s
}
