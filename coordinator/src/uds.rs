//! The Unix-domain-socket evaluator: the conventional alternative to shared memory, measured by
//! `sepval bench` beside the iceoryx2 transport. Same worker executable (`--uds PATH`), same
//! chunking and in-flight policy, but every request and response is serialised (postcard) and
//! copied through the kernel.

use std::os::unix::net::{UnixListener, UnixStream};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crossbeam::channel::{Receiver, RecvTimeoutError, unbounded};
use sepval_common::evaluation::{Candidate, EvalError, Evaluation, Evaluator, Job};
use sepval_common::messages::encode_setup;
use sepval_common::uds::{self, FromWorker, ToWorker, read_frame, write_frame};

use crate::ipc::{IN_FLIGHT_PER_WORKER, chunk_plan};

fn transport(e: impl std::fmt::Display) -> EvalError {
    EvalError::Transport(e.to_string())
}

/// The socket evaluator.
pub struct UdsEvaluator {
    job: Arc<Job>,
    streams: Vec<UnixStream>,
    children: Vec<Child>,
    responses: Receiver<(usize, Result<FromWorker, String>)>,
    deadline: Duration,
    _dir: tempfile::TempDir,
    next_chunk: u64,
}

impl UdsEvaluator {
    /// Spawns `workers` worker processes connected over a socket in a fresh temporary directory.
    pub fn start(
        job: Arc<Job>,
        workers: usize,
        executable: &std::path::Path,
        deadline: Duration,
    ) -> Result<Self, EvalError> {
        let dir = tempfile::tempdir().map_err(transport)?;
        let path: PathBuf = dir.path().join("sepval.sock");
        let listener = UnixListener::bind(&path).map_err(transport)?;
        listener.set_nonblocking(true).map_err(transport)?;
        let mut children = Vec::new();
        for _ in 0..workers {
            children.push(
                Command::new(executable)
                    .arg("--uds")
                    .arg(&path)
                    .stdin(Stdio::null())
                    .stdout(Stdio::null())
                    .spawn()
                    .map_err(|e| {
                        transport(format!("cannot start {}: {e}", executable.display()))
                    })?,
            );
        }
        let (header, bytes) = encode_setup(&job);
        let setup = ToWorker::Setup {
            protocol: header.protocol,
            sha256: header.sha256,
            catalogue: header.catalogue,
            bytes,
        };
        let mut streams = Vec::new();
        let until = Instant::now() + deadline;
        while streams.len() < workers {
            match listener.accept() {
                Ok((mut s, _)) => {
                    s.set_nonblocking(false).map_err(transport)?;
                    write_frame(&mut s, &setup).map_err(transport)?;
                    streams.push(s);
                }
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    if Instant::now() > until {
                        return Err(transport("socket workers did not connect in time"));
                    }
                    std::thread::sleep(Duration::from_millis(2));
                }
                Err(e) => return Err(transport(e)),
            }
        }
        let (tx, rx) = unbounded();
        for (w, s) in streams.iter().enumerate() {
            let mut reader = s.try_clone().map_err(transport)?;
            let tx = tx.clone();
            std::thread::spawn(move || {
                loop {
                    let r = read_frame::<FromWorker>(&mut reader).map_err(|e| e.to_string());
                    let stop = r.is_err();
                    if tx.send((w, r)).is_err() || stop {
                        break;
                    }
                }
            });
        }
        Ok(UdsEvaluator {
            job,
            streams,
            children,
            responses: rx,
            deadline,
            _dir: dir,
            next_chunk: 0,
        })
    }
}

impl Evaluator for UdsEvaluator {
    fn evaluate(
        &mut self,
        batch: &[Candidate],
        with_samples: bool,
    ) -> Result<Vec<Evaluation>, EvalError> {
        let n = batch.len();
        let workers = self.streams.len();
        let mut pending = chunk_plan(n, workers);
        let mut in_flight: Vec<Vec<(u64, Vec<usize>)>> = vec![Vec::new(); workers];
        let mut results: Vec<Option<Evaluation>> = vec![None; n];
        let mut done = 0;
        while done < n {
            for (w, flight) in in_flight.iter_mut().enumerate() {
                while flight.len() < IN_FLIGHT_PER_WORKER {
                    let Some(indices) = pending.pop_front() else {
                        break;
                    };
                    let chunk_id = self.next_chunk;
                    self.next_chunk += 1;
                    let frame = ToWorker::Chunk {
                        chunk_id,
                        with_samples,
                        items: indices
                            .iter()
                            .map(|&i| uds::item(i as u64, &batch[i]))
                            .collect(),
                    };
                    write_frame(&mut self.streams[w], &frame).map_err(transport)?;
                    flight.push((chunk_id, indices));
                }
            }
            let (w, frame) = match self.responses.recv_timeout(self.deadline) {
                Ok(r) => r,
                Err(RecvTimeoutError::Timeout) => {
                    return Err(transport("no socket worker answered in time"));
                }
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(transport("socket workers gone"));
                }
            };
            let frame = frame.map_err(|e| transport(format!("socket worker {w}: {e}")))?;
            let pos = in_flight[w]
                .iter()
                .position(|(id, _)| *id == frame.chunk_id)
                .ok_or_else(|| transport("a socket worker answered an unknown chunk"))?;
            let (_, indices) = in_flight[w].remove(pos);
            if frame.items.len() != indices.len() {
                return Err(transport("a socket worker answered a partial chunk"));
            }
            for ((index, outcome, samples), &expected) in frame.items.into_iter().zip(&indices) {
                if index as usize != expected {
                    return Err(transport("a socket worker answered out of order"));
                }
                results[expected] = Some(Evaluation {
                    outcome: outcome.into(),
                    samples: samples.map(uds::samples_in),
                });
                done += 1;
            }
        }
        Ok(results
            .into_iter()
            .map(|r| r.expect("every candidate answered"))
            .collect())
    }

    fn job(&self) -> &Job {
        &self.job
    }

    fn describe(&self) -> String {
        format!("uds, {} worker(s)", self.streams.len())
    }
}

impl Drop for UdsEvaluator {
    fn drop(&mut self) {
        // Closing the sockets ends the workers (end of file).
        for s in &self.streams {
            let _ = s.shutdown(std::net::Shutdown::Both);
        }
        self.streams.clear();
        let until = Instant::now() + Duration::from_secs(2);
        for c in self.children.iter_mut() {
            while matches!(c.try_wait(), Ok(None)) && Instant::now() < until {
                std::thread::sleep(Duration::from_millis(2));
            }
            if matches!(c.try_wait(), Ok(None)) {
                let _ = c.kill();
            }
            let _ = c.wait();
        }
    }
}
