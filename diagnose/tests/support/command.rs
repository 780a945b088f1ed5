//! `sepval diagnose` in process, for the test binaries that diagnose (included by `#[path]` in
//! `diagnose/tests/catalogue`, `diagnose/tests/discovery` and `plan/tests/closing`): the flags
//! turned into the command's own options by the function `sepval/src/command/diagnose.rs`
//! calls ([`DiagnoseOptions::configure`] of the releases and the baseline search), with the
//! CLI tests' reduced budget (`sepval_tests::REDUCED_BUDGET`: 20 generations, in process on two
//! threads) and the command's defaults (population 100, seed 1, LM budget 3000, outliers
//! refused), so that a diagnosis made here is the command's to the last bit. What only the
//! binary does (its summary on stdout, the claim of `--out`, the exit status) is tested
//! through the binary, `sepval/tests/cli`.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use sepval_common::evaluation::InProcess;
use sepval_common::telemetry::outliers::Policy;
use sepval_diagnose::{DiagnoseOptions, Diagnosis, diagnose};
use sepval_fit::BaselineSearch;
use sepval_run::inputs::Releases;
use sepval_solve::ga::GaSettings;
use sepval_solve::run::NoProgress;
use serde_json::Value;

/// The flags of one `sepval diagnose` run (files by their paths).
pub struct Diagnose {
    /// `--data`, each release fitted.
    pub data: Vec<PathBuf>,
    /// `--validate`, each release held out.
    pub validate: Vec<PathBuf>,
    /// `--scenario` (the embedded default when `None`).
    pub scenario: Option<PathBuf>,
    /// `--extension`.
    pub extension: Option<PathBuf>,
    /// `--generations`.
    pub generations: usize,
    /// `--after`: an earlier diagnosis's directory.
    pub after: Option<PathBuf>,
    /// `--plan`: the plan made from it.
    pub plan: Option<PathBuf>,
}

impl Diagnose {
    /// `sepval diagnose --data ... --generations 20 --evaluator inproc --threads 2`.
    pub fn of(data: Vec<PathBuf>) -> Diagnose {
        Diagnose {
            data,
            validate: Vec::new(),
            scenario: None,
            extension: None,
            generations: 20,
            after: None,
            plan: None,
        }
    }

    /// The diagnosis, its files written into `out` (created).
    pub fn run(&self, out: &Path) -> Diagnosis {
        let releases = Releases {
            data: &self.data,
            validate: &self.validate,
            scenario: self.scenario.as_deref(),
            extension: self.extension.as_deref(),
            policy: Policy::Refuse,
        };
        let search = BaselineSearch {
            ga: GaSettings {
                population: 100,
                generations: self.generations,
                seed: 1,
                ..GaSettings::default()
            },
            lm_budget: 3000,
            sigma_pos_m: None,
            sigma_att_deg: None,
        };
        let mut tell = |said: String| eprintln!("{said}");
        let (job, options) =
            DiagnoseOptions::configure(&releases, &search, out.to_path_buf(), &mut tell).unwrap();
        let options = DiagnoseOptions {
            after: self.after.clone(),
            plan: self.plan.clone(),
            ..options
        };
        std::fs::create_dir_all(out).unwrap();
        let mut evaluator = InProcess::new(Arc::new(job), 2);
        diagnose(&options, &mut evaluator, &mut NoProgress).unwrap()
    }

    /// [`Diagnose::run`], and the diagnosis as it wrote it: `out/diagnosis.json`.
    pub fn record(&self, out: &Path) -> Value {
        self.run(out);
        serde_json::from_slice(&std::fs::read(out.join("diagnosis.json")).unwrap()).unwrap()
    }
}

/// `sepval diagnose --data F ... --out OUT` in `dir` (the files `data` there) with the reduced
/// budget; returns diagnosis.json.
pub fn diagnosis_of(dir: &Path, data: &[&str], out: &str) -> Value {
    Diagnose::of(data.iter().map(|d| dir.join(d)).collect()).record(&dir.join(out))
}
