//! The job setup: what every worker needs once (the events: scenario and measured data of
//! each release), sent by the coordinator when a worker joins.
//!
//! The setup is, for every event, its name and scenario TOML (length-prefixed UTF-8; the TOML
//! round-trips exactly: sepval writes every number in the shortest form that reads back as the
//! same double) and its samples as little-endian doubles (count, then t, x, y, z, roll, pitch,
//! yaw per sample: 56 bytes a sample, nothing parsed), in the byte form of [`crate::codec`].
//! Comments and metadata of the data files do not travel: the coordinator has already applied
//! what the simulation needs (the flight condition) to each event's scenario. A [`SetupHeader`] carries the protocol version, the bytes' SHA-256 and
//! the effect catalogue's fingerprint; a worker checks all three before it decodes anything.

use sepval_common::effects::catalogue_fingerprint;
use sepval_common::evaluation::{Event, Job, JobError};
use sepval_common::scenario::Scenario;
use sepval_common::simulation::Simulator;
use sepval_common::telemetry::Trajectory;
use sepval_core::limits::MAX_SAMPLES;

use crate::codec::{CodecError, MAX_SETUP, Reader, Writer};
use crate::wire::{MAGIC, PROTOCOL_VERSION, SetupHeader};

/// Most events in one job.
pub const MAX_EVENTS: usize = 4096;

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
    #[error("setup bytes do not decode")]
    Decode(#[from] CodecError),
    /// An event's scenario that does not parse or check.
    #[error("setup event `{event}`: {reason}")]
    Scenario {
        /// The event.
        event: String,
        /// What failed.
        reason: sepval_common::scenario::ScenarioError,
    },
    /// An event's samples that no telemetry file may hold.
    #[error("setup event `{event}`: {reason}")]
    Samples {
        /// The event.
        event: String,
        /// What is wrong with them.
        reason: SampleError,
    },
    /// An invalid job.
    #[error(transparent)]
    Job(#[from] JobError),
}

/// SHA-256 of `bytes`.
pub fn sha256(bytes: &[u8]) -> [u8; 32] {
    use sha2::{Digest, Sha256};
    Sha256::digest(bytes).into()
}

/// The catalogue fingerprint as 32 bytes.
pub fn catalogue_bytes() -> [u8; 32] {
    sha256(catalogue_fingerprint().as_bytes())
}

/// Hex form of a digest, for messages.
pub fn hex(digest: &[u8]) -> String {
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

/// What makes an event's samples, as they arrived in a setup, unusable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SampleError {
    /// A value beyond the plausible bounds, or not finite.
    #[error("sample {sample} holds a value that no telemetry file may hold")]
    Implausible {
        /// The sample.
        sample: usize,
    },
    /// A time not after the previous sample's.
    #[error("sample {sample}: time {time_s} s is not after the previous sample's")]
    NotAfter {
        /// The sample.
        sample: usize,
        /// Its time \[s\].
        time_s: f64,
    },
    /// No samples.
    #[error("no samples")]
    None,
}

/// Checks samples that arrived as numbers as a telemetry file's are checked: finite, within the
/// plausible bounds, times increasing.
fn check_samples(d: &Trajectory) -> Result<(), SampleError> {
    use sepval_core::limits::{MAX_ANGLE_DEG, MAX_POSITION_M, MAX_SPAN_S};
    for k in 0..d.len() {
        let t = d.times_s[k];
        let within = |v: &f64, bound: f64| v.is_finite() && v.abs() <= bound;
        if !(within(&t, MAX_SPAN_S)
            && d.pos_m[k].iter().all(|v| within(v, MAX_POSITION_M))
            && d.att_deg[k].iter().all(|v| within(v, MAX_ANGLE_DEG)))
        {
            return Err(SampleError::Implausible { sample: k });
        }
        if k > 0 && t <= d.times_s[k - 1] {
            return Err(SampleError::NotAfter {
                sample: k,
                time_s: t,
            });
        }
    }
    if d.is_empty() {
        return Err(SampleError::None);
    }
    Ok(())
}

/// A job's setup: its header (announcing `protocol`) and bytes.
pub fn encode_setup_as(job: &Job, protocol: u32) -> (SetupHeader, Vec<u8>) {
    let mut w = Writer(Vec::new());
    w.u64(job.events().len() as u64);
    for e in job.events() {
        w.bytes(e.name.as_bytes());
        w.bytes(e.simulator.scenario().to_toml_string().as_bytes());
        let d = &e.data;
        w.u64(d.len() as u64);
        w.0.reserve(56 * d.len());
        for k in 0..d.len() {
            w.f64(d.times_s[k]);
            d.pos_m[k]
                .iter()
                .chain(&d.att_deg[k])
                .for_each(|&v| w.f64(v));
        }
    }
    let bytes = w.0;
    let header = SetupHeader {
        magic: MAGIC,
        protocol,
        reserved: 0,
        len: bytes.len() as u64,
        sha256: sha256(&bytes),
        catalogue: catalogue_bytes(),
    };
    (header, bytes)
}

/// A job's setup: its header and bytes.
pub fn encode_setup(job: &Job) -> (SetupHeader, Vec<u8>) {
    encode_setup_as(job, PROTOCOL_VERSION)
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
    if header.len != bytes.len() as u64 || sha256(bytes) != header.sha256 {
        return Err(SetupError::Hash { len: bytes.len() });
    }
    let mut r = Reader { bytes, at: 0 };
    let n = r.count("events", MAX_EVENTS, 24)?;
    // Not allocated for `n` up front: an event takes 24 bytes here and over a kilobyte in
    // memory, and events are few.
    let mut events = Vec::new();
    for _ in 0..n {
        let name = r.text("event name")?;
        let scenario_toml = r.text_up_to("scenario", MAX_SETUP)?;
        let scenario = Scenario::from_toml_str(&scenario_toml, &name).map_err(|reason| {
            SetupError::Scenario {
                event: name.clone(),
                reason,
            }
        })?;
        let n = r.count("samples", MAX_SAMPLES, 56)?;
        let mut data = Trajectory {
            times_s: Vec::with_capacity(n),
            pos_m: Vec::with_capacity(n),
            att_deg: Vec::with_capacity(n),
            ..Trajectory::default()
        };
        for _ in 0..n {
            let v: [f64; 7] = std::array::from_fn(|_| r.f64().unwrap_or(f64::NAN));
            data.times_s.push(v[0]);
            data.pos_m.push([v[1], v[2], v[3]]);
            data.att_deg.push([v[4], v[5], v[6]]);
        }
        check_samples(&data).map_err(|reason| SetupError::Samples {
            event: name.clone(),
            reason,
        })?;
        events.push(Event {
            name,
            simulator: Simulator::new(&scenario),
            data,
        });
    }
    r.end()?;
    Ok(Job::new(events)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn job() -> Job {
        crate::default_job()
    }

    #[test]
    fn setup_round_trips_with_the_same_hashes() {
        let j = job();
        let (h, bytes) = encode_setup(&j);
        let back = decode_setup(&h, &bytes).unwrap();
        assert_eq!(back.data_sha256(), j.data_sha256());
        assert_eq!(back.scenario_sha256(), j.scenario_sha256());
    }

    /// A scenario's tables travel with it, inline: a worker needs no table file, and what it
    /// decodes has the same content hash and simulates the same trajectory.
    #[test]
    fn tables_travel_inline_in_the_setup() {
        let dir = tempfile::tempdir().unwrap();
        let form =
            sepval_common::table_form::table_form(&Scenario::embedded_default(), true).unwrap();
        for (p, text) in &form.files {
            std::fs::create_dir_all(dir.path().join(p).parent().unwrap()).unwrap();
            std::fs::write(dir.path().join(p), text).unwrap();
        }
        let path = dir.path().join("scenario.toml");
        std::fs::write(&path, form.scenario.to_toml_string()).unwrap();
        let scenario = Scenario::load(&path).unwrap();
        let j = Job::single(
            "tables",
            &scenario,
            sepval_common::synthetic::default_flight_test(),
        );
        let (h, bytes) = encode_setup(&j);
        drop(dir); // the files are gone: the setup must not need them
        let back = decode_setup(&h, &bytes).unwrap();
        assert_eq!(back.scenario_sha256(), j.scenario_sha256());
        let sim = &back.events()[0].simulator;
        assert_eq!(sim.scenario(), &scenario);
        let f = sepval_core::factors::Factors::TRUTH;
        let none = sepval_common::effects::EffectSet::NONE;
        let times = sim.default_times();
        assert_eq!(
            sim.simulate(&f, &none, &times).unwrap(),
            j.events()[0].simulator.simulate(&f, &none, &times).unwrap()
        );
    }

    /// A count of events is refused at the first event that does not decode, with nothing
    /// allocated for the others (found by `fuzz_tests::setup_mutations`: 4096 events of 24
    /// bytes each allocated 4.8 MB up front, 48 times the bytes present).
    #[test]
    fn a_count_of_events_allocates_nothing_up_front() {
        let mut bytes = (MAX_EVENTS as u64).to_le_bytes().to_vec();
        bytes.resize(8 + 24 * MAX_EVENTS, 0);
        let header = SetupHeader {
            magic: MAGIC,
            protocol: PROTOCOL_VERSION,
            reserved: 0,
            len: bytes.len() as u64,
            sha256: sha256(&bytes),
            catalogue: catalogue_bytes(),
        };
        let (result, cost) = sepval_tests::fuzz::measure(|| decode_setup(&header, &bytes));
        let e = crate::error_chain(&result.unwrap_err());
        assert!(
            e.starts_with("setup event ``: scenario : line 1, column 1: "),
            "{e}"
        );
        // The test binary counts allocations (crate::fuzz_tests).
        assert!(cost.largest_allocation < bytes.len(), "{cost:?}");
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
        let mut catalogue = h;
        catalogue.catalogue[0] ^= 1;
        assert!(matches!(
            decode_setup(&catalogue, &bytes),
            Err(SetupError::Catalogue)
        ));
    }
}
