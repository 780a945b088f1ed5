//! Which evaluator runs the simulations, as a validated configuration: the command line (or a
//! benchmark) decides, [`EvaluatorSpec::start`] builds it. The one place evaluators are built.

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
