//! The byte form of the wire types, for transports that carry bytes (Unix sockets, zenoh).
//!
//! Every message is a [`Frame`]: [`MAGIC`] (u64), the sender's protocol version (u32) and the
//! kind (u32), checked in that order before anything else is read, so that two versions refuse
//! each other by name instead of misreading each other's bytes; then the body, whose fixed-layout
//! types ([`crate::wire`]) are written field by field, little-endian, and whose variable parts
//! (slices, text) carry their length first. Decoding never trusts a length: every count is
//! bounded ([`MAX_CHUNK`], [`MAX_TEXT`], [`MAX_SETUP`]) and checked against the bytes actually
//! present before anything is allocated, and trailing bytes are refused.

use crate::wire::WireTerm;
use crate::wire::{
    Answer, Chunk, ChunkHeader, MAGIC, MAX_CHUNK, PROTOCOL_VERSION, REASON_CAPACITY, SetupHeader,
    WireObservation, WireRequest, WireResponse,
};
use sepval_common::correction::MAX_CORRECTION_VALUES;
use sepval_common::effects::{MAX_ACTIVE_EFFECTS, MAX_EFFECT_PARAMS};
use sepval_common::extension::MAX_TERMS;
use sepval_core::factors::FACTOR_COUNT;

/// Longest text field (a host name, a reason, a run id) \[bytes\].
pub const MAX_TEXT: usize = 64 << 10;
/// Largest job setup \[bytes\].
pub const MAX_SETUP: usize = 1 << 30;
/// Most samples in one answer.
pub const MAX_SAMPLES: usize = 1 << 28;

/// A frame that cannot be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CodecError {
    /// Not a sepval message.
    #[error("magic {found:#x}, expected {MAGIC:#x}: not a sepval message")]
    Magic {
        /// The first eight bytes.
        found: u64,
    },
    /// Another protocol version.
    #[error("it speaks protocol version {theirs}, ours is {PROTOCOL_VERSION}")]
    Protocol {
        /// The sender's version.
        theirs: u32,
    },
    /// A kind this version does not know.
    #[error("unknown message kind {0}")]
    Kind(u32),
    /// Fewer bytes than the message needs.
    #[error("truncated: {needed} more bytes needed at byte {at}")]
    Truncated {
        /// Offset of the read.
        at: usize,
        /// Bytes missing.
        needed: usize,
    },
    /// A count beyond its bound.
    #[error("{what} of {count} exceeds the limit of {limit}")]
    TooLarge {
        /// What was counted.
        what: &'static str,
        /// The count read.
        count: u64,
        /// The bound.
        limit: usize,
    },
    /// Text that is not UTF-8.
    #[error("{0} is not valid UTF-8")]
    Utf8(&'static str),
    /// Bytes after the end of the message.
    #[error("{0} unexpected bytes after the message")]
    Trailing(usize),
    /// A chunk whose header counts other requests than follow it.
    #[error("chunk header counts {announced} requests, {follow} follow")]
    ChunkCount {
        /// The requests its header counts.
        announced: u32,
        /// The requests that follow.
        follow: usize,
    },
}

/// Kinds of frames.
mod kind {
    pub const SETUP: u32 = 1;
    pub const READY: u32 = 2;
    pub const CHUNK: u32 = 3;
    pub const ANSWER: u32 = 4;
    pub const QUIT: u32 = 5;
    pub const DROPPED: u32 = 6;
}

/// One message between a coordinator and a worker over a byte transport.
#[derive(Debug, Clone, PartialEq)]
pub enum Frame {
    /// The job setup of run `run_id` (coordinator to worker: the answer to a worker's query,
    /// and, sent on the worker's own channel, the run's next job).
    Setup {
        /// The run the setup belongs to.
        run_id: String,
        /// Its header.
        header: SetupHeader,
        /// Its bytes ([`crate::setup::encode_setup`]).
        bytes: Vec<u8>,
    },
    /// A worker accepted the setup and can hold `credits` chunks (worker to coordinator).
    Ready {
        /// Process id, for messages.
        pid: u32,
        /// Chunks it can hold at once.
        credits: u32,
        /// SHA-256 of the setup it accepted.
        setup_sha256: [u8; 32],
        /// Host name, for messages.
        host: String,
    },
    /// A chunk of candidates (coordinator to worker).
    Chunk(Chunk),
    /// Its answer (worker to coordinator).
    Answer(Answer),
    /// The run is over (coordinator to worker).
    Quit(String),
    /// The coordinator refuses this worker from now on (coordinator to worker).
    Dropped(String),
}

/// Little-endian writer.
pub(crate) struct Writer(pub(crate) Vec<u8>);

impl Writer {
    pub(crate) fn u32(&mut self, v: u32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub(crate) fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub(crate) fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_bits().to_le_bytes());
    }
    pub(crate) fn bytes(&mut self, b: &[u8]) {
        self.u64(b.len() as u64);
        self.0.extend_from_slice(b);
    }
    fn chunk_header(&mut self, h: &ChunkHeader) {
        self.u64(h.chunk_id);
        self.u32(h.count);
        self.u32(h.with_samples);
    }
}

/// Little-endian reader that checks every length against what is there.
pub(crate) struct Reader<'a> {
    pub(crate) bytes: &'a [u8],
    pub(crate) at: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn take(&mut self, n: usize) -> Result<&'a [u8], CodecError> {
        let left = self.bytes.len() - self.at;
        if n > left {
            return Err(CodecError::Truncated {
                at: self.at,
                needed: n - left,
            });
        }
        let s = &self.bytes[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    pub(crate) fn array<const N: usize>(&mut self) -> Result<[u8; N], CodecError> {
        Ok(self.take(N)?.try_into().expect("N bytes taken"))
    }
    pub(crate) fn u32(&mut self) -> Result<u32, CodecError> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    pub(crate) fn u64(&mut self) -> Result<u64, CodecError> {
        Ok(u64::from_le_bytes(self.array()?))
    }
    pub(crate) fn f64(&mut self) -> Result<f64, CodecError> {
        Ok(f64::from_bits(self.u64()?))
    }
    /// A count of items of `size` bytes each, bounded by `limit` and by the bytes left.
    pub(crate) fn count(
        &mut self,
        what: &'static str,
        limit: usize,
        size: usize,
    ) -> Result<usize, CodecError> {
        let n = self.u64()?;
        if n > limit as u64 {
            return Err(CodecError::TooLarge {
                what,
                count: n,
                limit,
            });
        }
        let n = n as usize;
        let left = self.bytes.len() - self.at;
        if n.saturating_mul(size) > left {
            return Err(CodecError::Truncated {
                at: self.at,
                needed: n * size - left,
            });
        }
        Ok(n)
    }
    pub(crate) fn bytes(
        &mut self,
        what: &'static str,
        limit: usize,
    ) -> Result<&'a [u8], CodecError> {
        let n = self.count(what, limit, 1)?;
        self.take(n)
    }
    pub(crate) fn text(&mut self, what: &'static str) -> Result<String, CodecError> {
        self.text_up_to(what, MAX_TEXT)
    }
    pub(crate) fn text_up_to(
        &mut self,
        what: &'static str,
        limit: usize,
    ) -> Result<String, CodecError> {
        let b = self.bytes(what, limit)?;
        std::str::from_utf8(b)
            .map(str::to_string)
            .map_err(|_| CodecError::Utf8(what))
    }
    fn chunk_header(&mut self) -> Result<ChunkHeader, CodecError> {
        Ok(ChunkHeader {
            chunk_id: self.u64()?,
            count: self.u32()?,
            with_samples: self.u32()?,
        })
    }
    pub(crate) fn end(&self) -> Result<(), CodecError> {
        match self.bytes.len() - self.at {
            0 => Ok(()),
            n => Err(CodecError::Trailing(n)),
        }
    }
}

const REQUEST_SIZE: usize = 8
    + 8 * FACTOR_COUNT
    + 4
    + 4 * MAX_ACTIVE_EFFECTS
    + 4
    + 8 * MAX_EFFECT_PARAMS * MAX_ACTIVE_EFFECTS
    + 4
    + 4
    + 32 * MAX_TERMS
    + 4
    + 4
    + 8 * MAX_CORRECTION_VALUES;
const RESPONSE_SIZE: usize = 8 + 4 + 4 + 8 * 3 + 4 + 4 + REASON_CAPACITY;
const OBSERVATION_SIZE: usize = 8 * 6;

fn put_request(w: &mut Writer, r: &WireRequest) {
    w.u64(r.index);
    r.factors.iter().for_each(|&v| w.f64(v));
    w.u32(r.effect_count);
    r.effect_index.iter().for_each(|&v| w.u32(v));
    w.u32(r.reserved);
    r.effect_params.iter().flatten().for_each(|&v| w.f64(v));
    w.u32(r.term_count);
    w.u32(r.reserved_terms);
    for t in &r.terms {
        w.u32(t.axis);
        w.u32(t.regressor);
        w.f64(t.locator[0]);
        w.f64(t.locator[1]);
        w.f64(t.coefficient);
    }
    w.u32(r.correction_count);
    w.u32(r.reserved_corrections);
    r.corrections.iter().for_each(|&v| w.f64(v));
}

fn get_request(r: &mut Reader) -> Result<WireRequest, CodecError> {
    let index = r.u64()?;
    let mut factors = [0.0; FACTOR_COUNT];
    for v in &mut factors {
        *v = r.f64()?;
    }
    let effect_count = r.u32()?;
    let mut effect_index = [0; MAX_ACTIVE_EFFECTS];
    for v in &mut effect_index {
        *v = r.u32()?;
    }
    let reserved = r.u32()?;
    let mut effect_params = [[0.0; MAX_EFFECT_PARAMS]; MAX_ACTIVE_EFFECTS];
    for v in effect_params.iter_mut().flatten() {
        *v = r.f64()?;
    }
    let term_count = r.u32()?;
    let reserved_terms = r.u32()?;
    let mut terms = [WireTerm::default(); MAX_TERMS];
    for t in &mut terms {
        *t = WireTerm {
            axis: r.u32()?,
            regressor: r.u32()?,
            locator: [r.f64()?, r.f64()?],
            coefficient: r.f64()?,
        };
    }
    let correction_count = r.u32()?;
    let reserved_corrections = r.u32()?;
    let mut corrections = [0.0; MAX_CORRECTION_VALUES];
    for v in &mut corrections {
        *v = r.f64()?;
    }
    Ok(WireRequest {
        index,
        factors,
        effect_count,
        effect_index,
        reserved,
        effect_params,
        term_count,
        reserved_terms,
        terms,
        correction_count,
        reserved_corrections,
        corrections,
    })
}

fn put_response(w: &mut Writer, r: &WireResponse) {
    w.u64(r.index);
    w.u32(r.status);
    w.u32(r.event);
    w.f64(r.j_pos_m);
    w.f64(r.j_att_deg);
    w.f64(r.t_s);
    w.u32(r.reason_len);
    w.u32(r.reserved);
    w.0.extend_from_slice(&r.reason);
}

fn get_response(r: &mut Reader) -> Result<WireResponse, CodecError> {
    Ok(WireResponse {
        index: r.u64()?,
        status: r.u32()?,
        event: r.u32()?,
        j_pos_m: r.f64()?,
        j_att_deg: r.f64()?,
        t_s: r.f64()?,
        reason_len: r.u32()?,
        reserved: r.u32()?,
        reason: r.array()?,
    })
}

fn put_observation(w: &mut Writer, o: &WireObservation) {
    o.pos_m.iter().chain(&o.att_deg).for_each(|&v| w.f64(v));
}

fn get_observation(r: &mut Reader) -> Result<WireObservation, CodecError> {
    Ok(WireObservation {
        pos_m: [r.f64()?, r.f64()?, r.f64()?],
        att_deg: [r.f64()?, r.f64()?, r.f64()?],
    })
}

impl Frame {
    /// The kind of a frame, for messages (`end of stream` for none).
    pub fn name_of(frame: Option<&Frame>) -> &'static str {
        match frame {
            None => "end of stream",
            Some(Frame::Setup { .. }) => "a setup",
            Some(Frame::Ready { .. }) => "a ready message",
            Some(Frame::Chunk(_)) => "a chunk",
            Some(Frame::Answer(_)) => "an answer",
            Some(Frame::Quit(_)) => "a quit message",
            Some(Frame::Dropped(_)) => "a dropped message",
        }
    }

    /// What a frame from the coordinator means to a worker: a chunk, or the end of the run;
    /// `Dropped`, or a frame coordinators do not send, is an error. (A setup, the run's next
    /// job, is the link's to check and accept before this.)
    pub fn into_incoming(self) -> Result<crate::link::Incoming, crate::TransportError> {
        use crate::link::{Incoming, Stopped};
        match self {
            Frame::Chunk(c) => Ok(Incoming::Chunk(c)),
            Frame::Quit(reason) => Ok(Incoming::Stop(Stopped::Quit(reason))),
            Frame::Dropped(reason) => Err(crate::TransportError::Dropped { reason }),
            other => Err(crate::TransportError::NotACoordinatorFrame {
                frame: Frame::name_of(Some(&other)),
            }),
        }
    }

    /// The frame's bytes, announcing our protocol version.
    pub fn encode(&self) -> Vec<u8> {
        self.encode_as(PROTOCOL_VERSION)
    }

    /// The frame's bytes, announcing `protocol` (compatibility tests announce other versions).
    pub fn encode_as(&self, protocol: u32) -> Vec<u8> {
        let mut w = Writer(Vec::with_capacity(64));
        w.u64(MAGIC);
        w.u32(protocol);
        match self {
            Frame::Setup {
                run_id,
                header,
                bytes,
            } => {
                w.u32(kind::SETUP);
                w.bytes(run_id.as_bytes());
                w.u64(header.magic);
                w.u32(header.protocol);
                w.u32(header.reserved);
                w.u64(header.len);
                w.0.extend_from_slice(&header.sha256);
                w.0.extend_from_slice(&header.catalogue);
                w.bytes(bytes);
            }
            Frame::Ready {
                pid,
                credits,
                setup_sha256,
                host,
            } => {
                w.u32(kind::READY);
                w.u32(*pid);
                w.u32(*credits);
                w.0.extend_from_slice(setup_sha256);
                w.bytes(host.as_bytes());
            }
            Frame::Chunk(c) => {
                w.u32(kind::CHUNK);
                w.chunk_header(&c.header);
                w.u64(c.requests.len() as u64);
                w.0.reserve(c.requests.len() * REQUEST_SIZE);
                c.requests.iter().for_each(|r| put_request(&mut w, r));
            }
            Frame::Answer(a) => {
                w.u32(kind::ANSWER);
                w.chunk_header(&a.header);
                w.u64(a.responses.len() as u64);
                w.0.reserve(a.responses.len() * RESPONSE_SIZE + a.samples.len() * OBSERVATION_SIZE);
                a.responses.iter().for_each(|r| put_response(&mut w, r));
                w.u64(a.samples.len() as u64);
                a.samples.iter().for_each(|o| put_observation(&mut w, o));
            }
            Frame::Quit(reason) => {
                w.u32(kind::QUIT);
                w.bytes(reason.as_bytes());
            }
            Frame::Dropped(reason) => {
                w.u32(kind::DROPPED);
                w.bytes(reason.as_bytes());
            }
        }
        w.0
    }

    /// Reads a frame, refusing another magic or protocol version before reading the body.
    pub fn decode(bytes: &[u8]) -> Result<Frame, CodecError> {
        let mut r = Reader { bytes, at: 0 };
        let magic = r.u64()?;
        if magic != MAGIC {
            return Err(CodecError::Magic { found: magic });
        }
        let protocol = r.u32()?;
        if protocol != PROTOCOL_VERSION {
            return Err(CodecError::Protocol { theirs: protocol });
        }
        let frame = match r.u32()? {
            kind::SETUP => {
                let run_id = r.text("run id")?;
                let header = SetupHeader {
                    magic: r.u64()?,
                    protocol: r.u32()?,
                    reserved: r.u32()?,
                    len: r.u64()?,
                    sha256: r.array()?,
                    catalogue: r.array()?,
                };
                let bytes = r.bytes("setup", MAX_SETUP)?.to_vec();
                Frame::Setup {
                    run_id,
                    header,
                    bytes,
                }
            }
            kind::READY => Frame::Ready {
                pid: r.u32()?,
                credits: r.u32()?,
                setup_sha256: r.array()?,
                host: r.text("host name")?,
            },
            kind::CHUNK => {
                let header = r.chunk_header()?;
                let n = r.count("chunk", MAX_CHUNK, REQUEST_SIZE)?;
                if n != header.count as usize {
                    return Err(CodecError::ChunkCount {
                        announced: header.count,
                        follow: n,
                    });
                }
                let requests = (0..n)
                    .map(|_| get_request(&mut r))
                    .collect::<Result<_, _>>()?;
                Frame::Chunk(Chunk { header, requests })
            }
            kind::ANSWER => {
                let header = r.chunk_header()?;
                let n = r.count("answer", MAX_CHUNK, RESPONSE_SIZE)?;
                let responses = (0..n)
                    .map(|_| get_response(&mut r))
                    .collect::<Result<_, _>>()?;
                let m = r.count("samples", MAX_SAMPLES, OBSERVATION_SIZE)?;
                let samples = (0..m)
                    .map(|_| get_observation(&mut r))
                    .collect::<Result<_, _>>()?;
                Frame::Answer(Answer {
                    header,
                    responses,
                    samples,
                })
            }
            kind::QUIT => Frame::Quit(r.text("reason")?),
            kind::DROPPED => Frame::Dropped(r.text("reason")?),
            other => return Err(CodecError::Kind(other)),
        };
        r.end()?;
        Ok(frame)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::{Chunk, serve_locally};
    use sepval_common::evaluation::Candidate;
    use sepval_core::factors::Factors;

    fn frames() -> Vec<Frame> {
        let job = crate::default_job();
        let batch = [
            Candidate::baseline(Factors::TRUTH),
            Candidate::baseline(Factors([9.0; 17])),
        ];
        let chunk = Chunk::new(4, &[0, 1], &batch, true);
        let answer = serve_locally(&job, &chunk);
        vec![
            Frame::Setup {
                run_id: "run-a".into(),
                header: SetupHeader {
                    magic: MAGIC,
                    len: 3,
                    ..SetupHeader::default()
                },
                bytes: vec![1, 2, 3],
            },
            Frame::Ready {
                pid: 7,
                credits: 2,
                setup_sha256: [5; 32],
                host: "h".into(),
            },
            Frame::Chunk(chunk),
            Frame::Answer(answer),
            Frame::Quit("done".into()),
            Frame::Dropped("late".into()),
        ]
    }

    #[test]
    fn every_frame_round_trips_bit_for_bit() {
        for f in frames() {
            let back = Frame::decode(&f.encode()).unwrap();
            // NaN samples compare unequal: compare the bytes again.
            assert_eq!(back.encode(), f.encode(), "{f:?}");
        }
    }

    #[test]
    fn other_versions_and_damaged_frames_are_refused_by_name() {
        let f = Frame::Quit("x".into());
        assert_eq!(
            Frame::decode(&f.encode_as(99)).unwrap_err().to_string(),
            format!("it speaks protocol version 99, ours is {PROTOCOL_VERSION}")
        );
        assert!(
            Frame::decode(b"hello, world")
                .unwrap_err()
                .to_string()
                .contains("not a sepval message")
        );
        for f in frames() {
            let bytes = f.encode();
            for cut in [13, bytes.len() / 2, bytes.len() - 1] {
                assert!(Frame::decode(&bytes[..cut]).is_err(), "{f:?} cut at {cut}");
            }
            let mut long = bytes.clone();
            long.push(0);
            assert_eq!(Frame::decode(&long), Err(CodecError::Trailing(1)));
        }
        // A count far beyond the bytes present allocates nothing and is refused.
        let mut w = Writer(Vec::new());
        w.u64(MAGIC);
        w.u32(PROTOCOL_VERSION);
        w.u32(kind::ANSWER);
        w.chunk_header(&ChunkHeader::default());
        w.u64(u64::MAX);
        assert!(matches!(
            Frame::decode(&w.0),
            Err(CodecError::TooLarge { .. })
        ));
    }
}
