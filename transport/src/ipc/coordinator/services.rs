//! The run's services as the coordinator holds them ([`RunServices`]): the subscriber to
//! `sepval/run/hello`, the listener of `sepval/run/coordinator-wake`, and the job setup on offer
//! on `sepval/run/setup` ([`SetupOffer`]). The coordinator creates them; workers open them (see
//! the table in [`crate::ipc`]).

use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory;
use sepval_common::evaluation::Job;

use super::super::{MAX_WORKERS, names, service_name};
use crate::setup::encode_setup_as;
use crate::wire::{Hello, SetupHeader};
use crate::{TransportError, iox};

/// The run's services, coordinator side.
pub(super) struct RunServices {
    /// The job setup for joining workers.
    pub(super) setup: SetupOffer,
    /// Workers announcing themselves.
    pub(super) hello: Subscriber<ipc::Service, Hello, ()>,
    /// "Answers are waiting", from any worker.
    pub(super) wake: Listener<ipc::Service>,
}

/// The job setup on offer: the setup service and, while workers may still join, its publisher
/// (its one sample, in the service's history, is as large as the data; it is dropped once every
/// worker has joined and made again for a replacement).
pub(super) struct SetupOffer {
    service: PortFactory<ipc::Service, [u8], SetupHeader>,
    publisher: Option<Publisher<ipc::Service, [u8], SetupHeader>>,
}

impl RunServices {
    /// Creates the run's services on `node`, room for [`MAX_WORKERS`] workers and a few
    /// replacements. The setup service comes last: a worker that finds it finds every run
    /// service. Nothing is published yet.
    pub(super) fn create(node: &Node<ipc::Service>) -> Result<RunServices, TransportError> {
        let hello = node
            .service_builder(&service_name(names::HELLO)?)
            .publish_subscribe::<Hello>()
            .max_publishers(MAX_WORKERS + 8)
            .max_subscribers(1)
            .subscriber_max_buffer_size(MAX_WORKERS + 8)
            .history_size(0)
            .create()
            .map_err(iox("creating the hello service"))?
            .subscriber_builder()
            .create()
            .map_err(iox("subscribing to hellos"))?;
        let wake = node
            .service_builder(&service_name(names::COORDINATOR_WAKE)?)
            .event()
            .max_notifiers(MAX_WORKERS + 8)
            .max_listeners(1)
            .create()
            .map_err(iox("creating the coordinator's wake-up service"))?
            .listener_builder()
            .create()
            .map_err(iox("listening for wake-ups"))?;
        let service = node
            .service_builder(&service_name(names::SETUP)?)
            .publish_subscribe::<[u8]>()
            .user_header::<SetupHeader>()
            .max_publishers(1)
            .max_subscribers(MAX_WORKERS + 8)
            .history_size(1)
            .subscriber_max_buffer_size(1)
            .create()
            .map_err(iox("creating the setup service"))?;
        Ok(RunServices {
            setup: SetupOffer {
                service,
                publisher: None,
            },
            hello,
            wake,
        })
    }
}

impl SetupOffer {
    /// Publishes the setup of `job`, announcing `protocol`, unless it is already on offer
    /// (once per publisher: it stays in the service's history).
    pub(super) fn publish(&mut self, job: &Job, protocol: u32) -> Result<(), TransportError> {
        if self.publisher.is_some() {
            return Ok(());
        }
        let (header, bytes) = encode_setup_as(job, protocol);
        let publisher = self
            .service
            .publisher_builder()
            .initial_max_slice_len(bytes.len())
            .create()
            .map_err(iox("publishing the setup"))?;
        let mut sample = publisher
            .loan_slice_uninit(bytes.len())
            .map_err(iox("loaning the setup"))?;
        *sample.user_header_mut() = header;
        sample
            .write_from_slice(&bytes)
            .send()
            .map_err(iox("sending the setup"))?;
        self.publisher = Some(publisher);
        Ok(())
    }

    /// Delivers the setup to newly subscribed workers (from the service's history), if it is on
    /// offer.
    pub(super) fn deliver(&self) -> Result<(), TransportError> {
        if let Some(publisher) = &self.publisher {
            publisher
                .update_connections()
                .map_err(iox("delivering the setup"))?;
        }
        Ok(())
    }

    /// Takes the setup off offer (drops the publisher and its sample).
    pub(super) fn retire(&mut self) {
        self.publisher = None;
    }
}
