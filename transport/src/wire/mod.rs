//! The wire protocol between a coordinator and its workers, defined once for every transport.
//!
//! Evaluation traffic is chunks: a [`ChunkHeader`] and a slice of fixed-layout, `#[repr(C)]`
//! [`WireRequest`]s one way; the same header, a slice of [`WireResponse`]s and (for residual
//! fits) of [`WireObservation`]s the other way. Over iceoryx2 these slices are the shared-memory
//! samples themselves (zero copy, no serialisation); over byte streams (Unix sockets, zenoh) the
//! same types are written field by field, little-endian ([`crate::codec`]). Either way the
//! values are the same bits, and this module is the one place where a request becomes a
//! candidate ([`WireRequest::candidate`], one validation with one set of messages), where a
//! chunk is evaluated ([`serve_chunks`], used by every worker loop and by the gateway), and where
//! an answer becomes evaluations again ([`Answer::evaluations`]).
//!
//! The layouts of [`Hello`] and [`SetupHeader`] never change, so that a worker and a
//! coordinator of different protocol versions can still read each other's version and refuse
//! with a clear message; every other type may change with [`PROTOCOL_VERSION`]. No type has
//! implicit padding (explicit `reserved` fields instead).

use iceoryx2::prelude::ZeroCopySend;
use sepval_common::correction::{CorrectionValues, MAX_CORRECTION_VALUES};
use sepval_common::effects::{CATALOGUE, EffectSet, MAX_ACTIVE_EFFECTS, MAX_EFFECT_PARAMS};
use sepval_common::evaluation::{Candidate, Evaluation, Job, MAX_REASON_BYTES, Outcome};
use sepval_common::extension::{Axis, MAX_TERMS, Regressor, Term, TermSet};
use sepval_common::propagator::Observation;
use sepval_core::factors::{FACTOR_COUNT, Factors};

/// Version of the coordinator-worker protocol. A coordinator and a worker refuse each other
/// unless they agree on it. Version 2: one wire format for every transport (failure reasons of
/// up to 240 bytes, explicit padding). Version 3: candidates carry extension terms. Version 4:
/// the same messages, but the goals a worker returns are those of sepval's own elementary
/// functions (`sepval_common::elementary`: no C library in the simulation, extension terms
/// included, results changed in their last bits), so a version-3 worker, which computes with the
/// C library, must not serve a version-4 fit whose results are to be bit-identical across hosts.
/// Version 5: the same layout, but a term may name the wind axes (`wind_y`, `wind_z`: axis
/// indices 7 and 8) and the `wind` family's regressors (indices 24 and 25); a version-4 worker
/// would fail such a candidate, which a diagnosis would read as a probe that does not simulate,
/// so the handshake refuses it instead. Version 6: a request carries the values of the
/// scenario's corrections (`sepval update`, docs/update.md) after its terms. Version
/// 7: the same messages, but a zenoh coordinator sends a worker that joined the setup of the
/// run's next job (an envelope's next condition, an update's next round), which the worker
/// accepts and serves, saying `Ready` again; a version-6 worker would take that setup for a
/// protocol error and leave the run after its first job, so the handshake refuses it. Version
/// 8: the same messages, but the simulation locates stroke ends to the last bit (arithmetic
/// version 3, docs/model.md section 3a), so a version-7 worker's results differ in their last
/// bits from a version-8 coordinator's, and the handshake refuses it.
pub const PROTOCOL_VERSION: u32 = 8;

/// "SEPVAL01" as a little-endian integer: the first field of [`Hello`], [`SetupHeader`] and
/// every byte-stream frame.
pub const MAGIC: u64 = u64::from_le_bytes(*b"SEPVAL01");

/// Longest failure reason carried by a [`WireResponse`] \[bytes of UTF-8\]: the same bound as
/// every outcome has where it is made, so no transport ever cuts one.
pub const REASON_CAPACITY: usize = MAX_REASON_BYTES;

/// Most candidates in one chunk (a chunk plan never makes more than 16; a decoder refuses more).
pub const MAX_CHUNK: usize = 1024;

/// A worker announcing itself to an iceoryx2 coordinator (layout fixed across versions).
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[type_name("sepval.Hello")]
#[repr(C)]
pub struct Hello {
    /// [`MAGIC`].
    pub magic: u64,
    /// The worker's [`PROTOCOL_VERSION`].
    pub protocol: u32,
    /// The worker's process id.
    pub pid: u32,
    /// The worker's iceoryx2 node id (which also names its services).
    pub node_id: u128,
}

/// Header of the job setup (layout fixed across protocol versions).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend)]
#[type_name("sepval.SetupHeader")]
#[repr(C)]
pub struct SetupHeader {
    /// [`MAGIC`].
    pub magic: u64,
    /// The coordinator's [`PROTOCOL_VERSION`].
    pub protocol: u32,
    /// Reserved (zero).
    pub reserved: u32,
    /// Length of the setup bytes.
    pub len: u64,
    /// SHA-256 of the setup bytes.
    pub sha256: [u8; 32],
    /// SHA-256 of the effect catalogue's fingerprint text.
    pub catalogue: [u8; 32],
}

/// Header of a chunk of requests or of its answer.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, ZeroCopySend)]
#[type_name("sepval.ChunkHeader")]
#[repr(C)]
pub struct ChunkHeader {
    /// The coordinator's id of the chunk (echoed in the answer).
    pub chunk_id: u64,
    /// Number of items.
    pub count: u32,
    /// 1 when the simulated samples are wanted back.
    pub with_samples: u32,
}

/// One candidate to evaluate.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("sepval.WireRequest")]
#[repr(C)]
pub struct WireRequest {
    /// The candidate's index in its batch (echoed in the response).
    pub index: u64,
    /// The 17 factors in table order.
    pub factors: [f64; FACTOR_COUNT],
    /// Number of active effects.
    pub effect_count: u32,
    /// Catalogue index of each active effect.
    pub effect_index: [u32; MAX_ACTIVE_EFFECTS],
    /// Reserved (zero): keeps the parameters 8-byte aligned without implicit padding.
    pub reserved: u32,
    /// Parameters of each active effect (unused entries zero).
    pub effect_params: [[f64; MAX_EFFECT_PARAMS]; MAX_ACTIVE_EFFECTS],
    /// Number of extension terms.
    pub term_count: u32,
    /// Reserved (zero).
    pub reserved_terms: u32,
    /// The extension terms (unused entries zero).
    pub terms: [WireTerm; MAX_TERMS],
    /// Number of correction values (0: every correction 0).
    pub correction_count: u32,
    /// Reserved (zero).
    pub reserved_corrections: u32,
    /// The values of the scenario's corrections (unused entries zero).
    pub corrections: [f64; MAX_CORRECTION_VALUES],
}

/// One extension term of a candidate (docs/discovery.md).
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[type_name("sepval.WireTerm")]
#[repr(C)]
pub struct WireTerm {
    /// Index of its axis in `Axis::ALL` (7 and 8: the wind axes, since version 5).
    pub axis: u32,
    /// Index of its regressor in `Regressor::ALL`.
    pub regressor: u32,
    /// Its locator pair (a window's `[t0_s, t1_s]`, a wind's `[t_on_s, rise_s]`; others use
    /// the first).
    pub locator: [f64; 2],
    /// Its coefficient.
    pub coefficient: f64,
}

/// Status codes of [`WireResponse`].
pub mod status {
    /// The run finished: `j_pos_m`, `j_att_deg` hold the goals.
    pub const GOALS: u32 = 0;
    /// The run diverged at `t_s` in event `event`.
    pub const DIVERGED: u32 = 1;
    /// The candidate could not be run: `reason`.
    pub const FAILED: u32 = 2;
}

/// One evaluation's outcome.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("sepval.WireResponse")]
#[repr(C)]
pub struct WireResponse {
    /// The candidate's index in its batch.
    pub index: u64,
    /// One of [`status`].
    pub status: u32,
    /// Event index (diverged runs).
    pub event: u32,
    /// RMS position error \[m\].
    pub j_pos_m: f64,
    /// RMS attitude error \[deg\].
    pub j_att_deg: f64,
    /// Divergence time \[s\].
    pub t_s: f64,
    /// Length of `reason` \[bytes\].
    pub reason_len: u32,
    /// Reserved (zero).
    pub reserved: u32,
    /// Failure reason, UTF-8.
    pub reason: [u8; REASON_CAPACITY],
}

/// One simulated sample (residual fits).
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[type_name("sepval.WireObservation")]
#[repr(C)]
pub struct WireObservation {
    /// Position \[m\].
    pub pos_m: [f64; 3],
    /// Euler angles \[deg\].
    pub att_deg: [f64; 3],
}

impl WireObservation {
    /// The sample of a run that did not finish.
    pub const MISSING: WireObservation = WireObservation {
        pos_m: [f64::NAN; 3],
        att_deg: [f64::NAN; 3],
    };
}

impl From<Observation> for WireObservation {
    fn from(o: Observation) -> Self {
        WireObservation {
            pos_m: o.pos_m,
            att_deg: o.att_deg,
        }
    }
}

impl From<WireObservation> for Observation {
    fn from(o: WireObservation) -> Self {
        Observation {
            pos_m: o.pos_m,
            att_deg: o.att_deg,
        }
    }
}

mod error;
pub use error::WireError;

impl WireRequest {
    /// The wire form of candidate `index`.
    pub fn new(index: u64, c: &Candidate) -> Self {
        let mut r = WireRequest {
            index,
            factors: c.factors.0,
            effect_count: c.effects.len() as u32,
            effect_index: [0; MAX_ACTIVE_EFFECTS],
            reserved: 0,
            effect_params: [[0.0; MAX_EFFECT_PARAMS]; MAX_ACTIVE_EFFECTS],
            term_count: c.terms.len() as u32,
            reserved_terms: 0,
            terms: [WireTerm::default(); MAX_TERMS],
            correction_count: c.corrections.len() as u32,
            reserved_corrections: 0,
            corrections: [0.0; MAX_CORRECTION_VALUES],
        };
        r.corrections[..c.corrections.len()].copy_from_slice(c.corrections.as_slice());
        for (k, a) in c.effects.iter().enumerate() {
            r.effect_index[k] = a.index as u32;
            r.effect_params[k][..a.values().len()].copy_from_slice(a.values());
        }
        for (k, t) in c.terms.iter().enumerate() {
            r.terms[k] = WireTerm {
                axis: t.axis.index() as u32,
                regressor: t.regressor as u32,
                locator: t.locator,
                coefficient: t.coefficient,
            };
        }
        r
    }

    /// The candidate, after checking everything that a [`Candidate`] cannot hold (effect
    /// counts, catalogue indices, parameters the catalogue refuses). The factors are checked
    /// when the candidate runs, by the model itself, as in-process candidates are: a factor
    /// that is not finite, or out of its bounds, fails with the same message over every
    /// transport.
    pub fn candidate(&self) -> Result<Candidate, WireError> {
        let n = self.effect_count as usize;
        if n > MAX_ACTIVE_EFFECTS {
            return Err(WireError::EffectCount(self.effect_count));
        }
        let mut effects = EffectSet::NONE;
        for k in 0..n {
            let index = self.effect_index[k];
            let effect = CATALOGUE
                .get(index as usize)
                .ok_or(WireError::EffectIndex(index))?;
            let params = &self.effect_params[k][..effect.params().len()];
            effects
                .push(index as usize, params)
                .map_err(WireError::Effect)?;
        }
        let n = self.term_count as usize;
        if n > MAX_TERMS {
            return Err(WireError::Term {
                index: n,
                reason: format!("term count {n} exceeds the maximum of {MAX_TERMS}"),
            });
        }
        let mut terms = TermSet::NONE;
        for (k, w) in self.terms[..n].iter().enumerate() {
            let bad = |reason: String| WireError::Term { index: k, reason };
            let axis = *Axis::ALL
                .get(w.axis as usize)
                .ok_or_else(|| bad(format!("axis index {} is not an axis", w.axis)))?;
            let regressor = Regressor::ALL
                .get(w.regressor as usize)
                .ok_or_else(|| {
                    bad(format!(
                        "regressor index {} is not a regressor",
                        w.regressor
                    ))
                })?
                .0;
            terms
                .push(Term {
                    axis,
                    regressor,
                    locator: w.locator,
                    coefficient: w.coefficient,
                })
                .map_err(|e| bad(e.to_string()))?;
        }
        let n = self.correction_count as usize;
        if n > MAX_CORRECTION_VALUES {
            return Err(WireError::CorrectionCount(self.correction_count));
        }
        let corrections = CorrectionValues::of(&self.corrections[..n])
            .map_err(|_| WireError::CorrectionCount(self.correction_count))?;
        Ok(Candidate {
            factors: Factors(self.factors),
            effects,
            terms,
            corrections,
        })
    }
}

impl WireResponse {
    /// The wire form of `outcome` for candidate `index`.
    pub fn new(index: u64, outcome: &Outcome) -> Self {
        let mut r = WireResponse {
            index,
            status: status::GOALS,
            event: 0,
            j_pos_m: 0.0,
            j_att_deg: 0.0,
            t_s: 0.0,
            reason_len: 0,
            reserved: 0,
            reason: [0; REASON_CAPACITY],
        };
        match outcome {
            Outcome::Goals { j_pos_m, j_att_deg } => {
                r.j_pos_m = *j_pos_m;
                r.j_att_deg = *j_att_deg;
            }
            Outcome::Diverged { t_s, event } => {
                r.status = status::DIVERGED;
                r.t_s = *t_s;
                r.event = *event as u32;
            }
            Outcome::Failed { reason } => {
                r.status = status::FAILED;
                // Outcomes are made with reasons of at most REASON_CAPACITY bytes
                // (`Outcome::failed`); cut at a character boundary all the same.
                let mut end = reason.len().min(REASON_CAPACITY);
                while !reason.is_char_boundary(end) {
                    end -= 1;
                }
                r.reason[..end].copy_from_slice(&reason.as_bytes()[..end]);
                r.reason_len = end as u32;
            }
        }
        r
    }

    /// The outcome, refusing a malformed message.
    pub fn outcome(&self) -> Result<Outcome, WireError> {
        match self.status {
            status::GOALS => Ok(Outcome::Goals {
                j_pos_m: self.j_pos_m,
                j_att_deg: self.j_att_deg,
            }),
            status::DIVERGED => Ok(Outcome::Diverged {
                t_s: self.t_s,
                event: self.event as usize,
            }),
            status::FAILED => {
                let len = self.reason_len as usize;
                let text = self
                    .reason
                    .get(..len)
                    .and_then(|b| std::str::from_utf8(b).ok())
                    .ok_or(WireError::Reason(self.reason_len))?;
                Ok(Outcome::Failed {
                    reason: text.to_string(),
                })
            }
            other => Err(WireError::Status(other)),
        }
    }
}

/// A chunk of requests, as a worker holds it.
#[derive(Debug, Clone, PartialEq)]
pub struct Chunk {
    /// Its header (`count` = `requests.len()`).
    pub header: ChunkHeader,
    /// The candidates.
    pub requests: Vec<WireRequest>,
}

impl Chunk {
    /// The chunk `chunk_id` of `batch[indices]`.
    pub fn new(chunk_id: u64, indices: &[usize], batch: &[Candidate], with_samples: bool) -> Self {
        Chunk {
            header: ChunkHeader {
                chunk_id,
                count: indices.len() as u32,
                with_samples: u32::from(with_samples),
            },
            requests: indices
                .iter()
                .map(|&i| WireRequest::new(i as u64, &batch[i]))
                .collect(),
        }
    }

    /// Whether samples are wanted back.
    pub fn with_samples(&self) -> bool {
        self.header.with_samples != 0
    }
}

/// The answer to a chunk.
#[derive(Debug, Clone, PartialEq)]
pub struct Answer {
    /// The chunk's header, echoed.
    pub header: ChunkHeader,
    /// One response per request, in order.
    pub responses: Vec<WireResponse>,
    /// With samples: the job's samples of every candidate in turn ([`WireObservation::MISSING`]
    /// for runs that did not finish); otherwise empty.
    pub samples: Vec<WireObservation>,
}

/// Evaluates chunks: their requests become candidates (a malformed one a `Failed` outcome),
/// `evaluate` runs every valid one as one batch (the job's own evaluation in a worker, a host's
/// workers behind a gateway), and the evaluations become one answer per chunk. The one serve
/// function of every worker loop. The chunks must be of one kind (all with samples, or none).
pub fn serve_chunks<E>(
    job: &Job,
    chunks: &[Chunk],
    evaluate: impl FnOnce(&[Candidate], bool) -> Result<Vec<Evaluation>, E>,
) -> Result<Vec<Answer>, E> {
    let with_samples = chunks.first().is_some_and(Chunk::with_samples);
    let requests: Vec<&WireRequest> = chunks.iter().flat_map(|c| &c.requests).collect();
    let mut outcomes: Vec<Option<Evaluation>> = vec![None; requests.len()];
    let mut batch = Vec::with_capacity(requests.len());
    let mut at = Vec::with_capacity(requests.len());
    for (k, r) in requests.iter().enumerate() {
        match r.candidate() {
            Ok(c) => {
                batch.push(c);
                at.push(k);
            }
            Err(e) => {
                outcomes[k] = Some(Evaluation::from(Outcome::failed(format!(
                    "malformed request: {e}"
                ))));
            }
        }
    }
    if !batch.is_empty() {
        for (e, k) in evaluate(&batch, with_samples)?.into_iter().zip(at) {
            outcomes[k] = Some(e);
        }
    }
    let per = job.sample_count();
    let mut outcomes = outcomes.into_iter();
    Ok(chunks
        .iter()
        .map(|chunk| {
            let mut samples = Vec::new();
            let mut responses = Vec::with_capacity(chunk.requests.len());
            for (r, e) in chunk.requests.iter().zip(outcomes.by_ref()) {
                let e = e.unwrap_or_else(|| Evaluation::from(Outcome::failed("not evaluated")));
                responses.push(WireResponse::new(r.index, &e.outcome));
                if with_samples {
                    match e.samples {
                        Some(events) => {
                            for ev in events {
                                let wire = ev.into_iter().map(WireObservation::from);
                                if samples.is_empty() {
                                    // The first event keeps its buffer (one layout).
                                    samples = wire.collect();
                                } else {
                                    samples.extend(wire);
                                }
                            }
                        }
                        None => samples.extend(std::iter::repeat_n(WireObservation::MISSING, per)),
                    }
                }
            }
            Answer {
                header: ChunkHeader {
                    count: responses.len() as u32,
                    ..chunk.header
                },
                responses,
                samples,
            }
        })
        .collect())
}

/// Evaluates a chunk in this process, its candidates [`sepval_common::propagator::LANES`] at a
/// time through the lane propagator ([`Job::evaluate_batch`]).
pub fn serve_locally(job: &Job, chunk: &Chunk) -> Answer {
    let result: Result<Vec<Answer>, std::convert::Infallible> =
        serve_chunks(job, std::slice::from_ref(chunk), |batch, s| {
            Ok(job.evaluate_batch(batch, s))
        });
    match result {
        Ok(mut a) => a.remove(0),
        Err(never) => match never {},
    }
}

impl Answer {
    /// The evaluations of the candidates at `indices` (the chunk as sent), refusing an answer
    /// that does not fit it: another count, another candidate, a malformed outcome, samples of
    /// the wrong length. The answer is consumed: its samples become the evaluations' without a
    /// second copy of the whole answer (a long telemetry record makes them large).
    pub fn evaluations(
        self,
        indices: &[usize],
        job: &Job,
    ) -> Result<Vec<(usize, Evaluation)>, String> {
        if self.responses.len() != indices.len() {
            return Err(format!(
                "it answered {} of {} candidates",
                self.responses.len(),
                indices.len()
            ));
        }
        let per = job.sample_count();
        let with_samples = self.header.with_samples != 0;
        if with_samples && self.samples.len() != per * indices.len() {
            return Err(format!(
                "it sent {} samples for {} candidates of {per}",
                self.samples.len(),
                indices.len()
            ));
        }
        let mut outcomes = Vec::with_capacity(indices.len());
        for (r, &index) in self.responses.iter().zip(indices) {
            if r.index as usize != index {
                return Err(format!(
                    "it answered candidate {} in place of {index}",
                    r.index
                ));
            }
            outcomes.push(r.outcome().map_err(|e| format!("malformed answer: {e}"))?);
        }
        // Each candidate's samples, taken from the back so that the buffer shrinks as it goes.
        let mut flat = self.samples;
        let mut samples: Vec<Option<Vec<Vec<Observation>>>> = vec![None; indices.len()];
        if with_samples {
            for k in (0..indices.len()).rev() {
                let part = if k == 0 {
                    std::mem::take(&mut flat)
                } else {
                    flat.split_off(k * per)
                };
                if outcomes[k].goals().is_some() {
                    samples[k] = Some(split_events(job, part));
                }
            }
        }
        Ok(indices
            .iter()
            .zip(outcomes)
            .zip(samples)
            .map(|((&index, outcome), samples)| (index, Evaluation { outcome, samples }))
            .collect())
    }
}

/// One candidate's flat samples, split per event (a single event keeps the buffer: the two
/// types have one layout).
fn split_events(job: &Job, mut flat: Vec<WireObservation>) -> Vec<Vec<Observation>> {
    let mut out = Vec::with_capacity(job.events().len());
    for e in job.events().iter().rev() {
        let start = flat.len() - e.data.len();
        let part = if start == 0 {
            std::mem::take(&mut flat)
        } else {
            flat.split_off(start)
        };
        out.push(part.into_iter().map(Observation::from).collect());
    }
    out.reverse();
    out
}

#[cfg(test)]
mod tests;
