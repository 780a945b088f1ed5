//! Naming the found terms (`docs/discovery.md` section 11.7): each entry's estimate with its
//! standard error (an oscillation pair as one amplitude and phase, its error propagated with the
//! pair's correlation), its locator, its gain, its physical reading and its group; most
//! important first.

use sepval_common::evaluation::Job;
use sepval_common::extension::Family;
use sepval_solve::identifiability::{Identifiability, identifiability};

use super::picked::{EntryParams, Picked};
use crate::found::{DiscoveredTerm, Gain, GroupMember, Location};
use crate::library::Entry;
use crate::{Fitted, readings};

/// The found terms of `fitted` (made of `picked`, at its values), with each entry's gain and
/// group; the largest chi-square drop first.
pub(super) fn name_terms(
    job: &Job,
    fitted: &Fitted,
    picked: &Picked,
    gains: &[Gain],
    total: &Gain,
    groups: &[Vec<GroupMember>],
    locations: Vec<Vec<Location>>,
) -> Vec<DiscoveredTerm> {
    let space = fitted.space(job);
    let events: Vec<usize> = job.events().iter().map(|e| e.data.len()).collect();
    let id = identifiability(
        &space.params,
        &fitted.lm.x,
        &fitted.lm.residuals,
        &fitted.lm.jacobian,
        &events,
    );
    let mut found: Vec<DiscoveredTerm> = picked
        .entries()
        .iter()
        .zip(picked.params(&fitted.terms))
        .zip(locations)
        .enumerate()
        .map(|(k, ((e, at), locations))| {
            let gain = gains.get(k).cloned().unwrap_or_else(|| total.clone());
            DiscoveredTerm {
                locations,
                ..named(job, e, &at, &id, gain, groups[k].clone())
            }
        })
        .collect();
    found.sort_by(|a, b| b.gain.chi2_drop.total_cmp(&a.gain.chi2_drop));
    found
}

/// Entry `e`, whose parameters sit at `at`, named with the estimates of `id`, its `gain` and
/// its `group`.
fn named(
    job: &Job,
    e: &Entry,
    at: &EntryParams,
    id: &Identifiability,
    gain: Gain,
    group: Vec<GroupMember>,
) -> DiscoveredTerm {
    let now = &e.terms;
    let coef_pos = at.coefficients();
    let (coefficient, std_error, phase_deg) = if now.len() == 2 {
        let (a, b) = (now[0].coefficient, now[1].coefficient);
        let amp = a.hypot(b);
        let var = match (id.std_error(coef_pos[0]), id.std_error(coef_pos[1])) {
            (Some(sa), Some(sb)) if amp > 0.0 => {
                let rho = id.rho(coef_pos[0], coef_pos[1]);
                Some(
                    ((a * a * sa * sa + b * b * sb * sb + 2.0 * a * b * rho * sa * sb)
                        / (amp * amp))
                        .max(0.0)
                        .sqrt(),
                )
            }
            _ => None,
        };
        (amp, var, Some(b.atan2(a).to_degrees()))
    } else {
        (now[0].coefficient, id.std_error(coef_pos[0]), None)
    };
    let lead = now[0];
    let locator = lead.locator[0];
    let family = lead.regressor.family();
    DiscoveredTerm {
        axis: lead.axis.name().to_string(),
        family: family.name().to_string(),
        term: e.formula(),
        coefficient,
        std_error,
        phase_deg,
        t_on_s: matches!(family, Family::Step | Family::Wind).then_some(locator),
        rise_s: (family == Family::Wind).then_some(lead.locator[1]),
        f_hz: (family == Family::Oscillation).then_some(locator),
        lambda_m: matches!(family, Family::Interference | Family::InterferenceFlowAngle)
            .then_some(locator),
        mach0: (family == Family::Mach).then_some(locator),
        locator_std_error: at.locator().and_then(|i| id.std_error(i)),
        rise_std_error: at
            .length()
            .and_then(|i| id.parameters.get(i))
            .filter(|p| p.identifiable)
            .and_then(|p| p.std_error),
        locations: Vec::new(),
        gain,
        reading: readings::reading(&lead, &job.events()[0].simulator.scenario().interference),
        group,
    }
}
