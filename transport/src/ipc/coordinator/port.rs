//! The coordinator's connection to one worker: [`Port`], the worker's own request, response,
//! sample and wake-up services (named by its node id, see the table in [`crate::ipc`]) opened
//! from the coordinator's side, and the worker's process when the coordinator spawned it.
//!
//! What the link needs of one worker lives here: connecting to it once it said hello, sending it
//! a chunk, reading its answers, and telling whether it is gone.

use std::process::Child;

use iceoryx2::node::Node;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;

use super::super::{REQUEST_BUFFER, names, open_chunk_service, service_name};
use crate::link::SendError;
use crate::wire::{Answer, Chunk, ChunkHeader, Hello, WireObservation, WireRequest, WireResponse};
use crate::{TransportError, iox};

/// One connected worker's ports.
pub(super) struct Port {
    pub(super) node_id: u128,
    pub(super) pid: u32,
    /// Its process, if the coordinator spawned it (attached workers have none).
    pub(super) child: Option<Child>,
    requests: Publisher<ipc::Service, [WireRequest], ChunkHeader>,
    responses: Subscriber<ipc::Service, [WireResponse], ChunkHeader>,
    samples: Subscriber<ipc::Service, [WireObservation], ChunkHeader>,
    wake: Notifier<ipc::Service>,
}

/// What one read of a worker's responses found.
pub(super) enum Received {
    /// A whole answer (with its samples when its header says it has them).
    Answer(Answer),
    /// Responses whose header promises samples that did not come: the worker is broken.
    WithoutSamples,
}

impl Port {
    /// Opens the services of the worker that said `hello` (it created them before it did).
    pub(super) fn connect(
        node: &Node<ipc::Service>,
        hello: &Hello,
        child: Option<Child>,
    ) -> Result<Port, TransportError> {
        let id = hello.node_id;
        let requests = open_chunk_service::<WireRequest>(node, &names::requests(id))?
            .publisher_builder()
            .initial_max_slice_len(16)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .max_loaned_samples(2)
            .create()
            .map_err(iox("publishing requests"))?;
        let responses = open_chunk_service::<WireResponse>(node, &names::responses(id))?
            .subscriber_builder()
            .buffer_size(REQUEST_BUFFER)
            .create()
            .map_err(iox("subscribing to responses"))?;
        let samples = open_chunk_service::<WireObservation>(node, &names::samples(id))?
            .subscriber_builder()
            .buffer_size(REQUEST_BUFFER)
            .create()
            .map_err(iox("subscribing to samples"))?;
        let wake = node
            .service_builder(&service_name(&names::wake(id))?)
            .event()
            .open()
            .map_err(iox("opening a worker's wake-up"))?
            .notifier_builder()
            .create()
            .map_err(iox("notifying a worker"))?;
        Ok(Port {
            node_id: id,
            pid: hello.pid,
            child,
            requests,
            responses,
            samples,
            wake,
        })
    }

    /// Sends `chunk` and wakes the worker. An error means the worker cannot be reached.
    pub(super) fn send(&mut self, chunk: &Chunk) -> Result<(), SendError> {
        let mut sample = self
            .requests
            .loan_slice_uninit(chunk.requests.len())
            .map_err(|e| SendError::Refused {
                what: "loaning a request chunk: ",
                detail: format!("{e:?}"),
            })?;
        *sample.user_header_mut() = chunk.header;
        sample
            .write_from_fn(|k| chunk.requests[k])
            .send()
            .map_err(|e| SendError::Refused {
                what: "sending a request chunk: ",
                detail: format!("{e:?}"),
            })?;
        let _ = self.wake.notify();
        Ok(())
    }

    /// The next answer waiting, if any. The worker sends an answer's samples before its
    /// responses, so they are read together.
    pub(super) fn receive(&mut self) -> Result<Option<Received>, TransportError> {
        let Some(sample) = self.responses.receive().map_err(iox("receiving answers"))? else {
            return Ok(None);
        };
        let header = *sample.user_header();
        let samples = if header.with_samples != 0 {
            match self.samples.receive().map_err(iox("receiving samples"))? {
                Some(s) => s.payload().to_vec(),
                None => return Ok(Some(Received::WithoutSamples)),
            }
        } else {
            Vec::new()
        };
        Ok(Some(Received::Answer(Answer {
            header,
            responses: sample.payload().to_vec(),
            samples,
        })))
    }

    /// Why this worker is gone, if it is: its process exited (spawned workers), or its node is
    /// missing from `alive`, the run's alive nodes when they were just listed (attached workers).
    pub(super) fn gone(&mut self, alive: Option<&[u128]>) -> Option<String> {
        match self.child.as_mut().map(Child::try_wait) {
            Some(Ok(Some(status))) => Some(format!("process exited: {status}")),
            _ if self.child.is_none() && alive.is_some_and(|a| !a.contains(&self.node_id)) => {
                Some("its node is dead".to_string())
            }
            _ => None,
        }
    }
}
