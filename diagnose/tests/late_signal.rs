//! A signal late in a diagnosis, while its files are written (issue 21, item 9): the
//! diagnosis ends with `Interrupted` (the command's exit status 130), the files written before
//! the signal stay whole, and no other file is begun. The flag is set by the test's progress
//! observer at a fixed point of the outputs stage (after its first file), so the test is
//! deterministic. It has this test binary to itself because the flag is process-wide and is
//! never cleared.

use std::path::Path;
use std::sync::Arc;

use sepval_common::evaluation::{InProcess, Job};
use sepval_common::scenario::Scenario;
use sepval_common::synthetic::default_flight_test;
use sepval_diagnose::{DiagnoseError, DiagnoseOptions, diagnose};
use sepval_fit::sigma::Sigma;
use sepval_fit::{FitOptions, Method};
use sepval_run::inputs::InputsRecord;
use sepval_solve::ga::GaSettings;
use sepval_solve::hill::HillSettings;
use sepval_solve::lm::LmSettings;
use sepval_solve::run::{Progress, ProgressObserver, RunError};

/// Asks the process to stop once the outputs stage has written its first file.
struct SignalAfterFirstOutput {
    outputs: bool,
}

impl ProgressObserver for SignalAfterFirstOutput {
    fn start(&mut self, label: &str, _: Option<usize>) {
        self.outputs = label == "outputs";
    }

    fn progress(&mut self, p: &Progress) {
        if self.outputs && p.step >= 1 {
            sepval_core::cancel::request();
        }
    }

    fn finish(&mut self) {}
}

fn options(out: &Path, job: &Job) -> DiagnoseOptions {
    let sigma = Sigma::resolve(job, Some(0.003), Some(0.1)).unwrap();
    let lm = LmSettings {
        budget: 300,
        ..LmSettings::default()
    };
    DiagnoseOptions {
        fit: FitOptions {
            method: Method::GaLm,
            ga: GaSettings {
                population: 20,
                generations: 3,
                ..GaSettings::default()
            },
            hill: HillSettings::default(),
            sigma,
            truth: None,
            out: out.join("baseline"),
            resume: None,
            inputs: InputsRecord {
                data: Vec::new(),
                scenario: None,
                extension: None,
                outliers: Default::default(),
            },
            lm: lm.clone(),
            lm_probe: lm.clone(),
            clearance: None,
            strict_tables: false,
        },
        out: out.to_path_buf(),
        candidate_lm: LmSettings {
            max_iterations: 20,
            budget: 2_000,
            ..lm
        },
        validation: None,
        given_terms: Vec::new(),
        strict_tables: false,
        clearance: None,
        after: None,
        plan: None,
    }
}

#[test]
fn a_signal_while_the_report_is_written_stops_it_and_leaves_no_partial_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("diag");
    let job = Arc::new(Job::single(
        "default",
        &Scenario::embedded_default(),
        default_flight_test(),
    ));
    let mut evaluator = InProcess::new(Arc::clone(&job), 2);
    let mut observer = SignalAfterFirstOutput { outputs: false };
    let e = diagnose(&options(&out, &job), &mut evaluator, &mut observer).unwrap_err();
    assert!(
        matches!(e, DiagnoseError::Run(RunError::Interrupted)),
        "{e}"
    );
    // The first output (the residual figure of the one event) was written whole before the
    // signal; nothing after it was begun.
    assert!(out.join("figures/residuals_event1.png").is_file());
    for later in [
        "diagnosis.json",
        "report.html",
        "extension.toml",
        "factors.json",
    ] {
        assert!(
            !out.join(later).exists(),
            "{later} written after the signal"
        );
    }
    let temporary: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .chain(std::fs::read_dir(out.join("figures")).unwrap())
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".sepval-tmp-"))
        .collect();
    assert!(temporary.is_empty(), "{temporary:?}");
}
