//! The coordinator's dispatcher: one batch of candidates over any [`Link`], written once.
//!
//! A batch is cut into chunks of consecutive candidates ([`chunk_plan`]); each worker holds at
//! most its credits' worth of chunks (so it never waits for the coordinator, and a fast worker
//! takes more chunks than a slow one); answers are placed by candidate index, so the result is
//! the same bit for bit whichever worker ran what, and whatever the worker count. A worker that
//! is lost (its link says so) or that holds a chunk past the deadline (it is then stopped) has
//! its chunks re-dispatched to the others, so a batch completes with exactly one evaluation
//! per candidate; with no worker left and none able to come, the batch fails with an error
//! instead of hanging. The dispatcher is an [`Evaluator`]: the searches cannot tell it from the
//! in-process thread pool.

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::sync::Arc;
use std::time::{Duration, Instant};

use sepval_common::evaluation::{Candidate, EvalError, Evaluation, Evaluator, Job};
use sepval_common::propagator::LANES;

use crate::TransportError;
use crate::link::{Link, LinkEvent, NextJob, Notice, Notices, WorkerId};
use crate::wire::Chunk;

/// How often the dispatcher checks deadlines while it waits.
const TICK: Duration = Duration::from_millis(50);

/// Splits a batch of `n` candidates into chunks of consecutive indices for `workers` workers:
/// about four chunks per worker, so the last chunks balance the load, a multiple of the lane
/// count ([`LANES`]: a worker runs a chunk four candidates at a time), and at most 16 candidates
/// per chunk, so a lost worker costs little. The same plan for every transport, so `sepval
/// bench` compares transports, not chunkings.
pub fn chunk_plan(n: usize, workers: usize) -> VecDeque<Vec<usize>> {
    let chunk = n
        .div_ceil(workers.max(1) * 4)
        .next_multiple_of(LANES)
        .clamp(LANES, 16);
    (0..n)
        .collect::<Vec<_>>()
        .chunks(chunk)
        .map(<[usize]>::to_vec)
        .collect()
}

/// Settings of a dispatcher.
#[derive(Debug, Clone)]
pub struct DispatchOptions {
    /// Workers to wait for before the first batch.
    pub min_workers: usize,
    /// How long to wait for them.
    pub join_timeout: Duration,
    /// A worker that answers nothing for this long while it holds chunks is considered hung.
    pub chunk_deadline: Duration,
}

/// What happened to the workers, for reports.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DispatchStats {
    /// Workers lost, with the reason.
    pub lost: Vec<String>,
    /// Evaluations re-dispatched after a loss.
    pub redispatched: u64,
}

struct InFlight {
    chunk_id: u64,
    indices: Vec<usize>,
    sent: Instant,
}

struct Worker {
    label: String,
    credits: usize,
    in_flight: VecDeque<InFlight>,
    /// When it last answered (a worker is hung when it answers nothing for the deadline).
    answered: Instant,
}

/// An [`Evaluator`] that sends chunks over a [`Link`].
pub struct Dispatcher<L: Link> {
    link: L,
    job: Arc<Job>,
    options: DispatchOptions,
    notices: Notices,
    workers: BTreeMap<WorkerId, Worker>,
    next_chunk: u64,
    stats: DispatchStats,
}

impl<L: Link> Dispatcher<L> {
    /// Waits until `options.min_workers` workers have joined over `link`.
    pub fn start(
        link: L,
        job: Arc<Job>,
        options: DispatchOptions,
        notices: Notices,
    ) -> Result<Self, TransportError> {
        let mut d = Dispatcher {
            link,
            job,
            options,
            notices,
            workers: BTreeMap::new(),
            next_chunk: 0,
            stats: DispatchStats::default(),
        };
        d.wait_for_workers(d.options.min_workers, d.options.join_timeout)?;
        Ok(d)
    }

    /// The link.
    pub fn link(&self) -> &L {
        &self.link
    }

    /// The link, mutably.
    pub fn link_mut(&mut self) -> &mut L {
        &mut self.link
    }

    /// What happened to the workers so far.
    pub fn stats(&self) -> &DispatchStats {
        &self.stats
    }

    /// Workers serving now.
    pub fn worker_count(&self) -> usize {
        self.workers.len()
    }

    fn wait_for_workers(&mut self, n: usize, timeout: Duration) -> Result<(), TransportError> {
        let deadline = Instant::now() + timeout;
        let mut events = Vec::new();
        while self.workers.len() < n {
            let now = Instant::now();
            if now >= deadline {
                return Err(TransportError::TooFewWorkers {
                    joined: self.workers.len(),
                    wanted: n,
                    run: self.link.run_id().to_string(),
                    seconds: timeout.as_secs_f64(),
                });
            }
            self.link.poll((deadline - now).min(TICK), &mut events)?;
            for e in events.drain(..) {
                self.handle(e, &mut VecDeque::new(), &mut []);
            }
        }
        Ok(())
    }

    /// Waits until every worker in `told` has joined again or is gone, and one at least serves,
    /// within the join timeout (after it, those that joined go on alone).
    fn wait_for_rejoin(&mut self, told: Vec<WorkerId>) -> Result<(), TransportError> {
        if told.is_empty() {
            return self.wait_for_workers(self.options.min_workers, self.options.join_timeout);
        }
        let wanted = told.len();
        let mut awaiting: BTreeSet<WorkerId> = told.into_iter().collect();
        let deadline = Instant::now() + self.options.join_timeout;
        let mut events = Vec::new();
        while !awaiting.is_empty() || self.workers.is_empty() {
            let now = Instant::now();
            if now >= deadline {
                if self.workers.is_empty() {
                    return Err(TransportError::TooFewWorkers {
                        joined: 0,
                        wanted,
                        run: self.link.run_id().to_string(),
                        seconds: self.options.join_timeout.as_secs_f64(),
                    });
                }
                break;
            }
            self.link.poll((deadline - now).min(TICK), &mut events)?;
            for e in events.drain(..) {
                if let LinkEvent::Joined { worker, .. } | LinkEvent::Lost { worker, .. } = &e {
                    awaiting.remove(worker);
                }
                self.handle(e, &mut VecDeque::new(), &mut []);
            }
        }
        Ok(())
    }

    /// Handles one event; returns the number of evaluations it completed.
    fn handle(
        &mut self,
        event: LinkEvent,
        pending: &mut VecDeque<Vec<usize>>,
        results: &mut [Option<Evaluation>],
    ) -> usize {
        match event {
            LinkEvent::Joined {
                worker,
                label,
                credits,
            } => {
                (self.notices)(Notice::Joined {
                    label: label.clone(),
                    credits,
                });
                if let Some(old) = self.workers.remove(&worker) {
                    self.requeue(old, "it announced itself again", pending);
                }
                self.workers.insert(
                    worker,
                    Worker {
                        label,
                        credits: credits.clamp(1, 64),
                        in_flight: VecDeque::new(),
                        answered: Instant::now(),
                    },
                );
                0
            }
            LinkEvent::Lost { worker, reason } => {
                if let Some(w) = self.workers.remove(&worker) {
                    self.requeue(w, &reason, pending);
                }
                0
            }
            LinkEvent::Notice(n) => {
                (self.notices)(n);
                0
            }
            LinkEvent::Answer { worker, answer } => {
                let Some(w) = self.workers.get_mut(&worker) else {
                    return 0; // a worker already given up on
                };
                let Some(pos) = w
                    .in_flight
                    .iter()
                    .position(|c| c.chunk_id == answer.header.chunk_id)
                else {
                    return 0; // a chunk already given to another worker
                };
                w.answered = Instant::now();
                let chunk = w.in_flight.remove(pos).expect("position is valid");
                // Chunk ids are never reused, so a chunk in flight belongs to this batch.
                let placed = match answer.evaluations(&chunk.indices, &self.job) {
                    Ok(e) => e,
                    Err(why) => {
                        w.in_flight.push_front(chunk);
                        let why = format!("it answered a chunk with the wrong candidates: {why}");
                        self.give_up(worker, &why, pending);
                        return 0;
                    }
                };
                let n = placed.len();
                for (i, e) in placed {
                    results[i] = Some(e);
                }
                n
            }
        }
    }

    /// Stops a worker that misbehaves and re-dispatches its work.
    fn give_up(&mut self, worker: WorkerId, why: &str, pending: &mut VecDeque<Vec<usize>>) {
        let action = self.link.drop_worker(worker, why);
        if let Some(w) = self.workers.remove(&worker) {
            let reason = format!("{why} ({action})");
            self.requeue(w, &reason, pending);
        }
    }

    fn requeue(&mut self, w: Worker, reason: &str, pending: &mut VecDeque<Vec<usize>>) {
        let n: usize = w.in_flight.iter().map(|c| c.indices.len()).sum();
        for c in w.in_flight.into_iter().rev() {
            pending.push_front(c.indices);
        }
        self.stats.redispatched += n as u64;
        self.stats.lost.push(format!("{}: {reason}", w.label));
        (self.notices)(Notice::Lost {
            label: w.label,
            reason: reason.to_string(),
            redispatched: n,
        });
    }

    /// Sends pending chunks to workers with free credit, one each in turn.
    fn fill(
        &mut self,
        pending: &mut VecDeque<Vec<usize>>,
        batch: &[Candidate],
        with_samples: bool,
    ) {
        let mut failed = Vec::new();
        let mut progress = true;
        while progress && !pending.is_empty() {
            progress = false;
            for (&id, w) in self.workers.iter_mut() {
                if w.in_flight.len() >= w.credits || failed.iter().any(|(f, _)| *f == id) {
                    continue;
                }
                let Some(indices) = pending.pop_front() else {
                    break;
                };
                let chunk_id = self.next_chunk;
                self.next_chunk += 1;
                let chunk = Chunk::new(chunk_id, &indices, batch, with_samples);
                if w.in_flight.is_empty() {
                    w.answered = Instant::now();
                }
                w.in_flight.push_back(InFlight {
                    chunk_id,
                    indices,
                    sent: Instant::now(),
                });
                if let Err(e) = self.link.send(id, &chunk) {
                    failed.push((id, e));
                }
                progress = true;
            }
        }
        for (id, e) in failed {
            self.give_up(id, &format!("sending failed: {e}"), pending);
        }
    }

    /// Drops every worker that holds chunks and has answered nothing for the deadline.
    fn check_deadlines(&mut self, pending: &mut VecDeque<Vec<usize>>) {
        let deadline = self.options.chunk_deadline;
        let late: Vec<WorkerId> = self
            .workers
            .iter()
            .filter(|(_, w)| {
                w.in_flight
                    .front()
                    .is_some_and(|c| c.sent.max(w.answered).elapsed() > deadline)
            })
            .map(|(&id, _)| id)
            .collect();
        for id in late {
            let why = format!(
                "it held a chunk longer than {} s (hung",
                deadline.as_secs_f64()
            );
            let action = self.link.drop_worker(id, &why);
            if let Some(w) = self.workers.remove(&id) {
                self.requeue(w, &format!("{why}, {action})"), pending);
            }
        }
    }

    fn run_batch(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, TransportError> {
        let n = batch.len();
        let mut results: Vec<Option<Evaluation>> = vec![None; n];
        let mut pending = chunk_plan(n, self.workers.len());
        let mut done = 0;
        let mut workerless_since: Option<Instant> = None;
        let mut events = Vec::new();
        while done < n {
            self.fill(&mut pending, batch, with_samples);
            self.check_deadlines(&mut pending);
            if self.workers.is_empty() {
                let since = *workerless_since.get_or_insert_with(Instant::now);
                if since.elapsed() >= self.link.replacement_wait() {
                    return Err(TransportError::AllLost {
                        run: self.link.run_id().to_string(),
                        lost: self.stats.lost.join("; "),
                        unfinished: n - done,
                        total: n,
                    });
                }
            } else {
                workerless_since = None;
            }
            self.link.poll(TICK, &mut events)?;
            for e in events.drain(..) {
                done += self.handle(e, &mut pending, &mut results);
            }
        }
        Ok(results
            .into_iter()
            .map(|r| r.expect("every candidate has exactly one result"))
            .collect())
    }
}

impl<L: NextJob> Dispatcher<L> {
    /// Moves the workers that joined on to `job` (the next job of the same run), telling
    /// `notices` from now on, and waits until they serve it (or, if none is left, for
    /// `min_workers` new ones), within the join timeout. Chunk ids go on from the last job's,
    /// so no answer to a chunk of it can be taken for one of this job's.
    pub fn next_job(&mut self, job: Arc<Job>, notices: Notices) -> Result<(), TransportError> {
        let told = self.link.next_job(&job)?;
        self.job = job;
        self.notices = notices;
        self.workers.clear();
        self.wait_for_rejoin(told)
    }
}

impl<L: Link> Evaluator for Dispatcher<L> {
    fn evaluate(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, EvalError> {
        self.run_batch(batch, with_samples).map_err(EvalError::from)
    }

    fn job(&self) -> &Arc<Job> {
        &self.job
    }

    fn describe(&self) -> String {
        format!(
            "{}, {} worker(s), run {}",
            self.link.describe(),
            self.workers.len(),
            self.link.run_id()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chunk_plan_covers_every_index_once_in_order() {
        for (n, w) in [(0, 1), (1, 1), (100, 2), (18, 4), (1000, 3)] {
            let plan = chunk_plan(n, w);
            let flat: Vec<usize> = plan.iter().flatten().copied().collect();
            assert_eq!(flat, (0..n).collect::<Vec<_>>());
            assert!(plan.iter().all(|c| !c.is_empty() && c.len() <= 16));
            // Every chunk but the last fills whole lane batches.
            let whole = plan.len().saturating_sub(1);
            assert!(
                plan.iter().take(whole).all(|c| c.len() % LANES == 0),
                "{n} {w}"
            );
        }
    }
}
