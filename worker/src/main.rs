//! `sepval-worker`: the simulation server of a distributed fit.
//!
//! A worker joins the run it is told (`--run RUN_ID`: the run's own iceoryx2 prefix), creates
//! its request, response, sample and wake-up services (named by its node id), announces itself
//! on `sepval/run/hello`, reads the job setup (scenarios and measured data, with their SHA-256
//! and protocol version) from `sepval/run/setup`, and then serves chunks of candidates until the
//! coordinator is gone, it receives SIGINT/SIGTERM, or the setup is refused.
//!
//! It blocks on a WaitSet between chunks (an idle worker uses no CPU), validates every request
//! (counts, indices, finite values; factor bounds when it runs) and answers a bad one with a
//! typed failure instead of crashing. Run `iox2 service list` with the run's configuration to
//! see its services (see the README).

// The doc comments here are clap's --help text, where units read `[s]`, `[m]`; rustdoc would
// take those for links.
#![allow(rustdoc::broken_intra_doc_links)]

use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use clap::Parser;
use iceoryx2::prelude::*;
use iceoryx2::waitset::WaitSetRunResult;
use sepval_common::evaluation::{Candidate, Evaluation, Job, Outcome};
use sepval_common::ipc::{self as sipc, COORDINATOR_NODE, REQUEST_BUFFER, WORKER_NODE, names};
use sepval_common::messages::{
    ChunkHeader, Hello, MAGIC, PROTOCOL_VERSION, SetupHeader, WireObservation, WireRequest,
    WireResponse, check_setup_header, decode_setup, setup_hash_hex,
};

#[derive(Parser)]
#[command(
    name = "sepval-worker",
    version,
    about = "Runs store-separation simulations for a sepval coordinator",
    long_about = "Runs store-separation simulations for a sepval coordinator. `sepval fit \
                  --workers N` starts workers itself; to start them yourself (as a job scheduler \
                  would), run `sepval fit --attach RUN_ID --workers N` and then N times \
                  `sepval-worker --run RUN_ID`."
)]
#[command(group(clap::ArgGroup::new("transport").required(true).args(["run", "uds"])))]
struct Cli {
    /// The run to join (the coordinator prints it).
    #[arg(long, value_name = "RUN_ID")]
    run: Option<String>,
    /// Serve over this Unix domain socket instead (the throughput benchmark's comparison).
    #[arg(long, value_name = "PATH")]
    uds: Option<std::path::PathBuf>,
    /// Join the run over zenoh at the coordinator's endpoint (e.g. tcp/192.0.2.7:7447) instead
    /// of shared memory: for workers on other hosts (built with the `zenoh` feature).
    #[arg(long, value_name = "ENDPOINT", requires = "run")]
    connect: Option<String>,
    /// zenoh: a zenoh JSON5 configuration to start from (TLS certificates, authentication).
    #[arg(long, value_name = "FILE", requires = "connect")]
    zenoh_config: Option<std::path::PathBuf>,
    /// How long to wait for the coordinator's job setup [s].
    #[arg(long, default_value_t = 30.0, value_name = "S")]
    setup_timeout: f64,
    /// Announce this protocol version instead of our own (compatibility testing only).
    #[arg(long, hide = true)]
    announce_protocol: Option<u32>,
}

/// How often an idle worker checks that its coordinator is still alive.
const LIVENESS_TICK: Duration = Duration::from_millis(500);

fn main() -> ExitCode {
    let cli = Cli::parse();
    iceoryx2::prelude::set_log_level(LogLevel::Error);
    let result = match (&cli.run, &cli.uds) {
        (Some(run), _) if cli.connect.is_some() => serve_remote(&cli, run),
        (Some(run), _) => {
            let r = serve(&cli, run);
            // The last process of a run leaves nothing behind on the host.
            let _ = sipc::clean_run_if_stale(run);
            r
        }
        (None, Some(path)) => serve_uds(path).map(|()| None),
        (None, None) => unreachable!("clap requires one transport"),
    };
    match result {
        Ok(Some(reason)) => {
            eprintln!("sepval-worker: {reason}");
            ExitCode::SUCCESS
        }
        Ok(None) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("sepval-worker: error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// Serves the run; returns why it stopped, when that is worth saying (not for the
/// coordinator's own SIGTERM at the end of a run).
fn serve(cli: &Cli, run: &str) -> Result<Option<String>> {
    let cfg = sipc::run_config(run)?;
    let node = NodeBuilder::new()
        .config(&cfg)
        .name(&NodeName::new(WORKER_NODE).map_err(sipc::iox("node name"))?)
        .create::<ipc::Service>()
        .map_err(sipc::iox("creating the worker node"))?;
    let id = node.id().value();
    let svc = |name: &str| sipc::service_name(name);

    // Our own services, created before we announce ourselves.
    let requests = node
        .service_builder(&svc(&names::requests(id))?)
        .publish_subscribe::<[WireRequest]>()
        .user_header::<ChunkHeader>()
        .max_publishers(1)
        .max_subscribers(1)
        .subscriber_max_buffer_size(REQUEST_BUFFER)
        .enable_safe_overflow(false)
        .history_size(0)
        .create()
        .map_err(sipc::iox("creating the request service"))?;
    let request_sub = requests
        .subscriber_builder()
        .buffer_size(REQUEST_BUFFER)
        .create()
        .map_err(sipc::iox("subscribing to requests"))?;
    let responses = node
        .service_builder(&svc(&names::responses(id))?)
        .publish_subscribe::<[WireResponse]>()
        .user_header::<ChunkHeader>()
        .max_publishers(1)
        .max_subscribers(1)
        .subscriber_max_buffer_size(REQUEST_BUFFER)
        .enable_safe_overflow(false)
        .history_size(0)
        .create()
        .map_err(sipc::iox("creating the response service"))?;
    let response_pub = responses
        .publisher_builder()
        .initial_max_slice_len(64)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(sipc::iox("publishing responses"))?;
    let samples = node
        .service_builder(&svc(&names::samples(id))?)
        .publish_subscribe::<[WireObservation]>()
        .user_header::<ChunkHeader>()
        .max_publishers(1)
        .max_subscribers(1)
        .subscriber_max_buffer_size(REQUEST_BUFFER)
        .enable_safe_overflow(false)
        .history_size(0)
        .create()
        .map_err(sipc::iox("creating the sample service"))?;
    let sample_pub = samples
        .publisher_builder()
        .initial_max_slice_len(1024)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(sipc::iox("publishing samples"))?;
    let wake = node
        .service_builder(&svc(&names::wake(id))?)
        .event()
        .max_notifiers(1)
        .max_listeners(1)
        .create()
        .map_err(sipc::iox("creating the wake-up service"))?;
    let wake_listener = wake
        .listener_builder()
        .create()
        .map_err(sipc::iox("listening for wake-ups"))?;

    // The run's services (the coordinator creates them).
    let open_deadline = Instant::now() + Duration::from_secs_f64(cli.setup_timeout.max(0.1));
    let setup_service = retry_until(open_deadline, || {
        node.service_builder(&svc(names::SETUP)?)
            .publish_subscribe::<[u8]>()
            .user_header::<SetupHeader>()
            .open()
            .map_err(|e| anyhow::Error::from(sipc::iox("opening the setup service")(e)))
    })
    .with_context(|| format!("no coordinator serves run {} (is the run id right?)", run))?;
    let setup_sub = setup_service
        .subscriber_builder()
        .history_request(1)
        .create()
        .map_err(sipc::iox("subscribing to the setup"))?;
    let coordinator_wake = retry_until(open_deadline, || {
        node.service_builder(&svc(names::COORDINATOR_WAKE)?)
            .event()
            .open()
            .map_err(|e| {
                anyhow::Error::from(sipc::iox("opening the coordinator's wake-up service")(e))
            })
    })?
    .notifier_builder()
    .create()
    .map_err(sipc::iox("notifying the coordinator"))?;
    // The job setup (delivered from the service's history). A setup we refuse ends the
    // worker at once; we announce ourselves only once we have accepted it.
    let job = loop {
        if let Some(sample) = setup_sub
            .receive()
            .map_err(sipc::iox("receiving the setup"))?
        {
            let header: SetupHeader = *sample.user_header();
            check_setup_header(&header)
                .map_err(|e| anyhow::anyhow!("refusing the setup of run {}: {e}", run))?;
            break decode_setup(&header, sample.payload()).with_context(|| {
                format!(
                    "refusing the setup {} of run {}",
                    setup_hash_hex(&header),
                    run
                )
            })?;
        }
        if Instant::now() >= open_deadline {
            bail!(
                "no job setup arrived from run {} within {} s",
                run,
                cli.setup_timeout
            );
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let hello_pub = retry_until(open_deadline, || {
        node.service_builder(&svc(names::HELLO)?)
            .publish_subscribe::<Hello>()
            .open()
            .map_err(|e| anyhow::Error::from(sipc::iox("opening the hello service")(e)))
    })?
    .publisher_builder()
    .create()
    .map_err(sipc::iox("publishing hello"))?;
    hello_pub
        .send_copy(Hello {
            magic: MAGIC,
            protocol: cli.announce_protocol.unwrap_or(PROTOCOL_VERSION),
            pid: std::process::id(),
            node_id: id,
        })
        .map_err(sipc::iox("sending hello"))?;
    let _ = coordinator_wake.notify();

    let waitset = WaitSetBuilder::new()
        .create::<ipc::Service>()
        .map_err(sipc::iox("creating the wait set"))?;
    let _wake_guard = waitset
        .attach_notification(&wake_listener)
        .map_err(sipc::iox("waiting for wake-ups"))?;
    let tick = waitset
        .attach_interval(LIVENESS_TICK)
        .map_err(sipc::iox("attaching the liveness tick"))?;

    loop {
        // Serve everything waiting (events are not latched: drain before every wait).
        while let Some(chunk) = request_sub
            .receive()
            .map_err(sipc::iox("receiving requests"))?
        {
            let header = *chunk.user_header();
            let evaluations: Vec<(u64, Evaluation)> = chunk
                .payload()
                .iter()
                .map(|r| (r.index, evaluate(&job, r, header.with_samples != 0)))
                .collect();
            drop(chunk);
            publish(&response_pub, &sample_pub, &job, header, &evaluations)?;
            let _ = coordinator_wake.notify();
        }
        let mut ticked = false;
        let outcome = waitset.wait_and_process_once(|attachment| {
            if attachment.has_event_from(&tick) {
                ticked = true;
            }
            CallbackProgression::Stop
        });
        match outcome {
            Ok(WaitSetRunResult::TerminationRequest) | Ok(WaitSetRunResult::Interrupt) => {
                return Ok(None);
            }
            Ok(_) => {}
            Err(e) => bail!("waiting for requests: {e:?}"),
        }
        wake_listener
            .try_wait(|_| {})
            .map_err(sipc::iox("draining wake-ups"))?;
        if ticked && sipc::presence(&cfg, COORDINATOR_NODE)?.alive == 0 {
            return Ok(Some(format!(
                "the coordinator of run {} is gone; exiting",
                run
            )));
        }
    }
}

/// Joins a run over zenoh and serves it (see `sepval_common::remote`).
#[cfg(feature = "zenoh")]
fn serve_remote(cli: &Cli, run: &str) -> Result<Option<String>> {
    use sepval_common::remote::{JoinOptions, Local, join};
    let endpoint = cli.connect.clone().expect("checked by the caller");
    let joined = join(JoinOptions {
        endpoint: endpoint.clone(),
        run_id: run.to_string(),
        setup_timeout: Duration::from_secs_f64(cli.setup_timeout.max(0.1)),
        zenoh_config: cli.zenoh_config.clone(),
        announce_protocol: cli.announce_protocol,
    })?;
    eprintln!(
        "sepval-worker: joined run {run} at {endpoint} as {}",
        joined.worker_id()
    );
    let mut server = Local(std::sync::Arc::new(joined.job().clone()));
    let stopped = joined.serve(&mut server)?;
    Ok(Some(stopped.to_string()))
}

#[cfg(not(feature = "zenoh"))]
fn serve_remote(_: &Cli, _: &str) -> Result<Option<String>> {
    bail!(
        "--connect: this sepval-worker was built without the zenoh transport; rebuild with \
         `cargo build --release --features zenoh`"
    )
}

/// Evaluates one request; a malformed one becomes a typed failure.
fn evaluate(job: &Job, r: &WireRequest, with_samples: bool) -> Evaluation {
    let candidate: Candidate = match r.candidate() {
        Ok(c) => c,
        Err(reason) => {
            return Evaluation::from(Outcome::Failed {
                reason: format!("malformed request: {reason}"),
            });
        }
    };
    if with_samples {
        job.evaluate_with_samples(&candidate)
    } else {
        job.evaluate(&candidate)
    }
}

/// Publishes one chunk's responses (and samples when asked for).
fn publish(
    response_pub: &iceoryx2::port::publisher::Publisher<ipc::Service, [WireResponse], ChunkHeader>,
    sample_pub: &iceoryx2::port::publisher::Publisher<ipc::Service, [WireObservation], ChunkHeader>,
    job: &Job,
    header: ChunkHeader,
    evaluations: &[(u64, Evaluation)],
) -> Result<()> {
    let n = evaluations.len();
    if header.with_samples != 0 {
        let per = job.sample_count();
        let nan = WireObservation {
            pos_m: [f64::NAN; 3],
            att_deg: [f64::NAN; 3],
        };
        let mut sample = sample_pub
            .loan_slice_uninit(n * per)
            .map_err(sipc::iox("loaning a sample chunk"))?;
        *sample.user_header_mut() = ChunkHeader {
            count: n as u32,
            ..header
        };
        let flat: Vec<WireObservation> = evaluations
            .iter()
            .flat_map(|(_, e)| match &e.samples {
                Some(events) => events.iter().flatten().map(WireObservation::from).collect(),
                None => vec![nan; per],
            })
            .collect();
        let sample = sample.write_from_fn(|i| flat[i]);
        sample.send().map_err(sipc::iox("sending samples"))?;
    }
    let mut sample = response_pub
        .loan_slice_uninit(n)
        .map_err(sipc::iox("loaning a response chunk"))?;
    *sample.user_header_mut() = ChunkHeader {
        count: n as u32,
        ..header
    };
    let sample =
        sample.write_from_fn(|i| WireResponse::new(evaluations[i].0, &evaluations[i].1.outcome));
    sample.send().map_err(sipc::iox("sending responses"))?;
    Ok(())
}

/// Serves chunks received as postcard frames over a Unix domain socket until the coordinator
/// closes it.
fn serve_uds(path: &std::path::Path) -> Result<()> {
    use sepval_common::uds::{self, FromWorker, ToWorker, read_frame, write_frame};
    let mut stream = std::os::unix::net::UnixStream::connect(path)
        .with_context(|| format!("cannot connect to {}", path.display()))?;
    let job = match read_frame::<ToWorker>(&mut stream)? {
        ToWorker::Setup {
            protocol,
            sha256,
            catalogue,
            bytes,
        } => {
            let header = uds::setup_header(protocol, sha256, catalogue, bytes.len());
            decode_setup(&header, &bytes).context("refusing the setup")?
        }
        ToWorker::Chunk { .. } => bail!("expected the job setup first, received a chunk"),
    };
    loop {
        let frame = match read_frame::<ToWorker>(&mut stream) {
            Ok(f) => f,
            Err(uds::UdsError::Io(e)) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                return Ok(());
            }
            Err(e) => return Err(e.into()),
        };
        let ToWorker::Chunk {
            chunk_id,
            with_samples,
            items,
        } = frame
        else {
            bail!("received a second setup");
        };
        let items = items
            .iter()
            .map(|(index, factors, effects)| {
                let e = match uds::candidate(factors, effects) {
                    Ok(c) if with_samples => job.evaluate_with_samples(&c),
                    Ok(c) => job.evaluate(&c),
                    Err(reason) => Evaluation::from(Outcome::Failed {
                        reason: format!("malformed request: {reason}"),
                    }),
                };
                (
                    *index,
                    uds::OutcomeFrame::from(&e.outcome),
                    e.samples.as_deref().map(uds::samples_out),
                )
            })
            .collect();
        write_frame(&mut stream, &FromWorker { chunk_id, items })?;
    }
}

/// Retries `f` until it succeeds or `deadline` passes (then returns its last error).
fn retry_until<T>(deadline: Instant, mut f: impl FnMut() -> Result<T>) -> Result<T> {
    loop {
        match f() {
            Ok(v) => return Ok(v),
            Err(e) if Instant::now() >= deadline => return Err(e),
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    }
}
