//! Which evaluator runs the simulations, as a validated configuration: the command line (or a
//! benchmark) decides, [`EvaluatorSpec::start`] builds it. The one place evaluators are built;
//! a command that evaluates several jobs one after another (an envelope's conditions, an
//! update's rounds) starts them with a [`Starter`], which keeps a zenoh run's hosts for all.

use std::sync::Arc;

use sepval_common::evaluation::{Evaluator, InProcess, Job};

use crate::TransportError;
use crate::dispatch::{DispatchOptions, Dispatcher};
use crate::ipc::{IpcLink, IpcOptions};
use crate::link::Notices;

/// An evaluator to start.
#[derive(Debug, Clone)]
pub enum EvaluatorSpec {
    /// Threads of this process.
    InProcess {
        /// Threads (at least one).
        threads: usize,
    },
    /// Worker processes over iceoryx2 shared memory.
    Ipc {
        /// The link.
        link: IpcOptions,
        /// The dispatcher.
        dispatch: DispatchOptions,
    },
    /// Worker processes over Unix sockets (the benchmark's baseline).
    Uds {
        /// Workers to spawn.
        workers: usize,
        /// The worker executable.
        executable: std::path::PathBuf,
        /// The dispatcher.
        dispatch: DispatchOptions,
    },
    /// Workers on any host that joins, over zenoh.
    #[cfg(feature = "zenoh")]
    Zenoh {
        /// The link.
        link: crate::zenoh::ZenohOptions,
        /// The dispatcher.
        dispatch: DispatchOptions,
    },
}

impl EvaluatorSpec {
    /// Starts the evaluator for `job` (workers started and joined); transport notices go to
    /// `notices`.
    pub fn start(
        &self,
        job: Arc<Job>,
        notices: Notices,
    ) -> Result<Box<dyn Evaluator>, TransportError> {
        Ok(match self {
            EvaluatorSpec::InProcess { threads } => Box::new(InProcess::new(job, *threads)),
            EvaluatorSpec::Ipc { link, dispatch } => {
                let link = IpcLink::start(&job, link.clone())?;
                Box::new(Dispatcher::start(link, job, dispatch.clone(), notices)?)
            }
            EvaluatorSpec::Uds {
                workers,
                executable,
                dispatch,
            } => {
                let link = crate::uds::UdsLink::start(&job, *workers, executable)?;
                Box::new(Dispatcher::start(link, job, dispatch.clone(), notices)?)
            }
            #[cfg(feature = "zenoh")]
            EvaluatorSpec::Zenoh { link, dispatch } => {
                crate::zenoh::validate_endpoint(&link.listen)?;
                let link = crate::zenoh::ZenohLink::start(&job, link.clone())?;
                Box::new(Dispatcher::start(link, job, dispatch.clone(), notices)?)
            }
        })
    }
}

/// Starts the evaluators of one command, one job after another (an envelope's conditions, an
/// update's baseline and rounds), at most one alive at a time. In process and over iceoryx2 or
/// Unix sockets each job gets an evaluator of its own (the coordinator spawns its workers for
/// it); over zenoh the link and the hosts that joined it are kept from one job to the next and
/// each next job is announced to them ([`Dispatcher::next_job`]), so that the workers started
/// by hand serve the run until the command ends, when the link tells them it is finished.
pub struct Starter {
    spec: EvaluatorSpec,
    #[cfg(feature = "zenoh")]
    zenoh: Home,
}

/// Where a zenoh run's dispatcher waits between jobs.
#[cfg(feature = "zenoh")]
type Home = Arc<std::sync::Mutex<Option<Dispatcher<crate::zenoh::ZenohLink>>>>;

impl Starter {
    /// A starter of `spec`'s evaluators.
    pub fn new(spec: EvaluatorSpec) -> Starter {
        Starter {
            spec,
            #[cfg(feature = "zenoh")]
            zenoh: Home::default(),
        }
    }

    /// Starts the evaluator of `job`; transport notices go to `notices`.
    pub fn start(
        &mut self,
        job: Arc<Job>,
        notices: Notices,
    ) -> Result<Box<dyn Evaluator>, TransportError> {
        #[cfg(feature = "zenoh")]
        if let EvaluatorSpec::Zenoh { link, dispatch } = &self.spec {
            let parked = self.zenoh.lock().expect("the run's lock").take();
            let dispatcher = match parked {
                Some(mut d) => {
                    d.next_job(job, notices)?;
                    d
                }
                None if Arc::strong_count(&self.zenoh) > 1 => {
                    return Err(TransportError::ZenohRunInUse);
                }
                None => {
                    crate::zenoh::validate_endpoint(&link.listen)?;
                    let link = crate::zenoh::ZenohLink::start(&job, link.clone())?;
                    Dispatcher::start(link, job, dispatch.clone(), notices)?
                }
            };
            return Ok(Box::new(Kept {
                dispatcher: Some(dispatcher),
                home: Arc::clone(&self.zenoh),
            }));
        }
        self.spec.start(job, notices)
    }
}

/// A zenoh run's dispatcher lent to one job: it goes back to its [`Starter`] when dropped.
#[cfg(feature = "zenoh")]
struct Kept {
    dispatcher: Option<Dispatcher<crate::zenoh::ZenohLink>>,
    home: Home,
}

#[cfg(feature = "zenoh")]
impl Kept {
    fn dispatcher(&self) -> &Dispatcher<crate::zenoh::ZenohLink> {
        self.dispatcher.as_ref().expect("lent until dropped")
    }
}

#[cfg(feature = "zenoh")]
impl Evaluator for Kept {
    fn evaluate(
        &mut self,
        batch: &[sepval_common::evaluation::Candidate],
        with_samples: bool,
    ) -> Result<Vec<sepval_common::evaluation::Evaluation>, sepval_common::evaluation::EvalError>
    {
        let d = self.dispatcher.as_mut().expect("lent until dropped");
        d.evaluate(batch, with_samples)
    }

    fn job(&self) -> &Arc<Job> {
        self.dispatcher().job()
    }

    fn describe(&self) -> String {
        self.dispatcher().describe()
    }
}

#[cfg(feature = "zenoh")]
impl Drop for Kept {
    fn drop(&mut self) {
        if let Ok(mut home) = self.home.lock() {
            *home = self.dispatcher.take();
        }
    }
}
