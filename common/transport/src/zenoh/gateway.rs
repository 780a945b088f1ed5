//! The gateway of a host: one zenoh worker that serves its chunks with the host's iceoryx2
//! workers, so the zero-copy path is kept within the host and the zenoh traffic is one session
//! per host. It holds two chunks per local worker and evaluates one chunk per local worker at a
//! time as one batch (spread over its workers by the dispatcher), so the next chunks are
//! already here when a batch ends.

use std::sync::Arc;

use sepval_common::evaluation::{Evaluator, Job};

use crate::TransportError;
use crate::dispatch::Dispatcher;
use crate::ipc::IpcLink;
use crate::serve::Server;
use crate::wire::{Answer, Chunk, serve_chunks};

/// A [`Server`] over a host's iceoryx2 workers.
pub struct Gateway {
    local: Dispatcher<IpcLink>,
    job: Arc<Job>,
    workers: usize,
}

impl Gateway {
    /// A gateway over `local`, a dispatcher of `workers` local iceoryx2 workers for `job`.
    pub fn new(local: Dispatcher<IpcLink>, job: Arc<Job>, workers: usize) -> Self {
        Gateway {
            local,
            job,
            workers,
        }
    }
}

impl Server for Gateway {
    fn credits(&self) -> u32 {
        (2 * self.workers).clamp(1, 64) as u32
    }

    fn parallelism(&self) -> usize {
        self.workers
    }

    fn serve(&mut self, chunks: &[Chunk]) -> Result<Vec<Answer>, TransportError> {
        serve_chunks(&self.job, chunks, |batch, with_samples| {
            self.local.evaluate(batch, with_samples).map_err(|e| {
                TransportError::Serve(format!(
                    "the host's iceoryx2 workers failed: {}",
                    crate::error_chain(&e)
                ))
            })
        })
    }
}
