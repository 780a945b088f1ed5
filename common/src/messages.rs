//! Messages between a coordinator and its workers: fixed-layout, zero-copy types (no
//! serialisation on the hot path), defined once here for both executables, with a protocol
//! version.
//!
//! The job setup (scenarios and measured data) travels once per run as bytes (postcard of the
//! scenario TOML and data CSV texts, which round-trip exactly) behind a [`SetupHeader`] that
//! carries the protocol version, the setup's SHA-256 and the effect catalogue's fingerprint.
//! Evaluation traffic is slices of [`WireRequest`] and [`WireResponse`] (and, for residual
//! fits, [`WireObservation`]) behind a [`ChunkHeader`].
//!
//! The layouts of [`Hello`] and [`SetupHeader`] never change, so that a worker and a
//! coordinator of different protocol versions can still read each other's version and refuse
//! with a clear message; every other type may change with [`PROTOCOL_VERSION`].

use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};

use crate::effects::{
    CATALOGUE, EffectSet, MAX_ACTIVE_EFFECTS, MAX_EFFECT_PARAMS, catalogue_fingerprint,
};
use crate::evaluation::{Candidate, Event, Job, JobError, Outcome};
use crate::factors::{FACTOR_COUNT, Factors};
use crate::propagator::Observation;
use crate::scenario::{Scenario, hex_sha256};
use crate::simulation::Simulator;
use crate::telemetry::Trajectory;

/// Version of the coordinator-worker protocol. A coordinator and a worker refuse each other
/// unless they agree on it.
pub const PROTOCOL_VERSION: u32 = 1;

/// "SEPVAL01" as a little-endian integer: the first field of [`Hello`] and [`SetupHeader`].
pub const MAGIC: u64 = u64::from_le_bytes(*b"SEPVAL01");

/// Longest failure reason carried by a [`WireResponse`] (bytes of UTF-8).
pub const REASON_CAPACITY: usize = 120;

/// A worker announcing itself to the coordinator (layout fixed across protocol versions).
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

/// Header of the job setup sample (layout fixed across protocol versions).
#[derive(Debug, Clone, Copy, Default, ZeroCopySend)]
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
    /// SHA-256 of the effect catalogue's fingerprint text ([`catalogue_fingerprint`]).
    pub catalogue: [u8; 32],
}

/// Header of a chunk of requests or responses.
#[derive(Debug, Clone, Copy, Default, ZeroCopySend)]
#[type_name("sepval.ChunkHeader")]
#[repr(C)]
pub struct ChunkHeader {
    /// The coordinator's id of the chunk (echoed in the response).
    pub chunk_id: u64,
    /// Number of items.
    pub count: u32,
    /// 1 when the simulated samples are wanted back.
    pub with_samples: u32,
}

/// One candidate to evaluate.
#[derive(Debug, Clone, Copy, ZeroCopySend)]
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
    /// Parameters of each active effect.
    pub effect_params: [[f64; MAX_EFFECT_PARAMS]; MAX_ACTIVE_EFFECTS],
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
#[derive(Debug, Clone, Copy, ZeroCopySend)]
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
    /// Length of `reason`.
    pub reason_len: u32,
    /// Failure reason, UTF-8 (truncated at a character boundary).
    pub reason: [u8; REASON_CAPACITY],
}

/// One simulated sample (residual fits).
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[type_name("sepval.WireObservation")]
#[repr(C)]
pub struct WireObservation {
    /// Position \[m\].
    pub pos_m: [f64; 3],
    /// Euler angles \[deg\].
    pub att_deg: [f64; 3],
}

impl From<&Observation> for WireObservation {
    fn from(o: &Observation) -> Self {
        WireObservation {
            pos_m: o.pos_m,
            att_deg: o.att_deg,
        }
    }
}

impl From<&WireObservation> for Observation {
    fn from(o: &WireObservation) -> Self {
        Observation {
            pos_m: o.pos_m,
            att_deg: o.att_deg,
        }
    }
}

impl WireRequest {
    /// The wire form of candidate `index`.
    pub fn new(index: u64, c: &Candidate) -> Self {
        let mut r = WireRequest {
            index,
            factors: c.factors.0,
            effect_count: c.effects.len() as u32,
            effect_index: [0; MAX_ACTIVE_EFFECTS],
            effect_params: [[0.0; MAX_EFFECT_PARAMS]; MAX_ACTIVE_EFFECTS],
        };
        for (k, a) in c.effects.iter().enumerate() {
            r.effect_index[k] = a.index as u32;
            r.effect_params[k] = a.params;
        }
        r
    }

    /// The candidate, after checking everything a message from another process could get
    /// wrong (counts, indices, finite values); factor bounds are checked when it runs.
    pub fn candidate(&self) -> Result<Candidate, String> {
        for (i, v) in self.factors.iter().enumerate() {
            if !v.is_finite() {
                return Err(format!(
                    "factor {} = {v} is not finite",
                    crate::factors::Factor::NAMES[i]
                ));
            }
        }
        let n = self.effect_count as usize;
        if n > MAX_ACTIVE_EFFECTS {
            return Err(format!(
                "effect count {n} exceeds the maximum of {MAX_ACTIVE_EFFECTS}"
            ));
        }
        let mut effects = EffectSet::NONE;
        for k in 0..n {
            let index = self.effect_index[k] as usize;
            let effect = CATALOGUE
                .get(index)
                .ok_or_else(|| format!("effect index {index} is not in the catalogue"))?;
            let params = &self.effect_params[k][..effect.params().len()];
            effects.push(index, params).map_err(|e| e.to_string())?;
        }
        Ok(Candidate {
            factors: Factors(self.factors),
            effects,
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
    pub fn outcome(&self) -> Result<Outcome, String> {
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
                let len = (self.reason_len as usize).min(REASON_CAPACITY);
                Ok(Outcome::Failed {
                    reason: String::from_utf8_lossy(&self.reason[..len]).into_owned(),
                })
            }
            other => Err(format!("unknown response status {other}")),
        }
    }
}

/// The job as it travels to the workers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct JobSetup {
    events: Vec<EventSetup>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct EventSetup {
    name: String,
    scenario_toml: String,
    data_csv: String,
}

/// Errors decoding a job setup.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SetupError {
    /// Not a sepval setup.
    #[error("setup header has magic {found:#x}, expected {MAGIC:#x}: not a sepval setup")]
    Magic {
        /// The magic found.
        found: u64,
    },
    /// Another protocol version.
    #[error("setup has protocol version {theirs}, this process speaks version {ours}")]
    Protocol {
        /// The sender's version.
        theirs: u32,
        /// Ours.
        ours: u32,
    },
    /// Another effect catalogue.
    #[error(
        "setup was made with another effect catalogue (fingerprints differ): build both executables from the same sources"
    )]
    Catalogue,
    /// Corrupted bytes.
    #[error("setup bytes do not match their SHA-256 ({len} bytes)")]
    Hash {
        /// Bytes received.
        len: usize,
    },
    /// Bytes that do not decode.
    #[error("setup bytes do not decode: {0}")]
    Decode(String),
    /// A scenario or data text that does not parse.
    #[error("setup event `{event}`: {message}")]
    Content {
        /// The event.
        event: String,
        /// What failed.
        message: String,
    },
    /// An invalid job.
    #[error(transparent)]
    Job(#[from] JobError),
}

fn sha256_bytes(bytes: &[u8]) -> [u8; 32] {
    use sha2::{Digest, Sha256};
    Sha256::digest(bytes).into()
}

/// The catalogue fingerprint as 32 bytes.
pub fn catalogue_bytes() -> [u8; 32] {
    sha256_bytes(catalogue_fingerprint().as_bytes())
}

/// Encodes a job for the workers: the header and the bytes.
pub fn encode_setup(job: &Job) -> (SetupHeader, Vec<u8>) {
    let setup = JobSetup {
        events: job
            .events()
            .iter()
            .map(|e| EventSetup {
                name: e.name.clone(),
                scenario_toml: e.simulator.scenario().to_toml_string(),
                data_csv: e.data.to_csv_string(),
            })
            .collect(),
    };
    let bytes = postcard::to_stdvec(&setup).expect("strings always serialise");
    let header = SetupHeader {
        magic: MAGIC,
        protocol: PROTOCOL_VERSION,
        reserved: 0,
        len: bytes.len() as u64,
        sha256: sha256_bytes(&bytes),
        catalogue: catalogue_bytes(),
    };
    (header, bytes)
}

/// Checks a setup header against this process (magic, protocol, catalogue).
pub fn check_setup_header(header: &SetupHeader) -> Result<(), SetupError> {
    if header.magic != MAGIC {
        return Err(SetupError::Magic {
            found: header.magic,
        });
    }
    if header.protocol != PROTOCOL_VERSION {
        return Err(SetupError::Protocol {
            theirs: header.protocol,
            ours: PROTOCOL_VERSION,
        });
    }
    if header.catalogue != catalogue_bytes() {
        return Err(SetupError::Catalogue);
    }
    Ok(())
}

/// Decodes a job setup after checking its header and hash.
pub fn decode_setup(header: &SetupHeader, bytes: &[u8]) -> Result<Job, SetupError> {
    check_setup_header(header)?;
    if header.len as usize != bytes.len() || sha256_bytes(bytes) != header.sha256 {
        return Err(SetupError::Hash { len: bytes.len() });
    }
    let setup: JobSetup =
        postcard::from_bytes(bytes).map_err(|e| SetupError::Decode(e.to_string()))?;
    let mut events = Vec::with_capacity(setup.events.len());
    for e in setup.events {
        let content = |message: String| SetupError::Content {
            event: e.name.clone(),
            message,
        };
        let scenario = Scenario::from_toml_str(&e.scenario_toml, &e.name)
            .map_err(|x| content(x.to_string()))?;
        let data = Trajectory::parse(&e.data_csv, &e.name).map_err(|x| content(x.to_string()))?;
        events.push(Event {
            name: e.name,
            simulator: Simulator::new(&scenario),
            data,
        });
    }
    Ok(Job::new(events)?)
}

/// The hex form of a setup's SHA-256 (for messages).
pub fn setup_hash_hex(header: &SetupHeader) -> String {
    header.sha256.iter().map(|b| format!("{b:02x}")).collect()
}

/// Hex SHA-256 of arbitrary bytes (re-exported for transports).
pub fn hex_digest(bytes: &[u8]) -> String {
    hex_sha256(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synthetic::default_flight_test;

    fn job() -> Job {
        Job::single(
            "default",
            &Scenario::embedded_default(),
            default_flight_test(),
        )
    }

    #[test]
    fn setup_round_trips_with_the_same_hashes() {
        let j = job();
        let (h, bytes) = encode_setup(&j);
        let back = decode_setup(&h, &bytes).unwrap();
        assert_eq!(back.data_sha256(), j.data_sha256());
        assert_eq!(back.scenario_sha256(), j.scenario_sha256());
    }

    #[test]
    fn bad_setups_are_refused_with_their_reason() {
        let (h, bytes) = encode_setup(&job());
        let mut other = h;
        other.protocol = PROTOCOL_VERSION + 1;
        assert_eq!(
            decode_setup(&other, &bytes).unwrap_err().to_string(),
            format!(
                "setup has protocol version {}, this process speaks version {PROTOCOL_VERSION}",
                PROTOCOL_VERSION + 1
            )
        );
        let mut corrupt = bytes.clone();
        corrupt[10] ^= 1;
        assert!(matches!(
            decode_setup(&h, &corrupt),
            Err(SetupError::Hash { .. })
        ));
        let mut magic = h;
        magic.magic = 7;
        assert!(matches!(
            decode_setup(&magic, &bytes),
            Err(SetupError::Magic { found: 7 })
        ));
    }

    #[test]
    fn requests_and_responses_round_trip_and_bad_ones_are_refused() {
        let mut effects = EffectSet::NONE;
        effects.push_spec("release_rates=0.1,0.2,0.3").unwrap();
        let c = Candidate {
            factors: Factors::TRUTH,
            effects,
        };
        let w = WireRequest::new(5, &c);
        assert_eq!(w.candidate().unwrap(), c);
        let mut bad = w;
        bad.factors[3] = f64::NAN;
        assert_eq!(
            bad.candidate().unwrap_err(),
            "factor yinerfac = NaN is not finite"
        );
        let mut bad = w;
        bad.effect_count = 9;
        assert_eq!(
            bad.candidate().unwrap_err(),
            "effect count 9 exceeds the maximum of 4"
        );
        let mut bad = w;
        bad.effect_index[0] = 99;
        assert_eq!(
            bad.candidate().unwrap_err(),
            "effect index 99 is not in the catalogue"
        );
        let mut bad = w;
        bad.effect_params[0][1] = f64::INFINITY;
        assert!(bad.candidate().unwrap_err().contains("not a finite number"));

        for o in [
            Outcome::Goals {
                j_pos_m: 0.1,
                j_att_deg: 2.0,
            },
            Outcome::Diverged { t_s: 0.5, event: 1 },
            Outcome::Failed {
                reason: "é".repeat(100),
            },
        ] {
            let back = WireResponse::new(3, &o).outcome().unwrap();
            match (&o, &back) {
                (Outcome::Failed { reason: a }, Outcome::Failed { reason: b }) => {
                    assert!(a.starts_with(b.as_str()) && b.len() <= REASON_CAPACITY)
                }
                _ => assert_eq!(back, o),
            }
        }
        let mut r = WireResponse::new(0, &Outcome::Diverged { t_s: 0.0, event: 0 });
        r.status = 42;
        assert_eq!(r.outcome().unwrap_err(), "unknown response status 42");
    }
}
