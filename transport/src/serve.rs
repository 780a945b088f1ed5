//! A worker's serve loop, written once for every transport: receive chunks from a
//! [`WorkerLink`], have a [`Server`] evaluate them, answer. A worker process serves with
//! [`Local`] (its own simulations); a gateway serves a zenoh run with a host's iceoryx2 workers
//! (a [`Server`] over a dispatcher).
//!
//! Chunks that arrive while others are served wait in a queue; a server of parallelism `p`
//! takes up to `p` queued chunks (of one kind: with or without samples) as one batch, so a
//! gateway keeps every local worker busy while the next chunks wait on the host.

use std::collections::VecDeque;
use std::sync::Arc;
use std::time::Duration;

use sepval_common::evaluation::Job;

use crate::TransportError;
use crate::link::{Incoming, Stopped, WorkerLink};
use crate::wire::{Answer, Chunk, serve_locally};

/// How long an idle worker waits for a chunk before looking around again (signals,
/// its coordinator's liveness are checked by the link at least this often).
const IDLE_WAIT: Duration = Duration::from_millis(500);

/// Evaluates the chunks a worker receives.
pub trait Server {
    /// Chunks it can hold at once (its credits with the coordinator).
    fn credits(&self) -> u32 {
        2
    }

    /// Chunks evaluated together as one batch.
    fn parallelism(&self) -> usize {
        1
    }

    /// Answers `chunks`, one answer per chunk in order.
    fn serve(&mut self, chunks: &[Chunk]) -> Result<Vec<Answer>, TransportError>;

    /// Serves `job` from now on: the coordinator moved on to the next job of the same run.
    fn next_job(&mut self, job: Arc<Job>) -> Result<(), TransportError>;
}

/// The plain worker: simulates each candidate itself.
pub struct Local(pub Arc<Job>);

impl Server for Local {
    fn serve(&mut self, chunks: &[Chunk]) -> Result<Vec<Answer>, TransportError> {
        Ok(chunks.iter().map(|c| serve_locally(&self.0, c)).collect())
    }

    fn next_job(&mut self, job: Arc<Job>) -> Result<(), TransportError> {
        self.0 = job;
        Ok(())
    }
}

/// Serves chunks from `link` with `server` until the coordinator ends the run, goes away, or a
/// signal asks this process to stop; when the coordinator moves on to the next job of the run,
/// the server takes it and the worker says it is ready again, so a worker that joined a run
/// serves it until the coordinator's command ends.
pub fn serve(
    link: &mut dyn WorkerLink,
    server: &mut dyn Server,
) -> Result<Stopped, TransportError> {
    let mut queue: VecDeque<Chunk> = VecDeque::new();
    link.ready(server.credits())?;
    loop {
        // Take everything already here; block only when there is nothing to do.
        let timeout = if queue.is_empty() {
            IDLE_WAIT
        } else {
            Duration::ZERO
        };
        match link.receive(timeout)? {
            Incoming::Chunk(c) => {
                queue.push_back(c);
                continue;
            }
            Incoming::Stop(s) => return Ok(s),
            Incoming::Job(job) => {
                // The coordinator moves on only when every chunk of the last job is answered
                // or given to another worker: what is still queued belongs to that job.
                queue.clear();
                server.next_job(job)?;
                link.ready(server.credits())?;
                continue;
            }
            Incoming::Idle => {}
        }
        let Some(kind) = queue.front().map(|c| c.header.with_samples) else {
            continue;
        };
        let mut group = Vec::new();
        while group.len() < server.parallelism().max(1)
            && queue.front().is_some_and(|c| c.header.with_samples == kind)
        {
            group.extend(queue.pop_front());
        }
        let answers = server.serve(&group)?;
        if answers.len() != group.len() {
            return Err(TransportError::ServedCount {
                answers: answers.len(),
                chunks: group.len(),
            });
        }
        for a in &answers {
            link.answer(a)?;
        }
    }
}
