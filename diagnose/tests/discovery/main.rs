//! The diagnosis beyond the effect catalogue, in process: causes outside the catalogue
//! discovered as terms of the library (`families`: a side-force step, a roll buffet, roll
//! damping as a rate term, a sideslip-dependent interference yaw moment, an ejector force along
//! the stroke, a Mach-dependent drag, null data), gusts discovered as wind (`gust`), the rivals
//! one release cannot tell apart (`rivals`), and what stops discovery or makes its answer
//! unreliable (`limits`: a full term budget, the public CFD trajectory). Slow tier
//! (`SEPVAL_SLOW_TESTS=1`): each test is one or a few diagnoses, 3 to 35 s alone on two cores;
//! but `after` (a diagnosis `--after` an earlier one whose open cause must be carried forward
//! and answer) runs in the fast tier, on a reduced budget (23 s of CPU, 2026-12-06).
//!
//! Each diagnosis is the one `sepval diagnose --data ... --generations 20 --evaluator inproc
//! --threads 2` makes of the same files (`support/command.rs`: the command's own options, so the
//! diagnosis is the command's to the last bit), of releases made by the tests' own generator
//! (`support/generator.rs`) or by simulate's library calls through an extension's gust
//! (`support/gusts.rs`); one of each, diagnosed here and by the binary, gave the same
//! diagnosis.json but for its wall time, digest and event names (2026-11-28). No two tests
//! diagnose the same releases, so no diagnosis is shared between them (a `OnceLock` fixture
//! would have nothing to share). The binary's own tests (`sepval/tests/cli`) keep one
//! discovery end to end (`gust.rs`: its summary on stdout, the page, the figures, the extension
//! read back by `sepval simulate`) and the refusals of a malformed extension.

#[path = "../support/command.rs"]
mod command;
#[path = "../support/generator.rs"]
mod generator;
#[path = "../support/gusts.rs"]
mod gusts;
#[path = "../support/releases.rs"]
mod releases;
#[path = "../support/simulate.rs"]
mod simulate;

mod after;
mod families;
mod gust;
mod limits;
mod located;
mod rivals;
