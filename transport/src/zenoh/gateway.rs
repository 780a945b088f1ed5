//! The gateway of a host: one zenoh worker that serves its chunks with the host's iceoryx2
//! workers, so the zero-copy path is kept within the host and the zenoh traffic is one session
//! per host. It holds two chunks per local worker and evaluates one chunk per local worker at a
//! time as one batch (spread over its workers by the dispatcher), so the next chunks are
//! already here when a batch ends. For the next job of the run, its local workers are started
//! anew for that job (as an iceoryx2 coordinator does for each of its jobs).

use std::sync::Arc;

use sepval_common::evaluation::{Evaluator, Job};

use crate::TransportError;
use crate::dispatch::{DispatchOptions, Dispatcher};
use crate::ipc::{IpcLink, IpcOptions};
use crate::link::Notices;
use crate::serve::Server;
use crate::wire::{Answer, Chunk, serve_chunks};

/// A [`Server`] over a host's iceoryx2 workers.
pub struct Gateway {
    ipc: IpcOptions,
    dispatch: DispatchOptions,
    notices: Notices,
    local: Option<Dispatcher<IpcLink>>,
    job: Arc<Job>,
}

impl Gateway {
    /// A gateway for `job` over the local iceoryx2 workers of `ipc`, started now and dispatched
    /// to with `dispatch`; their notices go to `notices`.
    pub fn start(
        ipc: IpcOptions,
        dispatch: DispatchOptions,
        job: Arc<Job>,
        notices: Notices,
    ) -> Result<Self, TransportError> {
        let mut gateway = Gateway {
            ipc,
            dispatch,
            notices,
            local: None,
            job: Arc::clone(&job),
        };
        gateway.next_job(job)?;
        Ok(gateway)
    }
}

impl Server for Gateway {
    fn credits(&self) -> u32 {
        (2 * self.ipc.workers).clamp(1, 64) as u32
    }

    fn parallelism(&self) -> usize {
        self.ipc.workers
    }

    fn serve(&mut self, chunks: &[Chunk]) -> Result<Vec<Answer>, TransportError> {
        let local = self.local.as_mut().ok_or(TransportError::LocalGone)?;
        serve_chunks(&self.job, chunks, |batch, with_samples| {
            local
                .evaluate(batch, with_samples)
                .map_err(|e| TransportError::LocalFailed { cause: Box::new(e) })
        })
    }

    fn next_job(&mut self, job: Arc<Job>) -> Result<(), TransportError> {
        // One iceoryx2 coordinator per run at a time: the last job's goes first.
        self.local = None;
        let link = IpcLink::start(&job, self.ipc.clone())?;
        let local = Dispatcher::start(
            link,
            Arc::clone(&job),
            self.dispatch.clone(),
            Arc::clone(&self.notices),
        )?;
        self.local = Some(local);
        self.job = job;
        Ok(())
    }
}
