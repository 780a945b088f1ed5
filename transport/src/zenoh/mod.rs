//! Workers on other hosts: the zenoh transport (cargo feature `zenoh`), the coordinator's
//! [`ZenohLink`] and the worker's [`ZenohWorker`], and the gateway ([`Gateway`]) that serves a
//! zenoh run with a host's iceoryx2 workers.
//!
//! iceoryx2 is shared memory on one host, so scale-out across hosts uses Eclipse zenoh 1.10
//! (<https://zenoh.io>) behind the same [`Link`](crate::link::Link). The coordinator listens on
//! one explicit endpoint (`tcp/ADDR:PORT`); every worker connects to it. Both run zenoh in peer
//! mode with multicast scouting and gossip switched off, so a session talks only to the
//! endpoints it is given (see docs/guide.md, "Workers on other hosts").
//!
//! Key expressions of run `R` (a run id is `[A-Za-z0-9-]`, so it is one key chunk):
//!
//! | key                          | what                                                      |
//! |------------------------------|-----------------------------------------------------------|
//! | `sepval/R/setup`             | queryable of the coordinator: the job setup (a [`Frame::Setup`]) |
//! | `sepval/R/coordinator`       | liveliness token of the coordinator                       |
//! | `sepval/R/worker/W`          | liveliness token of worker `W` (its zenoh session id)     |
//! | `sepval/R/up/W`              | worker `W` to the coordinator (`Ready`, `Answer` frames)  |
//! | `sepval/R/down/W`            | the coordinator to worker `W` (`Chunk`, `Quit`, `Dropped`) |
//!
//! Work is pulled: a worker announces how many chunks it can hold (`Ready`) and every answer
//! hands one credit back, so the coordinator sends a chunk only to a worker that asked for one
//! and fast hosts take more chunks than slow ones. A worker whose liveliness token disappears
//! (process killed, host or link down) loses its in-flight chunks to the others. Every message
//! is a [`Frame`] of [`crate::codec`]: magic and protocol version first, checked before the body
//! is read, so two versions refuse each other by name.

mod coordinator;
mod gateway;
mod worker;

pub use coordinator::{ZenohLink, ZenohOptions};
pub use gateway::Gateway;
pub use worker::{JoinOptions, ZenohWorker};

use zenoh::Wait;

use crate::TransportError;
#[allow(unused_imports)]
use crate::codec::Frame;

/// Maps a zenoh error into [`TransportError::Zenoh`] with what we were doing.
pub fn zerr(context: impl Into<String>) -> impl FnOnce(zenoh::Error) -> TransportError {
    let context = context.into();
    move |e| TransportError::Zenoh {
        context,
        message: e.to_string(),
    }
}

/// Checks an endpoint given on the command line: `PROTOCOL/HOST:PORT`, port not 0 (workers must
/// know where to connect).
pub fn validate_endpoint(endpoint: &str) -> Result<(), TransportError> {
    let bad = || TransportError::Endpoint {
        endpoint: endpoint.to_string(),
    };
    let (proto, addr) = endpoint.split_once('/').ok_or_else(bad)?;
    if proto.is_empty() || !proto.chars().all(|c| c.is_ascii_alphanumeric()) {
        return Err(bad());
    }
    let addr = addr.split('#').next().unwrap_or_default();
    let (host, port) = addr.rsplit_once(':').ok_or_else(bad)?;
    match port.parse::<u16>() {
        Ok(p) if p > 0 && !host.is_empty() => Ok(()),
        _ => Err(bad()),
    }
}

/// Key expressions of a run.
pub mod keys {
    /// The setup queryable.
    pub fn setup(run: &str) -> String {
        format!("sepval/{run}/setup")
    }
    /// The coordinator's liveliness token.
    pub fn coordinator(run: &str) -> String {
        format!("sepval/{run}/coordinator")
    }
    /// A worker's liveliness token.
    pub fn worker(run: &str, worker: &str) -> String {
        format!("sepval/{run}/worker/{worker}")
    }
    /// Every worker's liveliness token.
    pub fn workers(run: &str) -> String {
        format!("sepval/{run}/worker/*")
    }
    /// Messages from a worker.
    pub fn up(run: &str, worker: &str) -> String {
        format!("sepval/{run}/up/{worker}")
    }
    /// Messages from every worker.
    pub fn ups(run: &str) -> String {
        format!("sepval/{run}/up/*")
    }
    /// Messages to a worker.
    pub fn down(run: &str, worker: &str) -> String {
        format!("sepval/{run}/down/{worker}")
    }
    /// The last chunk of a key (the worker id of a worker key).
    pub fn last(key: &str) -> &str {
        key.rsplit('/').next().unwrap_or(key)
    }
}

/// Which side of the transport a session is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// The coordinator: listens on the endpoint.
    Listen,
    /// A worker: connects to the endpoint.
    Connect,
}

/// The zenoh configuration of a session: `base` (a zenoh JSON5 configuration file, e.g. with
/// TLS certificates, or zenoh's defaults), then peer mode, multicast scouting and gossip off,
/// and exactly one endpoint to listen on or connect to. A worker listens on nothing.
pub fn config(
    role: Role,
    endpoint: &str,
    base: Option<&std::path::Path>,
) -> Result<zenoh::Config, TransportError> {
    validate_endpoint(endpoint)?;
    let mut cfg = match base {
        Some(path) => zenoh::Config::from_file(path).map_err(zerr(format!(
            "reading the zenoh configuration {}",
            path.display()
        )))?,
        None => zenoh::Config::default(),
    };
    let endpoint_json = serde_json::to_string(&[endpoint]).expect("a string list serialises");
    let (listen, connect) = match role {
        Role::Listen => (endpoint_json.as_str(), "[]"),
        Role::Connect => ("[]", endpoint_json.as_str()),
    };
    let settings = [
        ("mode", "\"peer\""),
        ("scouting/multicast/enabled", "false"),
        ("scouting/gossip/enabled", "false"),
        ("listen/endpoints", listen),
        ("connect/endpoints", connect),
        // A worker started before its coordinator keeps trying to connect.
        ("connect/timeout_ms", "-1"),
        ("connect/exit_on_failure", "false"),
        // The listening endpoint is the one given, or nothing: fail loudly if it is taken.
        ("listen/exit_on_failure", "true"),
    ];
    for (key, value) in settings {
        cfg.insert_json5(key, value)
            .map_err(zerr(format!("setting {key} = {value}")))?;
    }
    Ok(cfg)
}

/// Opens a zenoh session.
pub fn open(cfg: zenoh::Config, endpoint: &str) -> Result<zenoh::Session, TransportError> {
    zenoh::open(cfg)
        .wait()
        .map_err(zerr(format!("opening a session on {endpoint}")))
}

/// This host's name, for messages.
pub fn host_name() -> String {
    std::fs::read_to_string("/proc/sys/kernel/hostname")
        .map(|s| s.trim().to_string())
        .ok()
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown-host".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_are_checked() {
        validate_endpoint("tcp/127.0.0.1:7447").unwrap();
        validate_endpoint("tcp/[::1]:7447").unwrap();
        validate_endpoint("tls/host.example:7447").unwrap();
        for bad in [
            "127.0.0.1:7447",
            "tcp/127.0.0.1",
            "tcp/127.0.0.1:0",
            "tcp/:7447",
            "tcp/h:70000",
            "/h:1",
        ] {
            assert!(validate_endpoint(bad).is_err(), "{bad}");
        }
    }
}
