//! The evaluation flags as given (`--evaluator`, `--workers`, `--threads`, `--listen`,
//! `--attach`, ...), checked into the [`EvaluatorSpec`] they ask for before anything starts:
//! the one place that knows which flag goes with which transport.

use std::path::PathBuf;
use std::time::Duration;

use sepval_core::flag_value::{FlagError, count, seconds};

use crate::RunId;
use crate::dispatch::DispatchOptions;
use crate::ipc::{IpcOptions, Launch, MAX_WORKERS};
use crate::spec::EvaluatorSpec;

/// Which transport `--evaluator` names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Threads of this process.
    InProcess,
    /// Worker processes over iceoryx2 shared memory.
    Ipc,
    /// Workers on any host that joins, over zenoh.
    Zenoh,
}

/// The evaluation flags as given.
#[derive(Debug, Clone)]
pub struct EvaluatorFlags {
    /// `--evaluator`.
    pub kind: Kind,
    /// `--workers`.
    pub workers: Option<usize>,
    /// `--threads`.
    pub threads: Option<usize>,
    /// `--listen` (zenoh).
    pub listen: Option<String>,
    /// `--zenoh-config` (zenoh).
    pub zenoh_config: Option<PathBuf>,
    /// `--attach` (ipc).
    pub attach: Option<RunId>,
    /// `--run-id`.
    pub run_id: Option<RunId>,
    /// `--worker-timeout` \[s\].
    pub worker_timeout_s: f64,
    /// `--join-timeout` \[s\].
    pub join_timeout_s: f64,
    /// The protocol version announced (compatibility testing only).
    pub announce_protocol: Option<u32>,
}

/// Evaluation flags that do not go together, or whose values are refused.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FlagsError {
    /// A value refused.
    #[error(transparent)]
    Value(#[from] FlagError),
    /// `--listen` or `--zenoh-config` without `--evaluator zenoh`.
    #[error("--listen and --zenoh-config are for --evaluator zenoh")]
    ZenohFlags,
    /// `--evaluator zenoh` without `--listen`.
    #[error("--evaluator zenoh needs --listen ENDPOINT (e.g. tcp/0.0.0.0:7447)")]
    NoListen,
    /// `--attach` with `--evaluator zenoh`.
    #[error("--attach is for --evaluator ipc; zenoh workers always join by themselves")]
    AttachZenoh,
    /// `--evaluator zenoh` in a build without the zenoh transport.
    #[error(
        "--evaluator zenoh: this sepval was built without the zenoh transport; rebuild with `cargo build --release --features zenoh`"
    )]
    NoZenoh,
    /// `--attach` for a command that evaluates several jobs.
    #[error(
        "--attach {run}: workers attached by hand serve one job of a run, and `{command}` runs {jobs}; leave out --attach (sepval starts the iceoryx2 workers of each job) or use --evaluator zenoh, whose workers serve every job of the run"
    )]
    AttachSeveralJobs {
        /// The run id given to `--attach`.
        run: RunId,
        /// The command.
        command: String,
        /// The jobs it runs ("one per condition").
        jobs: String,
    },
    /// The worker executable, which iceoryx2 workers are spawned from, cannot be found: the
    /// caller's error (the front end finds the executable), shown with its causes (not a
    /// `source`: the message holds them).
    #[error("{}", crate::error_chain(&**.0))]
    Worker(Box<dyn std::error::Error + Send + Sync>),
    /// `--listen` refused.
    #[error("--listen")]
    Listen(#[source] crate::TransportError),
}

impl EvaluatorFlags {
    /// The evaluator the flags ask for, checked (nothing is started); `worker` finds the worker
    /// executable when workers are to be spawned.
    pub fn spec<E: Into<Box<dyn std::error::Error + Send + Sync>>>(
        &self,
        worker: impl FnOnce() -> Result<PathBuf, E>,
    ) -> Result<EvaluatorSpec, FlagsError> {
        if self.kind != Kind::Zenoh && (self.listen.is_some() || self.zenoh_config.is_some()) {
            return Err(FlagsError::ZenohFlags);
        }
        let chunk_deadline = seconds("--worker-timeout", self.worker_timeout_s)?;
        let join_timeout = seconds("--join-timeout", self.join_timeout_s)?;
        let dispatch = |workers| DispatchOptions {
            min_workers: workers,
            join_timeout,
            chunk_deadline,
        };
        match self.kind {
            Kind::InProcess => Ok(EvaluatorSpec::InProcess {
                threads: count("--threads", self.threads)?,
            }),
            Kind::Ipc => {
                let workers = count("--workers", self.workers)?;
                if workers > MAX_WORKERS {
                    return Err(FlagError::TooMany {
                        flag: "--workers".into(),
                        value: workers,
                        max: MAX_WORKERS,
                    }
                    .into());
                }
                let (run_id, launch) = match &self.attach {
                    Some(id) => (id.clone(), Launch::Attach),
                    None => (
                        self.run_id.clone().unwrap_or_else(RunId::fresh),
                        Launch::Spawn {
                            executable: worker().map_err(|e| FlagsError::Worker(e.into()))?,
                        },
                    ),
                };
                Ok(EvaluatorSpec::Ipc {
                    link: IpcOptions {
                        run_id,
                        workers,
                        launch,
                        max_respawns: 2 * workers + 2,
                        join_timeout,
                        announce_protocol: self.announce_protocol,
                    },
                    dispatch: dispatch(workers),
                })
            }
            Kind::Zenoh => self.zenoh(join_timeout, dispatch),
        }
    }

    #[cfg(feature = "zenoh")]
    fn zenoh(
        &self,
        join_timeout: Duration,
        dispatch: impl Fn(usize) -> DispatchOptions,
    ) -> Result<EvaluatorSpec, FlagsError> {
        use crate::zenoh::{ZenohOptions, validate_endpoint};
        use sepval_core::flag_value::count_or;
        let listen = self.listen.clone().ok_or(FlagsError::NoListen)?;
        validate_endpoint(&listen).map_err(FlagsError::Listen)?;
        if self.attach.is_some() {
            return Err(FlagsError::AttachZenoh);
        }
        let workers = count_or("--workers", self.workers, 1)?;
        Ok(EvaluatorSpec::Zenoh {
            link: ZenohOptions {
                run_id: self.run_id.clone().unwrap_or_else(RunId::fresh),
                listen,
                workers,
                join_timeout,
                zenoh_config: self.zenoh_config.clone(),
                announce_protocol: self.announce_protocol,
            },
            dispatch: dispatch(workers),
        })
    }

    #[cfg(not(feature = "zenoh"))]
    fn zenoh(
        &self,
        _: Duration,
        _: impl Fn(usize) -> DispatchOptions,
    ) -> Result<EvaluatorSpec, FlagsError> {
        Err(FlagsError::NoZenoh)
    }

    /// Refuses `--attach` for `command`, which evaluates several jobs one after another (an
    /// envelope's conditions, an update's rounds): iceoryx2 workers attached by hand serve one
    /// job and leave with it, so the next would wait for workers that never come back.
    pub fn several_jobs(&self, command: &str, jobs: &str) -> Result<(), FlagsError> {
        match &self.attach {
            Some(run) => Err(FlagsError::AttachSeveralJobs {
                run: run.clone(),
                command: command.to_string(),
                jobs: jobs.to_string(),
            }),
            None => Ok(()),
        }
    }
}
