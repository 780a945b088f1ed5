//! The source of a prediction: the `--out` directory of `sepval fit` (DIR/result.json, format
//! [`sepval_fit::results::RESULT_FORMAT`]) or of `sepval diagnose` (DIR/diagnosis.json, format
//! [`sepval_diagnose::DIAGNOSIS_FORMAT`]), read and checked. What a prediction needs from it
//! (docs/prediction.md section 13.1): the fitted models (a fit's best refined factors; a diagnosis's
//! answer and its rivals with their BIC against the answer), the covariance of the answer's
//! parameters (`identifiability`: standard errors and correlations of the `+lm` refinement or
//! of the diagnosis's refit of its answer), the noise, the answer's residual RMS per channel on
//! the releases fitted, and where the releases fitted came from (`inputs`).

use std::path::{Path, PathBuf};

use sepval_common::evaluation::{Event, Job};
use sepval_common::telemetry::outliers::Policy;
use sepval_fit::results::FitResult;
use sepval_fit::space::Noise;
use sepval_run::inputs::InputsRecord;
use sepval_run::inputs::{self, InputError, Tell};
use sepval_run::model_spec::ModelSpec;
use sepval_run::sealed::{Record, read_record};
use sepval_solve::identifiability::Identifiability;

/// A `--from` directory that cannot be predicted from.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SourceError {
    /// Not a directory, or holding neither result.json nor diagnosis.json.
    #[error("--from {}: {message}", path.display())]
    NotASepvalOutput {
        /// The directory.
        path: PathBuf,
        /// What is missing.
        message: String,
    },
    /// A record that cannot be used: unreadable, not JSON, of another format, edited, a value
    /// out of range (the message names the file, and the line and column or the field).
    #[error("--from {}: {message}", path.display())]
    Record {
        /// The directory.
        path: PathBuf,
        /// What is wrong, with its causes.
        message: String,
    },
    /// A record that lacks what a prediction needs.
    #[error("--from {}: {file}: {message}", path.display())]
    File {
        /// The directory.
        path: PathBuf,
        /// `result.json` or `diagnosis.json`.
        file: &'static str,
        /// What is wrong.
        message: String,
    },
    /// A record whose covariance determines no parameter's standard error.
    #[error("--from {}: {file}: {reason}", path.display())]
    Undetermined {
        /// The directory.
        path: PathBuf,
        /// `result.json` or `diagnosis.json`.
        file: &'static str,
        /// How many parameters, and which are not identifiable.
        reason: Undetermined,
    },
    /// A fit without a covariance of its factors (`--method ga` or `hill`).
    #[error(
        "--from {}: the fit ran --method {methods}, which estimates no covariance of the factors; fit with --method ga+lm (or hill+lm) to predict from it",
        path.display()
    )]
    NoCovariance {
        /// The directory.
        path: PathBuf,
        /// The methods it ran.
        methods: String,
    },
}

/// Which command wrote the source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SourceKind {
    /// `sepval fit` (DIR/result.json).
    Fit,
    /// `sepval diagnose` (DIR/diagnosis.json).
    Diagnosis,
}

impl SourceKind {
    /// Its name in files: `fit` or `diagnosis`.
    pub fn name(self) -> &'static str {
        match self {
            SourceKind::Fit => "fit",
            SourceKind::Diagnosis => "diagnosis",
        }
    }
}

/// One fitted model of the source.
#[derive(Debug, Clone, PartialEq)]
pub struct SourceModel {
    /// The model as files hold it.
    pub spec: ModelSpec,
    /// Its BIC minus the answer's on the releases fitted (0 for the answer).
    pub delta_bic: f64,
}

/// What a prediction takes from its `--from` directory.
#[derive(Debug, Clone)]
pub struct Source {
    /// Which command wrote it.
    pub kind: SourceKind,
    /// The directory.
    pub dir: PathBuf,
    /// The answer first, then the rivals (a fit has none).
    pub models: Vec<SourceModel>,
    /// Standard errors and correlations of the answer's parameters.
    pub identifiability: Identifiability,
    /// The measurement noise of the source.
    pub noise: Noise,
    /// Where the releases fitted came from.
    pub inputs: InputsRecord,
    /// Releases the source held out of its fits (a diagnosis's `--validate`) whose files still
    /// open.
    pub held_out: Vec<PathBuf>,
    /// The SHA-256 of the releases fitted, as the fit recorded it (a diagnosis's: its
    /// baseline's), so that a release file changed since is refused, not fitted anew in
    /// silence; `None` when the source records none.
    pub data_sha256: Option<String>,
}

/// Refuses a covariance that determines no parameter's standard error (a fit of fewer
/// residuals than parameters: every one not identifiable): draws from it would hold every
/// parameter, and its bands would leave out the factors' uncertainty whole.
fn some_determined(id: &Identifiability) -> Result<(), Undetermined> {
    let determined = id
        .parameters
        .iter()
        .any(|p| p.std_error_white.is_some_and(|s| s.is_finite() && s > 0.0));
    if determined || id.parameters.is_empty() {
        return Ok(());
    }
    Err(Undetermined {
        parameters: id.parameters.len(),
        not_identifiable: id.not_identifiable.clone(),
    })
}

/// A covariance that determines no parameter's standard error.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "determines the standard error of none of its {parameters} parameters (not identifiable from its releases: {}): bands from it would leave out the factors' uncertainty; fit more of the release, or more releases",
    not_identifiable.join(", ")
)]
pub struct Undetermined {
    /// The parameters.
    pub parameters: usize,
    /// Those not identifiable, by name.
    pub not_identifiable: Vec<String>,
}

/// The `data_sha256` of the baseline fit a diagnosis in `dir` wrote (`baseline/result.json`,
/// read and checked as every fit result is), none when it has none.
fn baseline_data_sha256(dir: &Path) -> Result<Option<String>, SourceError> {
    let baseline = dir.join("baseline");
    if !baseline.join("result.json").exists() {
        return Ok(None);
    }
    let r: FitResult = read(&baseline, "result.json", "baseline fit result")?;
    Ok(Some(r.data_sha256))
}

/// Reads the source in `dir`: diagnosis.json when it holds one, else result.json.
pub fn read_source(dir: &Path) -> Result<Source, SourceError> {
    let not = |message: &str| SourceError::NotASepvalOutput {
        path: dir.to_path_buf(),
        message: message.to_string(),
    };
    if !dir.is_dir() {
        return Err(not(
            "not a directory (give the --out directory of `sepval fit` or `sepval diagnose`)",
        ));
    }
    if dir.join("diagnosis.json").exists() {
        return diagnosis_source(dir);
    }
    if dir.join("result.json").exists() {
        return fit_source(dir);
    }
    Err(not(
        "holds neither result.json nor diagnosis.json: not the output of `sepval fit` or `sepval diagnose`",
    ))
}

/// The record `dir/file`, read and checked by the records' one reader
/// ([`sepval_run::sealed::read_record`]: parse errors with line and column, format, digest,
/// ranges).
fn read<T: Record>(dir: &Path, file: &'static str, label: &'static str) -> Result<T, SourceError> {
    read_record(&dir.join(file), label).map_err(|e| SourceError::Record {
        path: dir.to_path_buf(),
        message: chain(&e),
    })
}

/// An error and its causes, joined by ": ".
fn chain(e: &dyn std::error::Error) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        text.push_str(": ");
        text.push_str(&c.to_string());
        cause = c.source();
    }
    text
}

fn diagnosis_source(dir: &Path) -> Result<Source, SourceError> {
    let d: sepval_diagnose::Diagnosis = read(dir, "diagnosis.json", "diagnosis")?;
    Source::of_diagnosis(d, dir)
}

impl Source {
    /// The source of diagnosis `d`, written to `dir` (its diagnosis.json, read or just
    /// written): its answer and rivals, their covariance, its noise and its held-out releases
    /// whose files still open.
    pub fn of_diagnosis(d: sepval_diagnose::Diagnosis, dir: &Path) -> Result<Source, SourceError> {
        let file = "diagnosis.json";
        let bad = |message: String| SourceError::File {
            path: dir.to_path_buf(),
            file,
            message,
        };
        let identifiability = d.identifiability.clone().ok_or_else(|| {
            bad("records no covariance of the answer's parameters (`identifiability`, written by sepval since predict): diagnose again with this sepval".into())
        })?;
        some_determined(&identifiability).map_err(|reason| SourceError::Undetermined {
            path: dir.to_path_buf(),
            file,
            reason,
        })?;
        let mut models = vec![SourceModel {
            spec: d.model.clone(),
            delta_bic: 0.0,
        }];
        models.extend(d.rivals.iter().map(|r| SourceModel {
            spec: r.model.clone(),
            delta_bic: r.delta_bic,
        }));
        let held_out = d
            .validation
            .iter()
            .map(|v| PathBuf::from(&v.event))
            .filter(|p| p.is_file())
            .collect();
        Ok(Source {
            kind: SourceKind::Diagnosis,
            dir: dir.to_path_buf(),
            models,
            identifiability,
            noise: Noise {
                pos_m: d.sigma_pos_m,
                att_deg: d.sigma_att_deg,
            },
            inputs: d.inputs,
            held_out,
            data_sha256: baseline_data_sha256(dir)?,
        })
    }
}

fn fit_source(dir: &Path) -> Result<Source, SourceError> {
    let file = "result.json";
    let r: FitResult = read(dir, file, "fit result")?;
    let bad = |message: String| SourceError::File {
        path: dir.to_path_buf(),
        file,
        message,
    };
    // The refined methods; the identifiability is that of the best of them.
    let best = r
        .methods
        .values()
        .filter(|m| m.refinement.is_some())
        .min_by(|a, b| a.best.weighted.total_cmp(&b.best.weighted));
    let (Some(identifiability), Some(best)) = (r.identifiability.clone(), best) else {
        let methods: Vec<&str> = r.methods.keys().map(String::as_str).collect();
        return Err(SourceError::NoCovariance {
            path: dir.to_path_buf(),
            methods: methods.join(", "),
        });
    };
    some_determined(&identifiability).map_err(|reason| SourceError::Undetermined {
        path: dir.to_path_buf(),
        file,
        reason,
    })?;
    let inputs = r.inputs.clone().ok_or_else(|| {
        bad("records no `inputs` (written by an older sepval): fit again with this sepval".into())
    })?;
    Ok(Source {
        kind: SourceKind::Fit,
        dir: dir.to_path_buf(),
        models: vec![SourceModel {
            spec: ModelSpec {
                factors: best.best.factors,
                effects: Vec::new(),
                terms: Vec::new(),
            },
            delta_bic: 0.0,
        }],
        identifiability,
        noise: Noise {
            pos_m: r.sigma_pos_m,
            att_deg: r.sigma_att_deg,
        },
        inputs,
        held_out: Vec::new(),
        data_sha256: Some(r.data_sha256.clone()),
    })
}

/// A `--from` source that cannot be read with its releases.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SourceInputsError {
    /// The source itself.
    #[error(transparent)]
    Source(#[from] SourceError),
    /// The releases it records as fitted no longer read as they did.
    #[error("--from {}: the releases it was fitted to", .from.display())]
    Fitted {
        /// The source directory.
        from: PathBuf,
        /// Why.
        #[source]
        source: Box<InputError>,
    },
    /// A release held out (given, or recorded by the source) that cannot be read.
    #[error(transparent)]
    HeldOut(Box<InputError>),
    /// The releases it records as fitted read, but not as they were when it was fitted.
    #[error(
        "--from {}: the releases it was fitted to ({}) have changed since (their SHA-256 was {recorded}, now {now}): what it predicts would not be what was fitted; fit again, or restore them",
        .from.display(), .files
    )]
    FittedChanged {
        /// The source directory.
        from: PathBuf,
        /// The release files, comma-separated.
        files: String,
        /// The SHA-256 it records.
        recorded: String,
        /// The SHA-256 of the files now.
        now: String,
    },
}

/// A source with its releases: the releases it was fitted to, and those held out.
pub struct SourceInputs {
    /// The source read and checked.
    pub source: Source,
    /// The releases it was fitted to, read as its fit read them.
    pub fitted: Job,
    /// The releases held out: `validate` (read with its policy), then those the source records.
    pub held_out: Vec<Event>,
}

/// The source of `--from` read and checked, the releases it was fitted to, and the releases
/// held out (`validate`, read with `policy`, then those the source records, read as its fit
/// read its data); `extension` replaces the one it records.
pub fn source_inputs(
    from: &Path,
    extension: Option<&Path>,
    validate: &[PathBuf],
    policy: Policy,
    tell: Tell,
) -> Result<SourceInputs, SourceInputsError> {
    let source = read_source(from)?;
    let record = source.inputs.clone();
    let extension = extension
        .map(Path::to_path_buf)
        .or(record.extension.clone());
    let (fitted, _) = inputs::job(
        &record.data,
        record.scenario.as_deref(),
        extension.as_deref(),
        record.outliers,
        tell,
    )
    .map_err(|source| SourceInputsError::Fitted {
        from: from.to_path_buf(),
        source: Box::new(source),
    })?;
    let changed = source
        .data_sha256
        .as_deref()
        .filter(|&r| r != fitted.data_sha256());
    if let Some(recorded) = changed {
        let files: Vec<String> = record
            .data
            .iter()
            .map(|p| p.display().to_string())
            .collect();
        return Err(SourceInputsError::FittedChanged {
            from: from.to_path_buf(),
            files: if files.is_empty() {
                "the embedded flight test".into()
            } else {
                files.join(", ")
            },
            recorded: recorded.to_string(),
            now: fitted.data_sha256().to_string(),
        });
    }
    let mut held = inputs::with_policy(validate, policy);
    let recorded = source
        .held_out
        .iter()
        .filter(|p| !validate.contains(p))
        .map(|p| (p.clone(), record.outliers));
    held.extend(recorded.collect::<Vec<_>>());
    let held_out = inputs::HeldOut {
        held: &held,
        data_paths: &record.data,
        fitted: &fitted,
        scenario_path: record.scenario.as_deref(),
        extension_path: extension.as_deref(),
    };
    let held_out: Vec<Event> = inputs::validation_job(&held_out, tell)
        .map_err(|e| SourceInputsError::HeldOut(Box::new(e)))?
        .map(|j| j.events().to_vec())
        .unwrap_or_default();
    Ok(SourceInputs {
        source,
        fitted,
        held_out,
    })
}
