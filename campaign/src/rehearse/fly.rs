//! One release of a rehearsal flown (docs/campaign.md, "Rehearsal"): the truth simulated at
//! the condition with the instrument's noise (seed `noise_seed + k - 1` for the k-th release,
//! docs/model.md's synthetic flight test), its file written, `add` run on it, and what it did
//! to the conditions' states counted.

use std::path::{Path, PathBuf};

use sepval_common::scenario::hex_sha256;
use sepval_common::simulation::{SimError, Simulator, sample_times};
use sepval_common::synthetic::synthetic_flight_test;
use sepval_predict::record::ConditionRecord;
use sepval_solve::run::ProgressObserver;

use super::{FlownRelease, Truth};
use crate::CampaignError;
use crate::assess::StartEvaluator;
use crate::program::Campaign;
use crate::record::record_error;
use crate::release::NewRelease;
use crate::state::State;

/// Where a release is flown and what its plan said of it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Candidate {
    /// Its index in the grid.
    pub index: usize,
    /// The planned probability of failing there.
    pub p_fail: f64,
    /// The plan's forecast of how many undecided conditions it settles.
    pub expected_settled: f64,
}

/// One release of a rehearsal: the truth flown at the planned condition, the release's
/// number (1 for the first), and where its file goes.
pub(super) struct Release<'a> {
    pub truth: &'a Truth,
    pub at: Candidate,
    pub number: usize,
    pub dir: &'a Path,
}

/// What flying a planned release did.
pub(super) enum Flew {
    /// The release was added to the campaign.
    Added(FlownRelease),
    /// The truth diverged there (the store tumbles): nothing to add, and why.
    Tumbled(FlownRelease, String),
}

/// Flies `release` in the truth (`truly_fails` there or not) and adds it to `c`.
pub(super) fn fly(
    c: &mut Campaign,
    release: &Release<'_>,
    truly_fails: bool,
    start: &mut StartEvaluator<'_>,
    observer: &mut dyn ProgressObserver,
) -> Result<Flew, CampaignError> {
    let Release {
        truth,
        at: p,
        number,
        dir,
    } = *release;
    let base = &truth.scenario;
    let times = sample_times(base.integrator.t_end_s, base.integrator.rate_hz);
    let s = c.grid.scenario(base, p.index);
    let mut flown = FlownRelease {
        condition: ConditionRecord::of(&s.flight),
        p_fail_planned: p.p_fail,
        truly_safe: !truly_fails,
        expected_settled: p.expected_settled,
        settled: 0,
        unsettled: 0,
    };
    let data = match synthetic_flight_test(
        &Simulator::new(&s),
        &truth.factors,
        &truth.effects,
        &times,
        Some(truth.noise_seed.wrapping_add(number as u64 - 1)),
    ) {
        Ok(data) => data,
        Err(SimError::Diverged(d)) => {
            flown.truly_safe = false;
            let why = format!("release {number} tumbled ({d}); the rehearsal stopped there");
            return Ok(Flew::Tumbled(flown, why));
        }
        Err(e) => {
            return Err(crate::Refusal::TruthAtRelease { number, reason: e }.into());
        }
    };
    let path: PathBuf = dir.join(format!("flown-{number:02}.csv"));
    data.write(&path).map_err(|e| record_error(&path, e))?;
    let bytes = std::fs::read(&path).map_err(|e| record_error(&path, e))?;
    let before = c.current()?;
    let release = NewRelease {
        given: path,
        sha256: hex_sha256(&bytes),
        data,
        scenario: c.grid.scenario(&c.scenario, p.index),
        notes: Vec::new(),
    };
    crate::add::add(c, vec![release], start, observer)?;
    let after = c.current()?;
    let moved = |from: &dyn Fn(State) -> bool, to: &dyn Fn(State) -> bool| {
        before
            .iter()
            .zip(&after)
            .filter(|(b, a)| from(b.state) && to(a.state))
            .count()
    };
    let undecided = |s: State| s == State::Undecided;
    let decided = |s: State| s != State::Undecided;
    flown.settled = moved(&undecided, &decided);
    flown.unsettled = moved(&decided, &undecided);
    Ok(Flew::Added(flown))
}
