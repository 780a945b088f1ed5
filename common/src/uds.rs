//! The conventional alternative to shared memory, for the throughput benchmark: the same
//! requests as postcard frames (a little-endian u32 length, then the bytes) over a Unix domain
//! socket. The coordinator listens; each `sepval-worker --uds PATH` connects, receives the job
//! setup frame, then answers request frames with response frames.

use std::io::{Read, Write};

use serde::{Deserialize, Serialize};

use crate::effects::EffectSet;
use crate::evaluation::{Candidate, Outcome};
use crate::factors::Factors;
use crate::messages::{PROTOCOL_VERSION, SetupHeader};
use crate::propagator::Observation;

/// Largest frame accepted \[bytes\] (a corrupt length must not allocate gigabytes).
pub const MAX_FRAME: usize = 256 << 20;

/// One candidate in a frame: (index, factors, effects as (catalogue index, values)).
pub type ItemFrame = (u64, [f64; 17], Vec<(u32, Vec<f64>)>);
/// Simulated samples in a frame: per event, (position, attitude) per sample.
pub type SamplesFrame = Vec<Vec<([f64; 3], [f64; 3])>>;
/// One answer in a frame: (index, outcome, samples).
pub type AnswerFrame = (u64, OutcomeFrame, Option<SamplesFrame>);

/// Coordinator to worker.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ToWorker {
    /// The job: protocol version, setup header fields and bytes.
    Setup {
        /// Protocol version.
        protocol: u32,
        /// SHA-256 of the bytes.
        sha256: [u8; 32],
        /// Catalogue fingerprint.
        catalogue: [u8; 32],
        /// The setup bytes ([`crate::messages::encode_setup`]).
        bytes: Vec<u8>,
    },
    /// A chunk of candidates.
    Chunk {
        /// Chunk id.
        chunk_id: u64,
        /// Whether samples are wanted.
        with_samples: bool,
        /// (index, factors, effects as (catalogue index, values)).
        items: Vec<ItemFrame>,
    },
}

/// Worker to coordinator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FromWorker {
    /// Chunk id.
    pub chunk_id: u64,
    /// (index, outcome, samples) per candidate.
    pub items: Vec<AnswerFrame>,
}

/// An outcome as a frame carries it (postcard needs an externally tagged enum).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum OutcomeFrame {
    /// Goals (J_pos \[m\], J_att \[deg\]).
    Goals(f64, f64),
    /// Diverged at t \[s\] in an event.
    Diverged(f64, u64),
    /// Failed, with the reason.
    Failed(String),
}

impl From<&Outcome> for OutcomeFrame {
    fn from(o: &Outcome) -> Self {
        match o {
            Outcome::Goals { j_pos_m, j_att_deg } => OutcomeFrame::Goals(*j_pos_m, *j_att_deg),
            Outcome::Diverged { t_s, event } => OutcomeFrame::Diverged(*t_s, *event as u64),
            Outcome::Failed { reason } => OutcomeFrame::Failed(reason.clone()),
        }
    }
}

impl From<OutcomeFrame> for Outcome {
    fn from(o: OutcomeFrame) -> Self {
        match o {
            OutcomeFrame::Goals(j_pos_m, j_att_deg) => Outcome::Goals { j_pos_m, j_att_deg },
            OutcomeFrame::Diverged(t_s, event) => Outcome::Diverged {
                t_s,
                event: event as usize,
            },
            OutcomeFrame::Failed(reason) => Outcome::Failed { reason },
        }
    }
}

/// Errors of the socket protocol.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum UdsError {
    /// The socket failed.
    #[error("socket: {0}")]
    Io(#[from] std::io::Error),
    /// A frame too large to be real.
    #[error("frame of {0} bytes exceeds the {MAX_FRAME}-byte limit")]
    TooLarge(usize),
    /// A frame that does not decode.
    #[error("frame does not decode: {0}")]
    Decode(String),
}

/// Writes one frame.
pub fn write_frame<T: Serialize>(w: &mut impl Write, value: &T) -> Result<(), UdsError> {
    let bytes = postcard::to_stdvec(value).map_err(|e| UdsError::Decode(e.to_string()))?;
    w.write_all(&(bytes.len() as u32).to_le_bytes())?;
    w.write_all(&bytes)?;
    w.flush()?;
    Ok(())
}

/// Reads one frame.
pub fn read_frame<T: for<'de> Deserialize<'de>>(r: &mut impl Read) -> Result<T, UdsError> {
    let mut len = [0u8; 4];
    r.read_exact(&mut len)?;
    let len = u32::from_le_bytes(len) as usize;
    if len > MAX_FRAME {
        return Err(UdsError::TooLarge(len));
    }
    let mut buf = vec![0u8; len];
    r.read_exact(&mut buf)?;
    postcard::from_bytes(&buf).map_err(|e| UdsError::Decode(e.to_string()))
}

/// The chunk item of a candidate.
pub fn item(index: u64, c: &Candidate) -> ItemFrame {
    (
        index,
        c.factors.0,
        c.effects
            .iter()
            .map(|a| (a.index as u32, a.values().to_vec()))
            .collect(),
    )
}

/// The candidate of a chunk item (checked like a shared-memory request).
pub fn candidate(factors: &[f64; 17], effects: &[(u32, Vec<f64>)]) -> Result<Candidate, String> {
    if let Some(v) = factors.iter().find(|v| !v.is_finite()) {
        return Err(format!("factor value {v} is not finite"));
    }
    let mut set = EffectSet::NONE;
    for (index, values) in effects {
        set.push(*index as usize, values)
            .map_err(|e| e.to_string())?;
    }
    Ok(Candidate {
        factors: Factors(*factors),
        effects: set,
    })
}

/// The setup frame's header, for [`crate::messages::decode_setup`].
pub fn setup_header(
    protocol: u32,
    sha256: [u8; 32],
    catalogue: [u8; 32],
    len: usize,
) -> SetupHeader {
    SetupHeader {
        magic: crate::messages::MAGIC,
        protocol,
        reserved: 0,
        len: len as u64,
        sha256,
        catalogue,
    }
}

/// Samples as frame data.
pub fn samples_out(s: &[Vec<Observation>]) -> SamplesFrame {
    s.iter()
        .map(|e| e.iter().map(|o| (o.pos_m, o.att_deg)).collect())
        .collect()
}

/// Samples from frame data.
pub fn samples_in(s: SamplesFrame) -> Vec<Vec<Observation>> {
    s.into_iter()
        .map(|e| {
            e.into_iter()
                .map(|(pos_m, att_deg)| Observation { pos_m, att_deg })
                .collect()
        })
        .collect()
}

/// Our protocol version (the same as the shared-memory transport's).
pub const UDS_PROTOCOL: u32 = PROTOCOL_VERSION;
