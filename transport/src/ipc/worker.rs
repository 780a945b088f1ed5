//! A worker's end of the iceoryx2 transport: [`IpcWorker`].
//!
//! A worker joins the run it is told (the run's own prefix), creates its request, response,
//! sample and wake-up services (named by its node id), reads the job setup from the run's setup
//! service (checking its protocol version, catalogue and SHA-256 before decoding it), and only
//! then announces itself on `sepval/run/hello`. Between chunks it sleeps on its wake-up listener
//! (an idle worker uses no CPU), checking every 500 ms that its coordinator is still alive and
//! whether a signal asked it to stop. The last process of a run removes the run's resources as
//! it leaves.

use std::sync::Arc;
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::node::Node;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use sepval_common::evaluation::Job;
use sepval_core::cancel;

use super::{
    COORDINATOR_NODE, REQUEST_BUFFER, WORKER_NODE, create_chunk_service, names, node, presence,
    service_name,
};
use crate::link::{Incoming, Stopped, WorkerLink};
use crate::setup::{check_setup_header, decode_setup, hex};
use crate::wire::{
    Answer, Chunk, ChunkHeader, Hello, MAGIC, PROTOCOL_VERSION, SetupHeader, WireObservation,
    WireRequest, WireResponse,
};
use crate::{RunId, TransportError, iox};

/// How often an idle worker checks that its coordinator is still alive.
const LIVENESS_TICK: Duration = Duration::from_millis(500);

/// A worker's end of the iceoryx2 transport, joined to a run.
pub struct IpcWorker {
    run_id: RunId,
    cfg: Config,
    job: Arc<Job>,
    own: OwnServices,
    coordinator_wake: Notifier<ipc::Service>,
    /// Kept alive: a dropped publisher takes its unread hello with it.
    _hello: Publisher<ipc::Service, Hello, ()>,
    checked: Instant,
    _node: Node<ipc::Service>,
    /// Dropped last: the last process of a run leaves nothing behind on the host.
    _cleanup: super::RunCleanup,
}

/// Retries `f` until it succeeds or `deadline` passes (then returns its last error).
fn retry_until<T>(
    deadline: Instant,
    mut f: impl FnMut() -> Result<T, TransportError>,
) -> Result<T, TransportError> {
    loop {
        match f() {
            Ok(v) => return Ok(v),
            Err(e) if Instant::now() >= deadline => return Err(e),
            Err(_) => {
                cancel::check()?;
                std::thread::sleep(Duration::from_millis(20));
            }
        }
    }
}

/// This worker's own services (named by its node id), created before it announces itself.
struct OwnServices {
    requests: Subscriber<ipc::Service, [WireRequest], ChunkHeader>,
    responses: Publisher<ipc::Service, [WireResponse], ChunkHeader>,
    samples: Publisher<ipc::Service, [WireObservation], ChunkHeader>,
    wake: Listener<ipc::Service>,
}

impl OwnServices {
    /// Creates the services of the worker whose node id is `id` on `node`.
    fn create(node: &Node<ipc::Service>, id: u128) -> Result<OwnServices, TransportError> {
        let requests = create_chunk_service::<WireRequest>(node, &names::requests(id))?
            .subscriber_builder()
            .buffer_size(REQUEST_BUFFER)
            .create()
            .map_err(iox("subscribing to requests"))?;
        let responses = create_chunk_service::<WireResponse>(node, &names::responses(id))?
            .publisher_builder()
            .initial_max_slice_len(64)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(iox("publishing responses"))?;
        let samples = create_chunk_service::<WireObservation>(node, &names::samples(id))?
            .publisher_builder()
            .initial_max_slice_len(1024)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(iox("publishing samples"))?;
        let wake = node
            .service_builder(&service_name(&names::wake(id))?)
            .event()
            .max_notifiers(1)
            .max_listeners(1)
            .create()
            .map_err(iox("creating the wake-up service"))?
            .listener_builder()
            .create()
            .map_err(iox("listening for wake-ups"))?;
        Ok(OwnServices {
            requests,
            responses,
            samples,
            wake,
        })
    }
}

/// Joining a run's services (the coordinator creates them): the run, and the one deadline of
/// every wait until this worker has announced itself.
struct Joining<'a> {
    run_id: &'a RunId,
    setup_timeout: Duration,
    deadline: Instant,
}

impl Joining<'_> {
    /// Subscribes to the job setup (its service is the last the coordinator creates): no setup
    /// service by the deadline means no coordinator.
    fn subscribe_setup(
        &self,
        node: &Node<ipc::Service>,
    ) -> Result<Subscriber<ipc::Service, [u8], SetupHeader>, TransportError> {
        retry_until(self.deadline, || {
            node.service_builder(&service_name(names::SETUP)?)
                .publish_subscribe::<[u8]>()
                .user_header::<SetupHeader>()
                .open()
                .map_err(iox("opening the setup service"))
        })
        .map_err(|_| TransportError::NoCoordinator {
            run: self.run_id.to_string(),
            place: "on this host".to_string(),
            seconds: self.setup_timeout.as_secs_f64(),
        })?
        .subscriber_builder()
        .history_request(1)
        .create()
        .map_err(iox("subscribing to the setup"))
    }

    /// A notifier of the coordinator's wake-up.
    fn notify_coordinator(
        &self,
        node: &Node<ipc::Service>,
    ) -> Result<Notifier<ipc::Service>, TransportError> {
        retry_until(self.deadline, || {
            node.service_builder(&service_name(names::COORDINATOR_WAKE)?)
                .event()
                .open()
                .map_err(iox("opening the coordinator's wake-up service"))
        })?
        .notifier_builder()
        .create()
        .map_err(iox("notifying the coordinator"))
    }

    /// The job setup (delivered from the service's history), checked and decoded. A setup we
    /// refuse ends the worker at once.
    fn receive_setup(
        &self,
        setup: &Subscriber<ipc::Service, [u8], SetupHeader>,
    ) -> Result<Job, TransportError> {
        let refuse = |reason: String| TransportError::SetupRefused {
            run: self.run_id.to_string(),
            reason,
        };
        loop {
            if let Some(sample) = setup.receive().map_err(iox("receiving the setup"))? {
                let header: SetupHeader = *sample.user_header();
                check_setup_header(&header).map_err(|e| refuse(e.to_string()))?;
                return decode_setup(&header, sample.payload()).map_err(|e| {
                    refuse(format!(
                        "setup {}: {}",
                        hex(&header.sha256),
                        crate::error_chain(&e)
                    ))
                });
            }
            if Instant::now() >= self.deadline {
                return Err(refuse(format!(
                    "no job setup arrived within {} s",
                    self.setup_timeout.as_secs_f64()
                )));
            }
            cancel::check()?;
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Announces this worker on the hello service; the publisher is kept alive by the caller
    /// (a dropped publisher takes its unread hello with it).
    fn announce(
        &self,
        node: &Node<ipc::Service>,
        hello: Hello,
    ) -> Result<Publisher<ipc::Service, Hello, ()>, TransportError> {
        let publisher = retry_until(self.deadline, || {
            node.service_builder(&service_name(names::HELLO)?)
                .publish_subscribe::<Hello>()
                .open()
                .map_err(iox("opening the hello service"))
        })?
        .publisher_builder()
        .create()
        .map_err(iox("publishing hello"))?;
        publisher.send_copy(hello).map_err(iox("sending hello"))?;
        Ok(publisher)
    }
}

impl IpcWorker {
    /// Joins run `run_id`: creates this worker's services, waits up to `setup_timeout` for the
    /// coordinator's setup, checks and decodes it, and announces this worker (announcing
    /// `announce_protocol` instead of ours, for compatibility tests).
    pub fn join(
        run_id: RunId,
        setup_timeout: Duration,
        announce_protocol: Option<u32>,
    ) -> Result<IpcWorker, TransportError> {
        let cfg = super::run_config(&run_id)?;
        let node = node(&cfg, WORKER_NODE)?;
        let id = node.id().value();
        let own = OwnServices::create(&node, id)?;
        let joining = Joining {
            run_id: &run_id,
            setup_timeout,
            deadline: Instant::now() + setup_timeout,
        };
        let setup = joining.subscribe_setup(&node)?;
        let coordinator_wake = joining.notify_coordinator(&node)?;
        // We announce ourselves only once we have accepted the setup.
        let job = joining.receive_setup(&setup)?;
        let hello = joining.announce(
            &node,
            Hello {
                magic: MAGIC,
                protocol: announce_protocol.unwrap_or(PROTOCOL_VERSION),
                pid: std::process::id(),
                node_id: id,
            },
        )?;
        let _ = coordinator_wake.notify();
        Ok(IpcWorker {
            run_id: run_id.clone(),
            cfg,
            job: Arc::new(job),
            own,
            coordinator_wake,
            _hello: hello,
            checked: Instant::now(),
            _node: node,
            _cleanup: super::RunCleanup(run_id),
        })
    }

    /// The job of the accepted setup.
    pub fn job(&self) -> &Arc<Job> {
        &self.job
    }

    fn take(&mut self) -> Result<Option<Chunk>, TransportError> {
        Ok(self
            .own
            .requests
            .receive()
            .map_err(iox("receiving requests"))?
            .map(|s| Chunk {
                header: *s.user_header(),
                requests: s.payload().to_vec(),
            }))
    }
}

impl WorkerLink for IpcWorker {
    fn receive(&mut self, timeout: Duration) -> Result<Incoming, TransportError> {
        if cancel::requested() {
            return Ok(Incoming::Stop(Stopped::Signal));
        }
        if let Some(c) = self.take()? {
            return Ok(Incoming::Chunk(c));
        }
        if timeout.is_zero() {
            return Ok(Incoming::Idle);
        }
        // Events are not latched: the requests were drained above before sleeping.
        // A signal interrupts the wait (sockets with a timeout are not restarted): the flag is
        // checked right after.
        match self.own.wake.timed_wait(|_| {}, timeout.min(LIVENESS_TICK)) {
            Ok(_) | Err(ListenerWaitError::InterruptSignal) => {}
            Err(e) => return Err(iox("waiting for requests")(e)),
        }
        if cancel::requested() {
            return Ok(Incoming::Stop(Stopped::Signal));
        }
        if self.checked.elapsed() >= LIVENESS_TICK {
            self.checked = Instant::now();
            if presence(&self.cfg, COORDINATOR_NODE)?.alive == 0 {
                return Ok(Incoming::Stop(Stopped::CoordinatorGone(
                    self.run_id.to_string(),
                )));
            }
        }
        Ok(self.take()?.map_or(Incoming::Idle, Incoming::Chunk))
    }

    fn answer(&mut self, answer: &Answer) -> Result<(), TransportError> {
        // Samples first: the coordinator reads them when it reads the responses.
        if answer.header.with_samples != 0 {
            let mut s = self
                .own
                .samples
                .loan_slice_uninit(answer.samples.len())
                .map_err(iox("loaning a sample chunk"))?;
            *s.user_header_mut() = answer.header;
            s.write_from_fn(|i| answer.samples[i])
                .send()
                .map_err(iox("sending samples"))?;
        }
        let mut s = self
            .own
            .responses
            .loan_slice_uninit(answer.responses.len())
            .map_err(iox("loaning a response chunk"))?;
        *s.user_header_mut() = answer.header;
        s.write_from_fn(|i| answer.responses[i])
            .send()
            .map_err(iox("sending responses"))?;
        let _ = self.coordinator_wake.notify();
        Ok(())
    }
}
