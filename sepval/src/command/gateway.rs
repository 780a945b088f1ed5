//! `sepval gateway`: one host's gateway into a zenoh run, served by local iceoryx2 workers.

use anyhow::Result;

use crate::cli::GatewayArgs;

/// Runs `sepval gateway`.
#[cfg(feature = "zenoh")]
pub fn run(args: GatewayArgs) -> Result<()> {
    use std::sync::Arc;

    use sepval_transport::RunId;
    use sepval_transport::dispatch::DispatchOptions;
    use sepval_transport::ipc::{IpcOptions, Launch};
    use sepval_transport::serve::serve;
    use sepval_transport::zenoh::{Gateway, JoinOptions, ZenohWorker};

    use super::{count, notices, seconds, worker_executable};

    let workers = count("--workers", args.workers)?;
    let chunk_deadline = seconds("--worker-timeout", args.worker_timeout)?;
    let setup_timeout = seconds("--setup-timeout", args.setup_timeout)?;
    let executable = worker_executable()?;
    let mut link = ZenohWorker::join(JoinOptions {
        endpoint: args.connect.clone(),
        run_id: args.run.clone(),
        setup_timeout,
        zenoh_config: args.zenoh_config.clone(),
        announce_protocol: None,
    })?;
    let job = Arc::clone(link.job());
    let local_run = RunId::fresh();
    let join_timeout = std::time::Duration::from_secs(60);
    let ipc = IpcOptions {
        run_id: local_run.clone(),
        workers,
        launch: Launch::Spawn { executable },
        max_respawns: 2 * workers + 2,
        join_timeout,
        announce_protocol: None,
    };
    let dispatch = DispatchOptions {
        min_workers: workers,
        join_timeout,
        chunk_deadline,
    };
    let mut gateway = Gateway::start(ipc, dispatch, job, notices())?;
    note!(
        "sepval gateway: joined run {} at {} as {}, serving with {workers} local worker(s) \
         (iceoryx2 run {local_run})",
        args.run,
        args.connect,
        link.worker_id()
    );
    let stopped = serve(&mut link, &mut gateway)?;
    note!("sepval gateway: {stopped}");
    Ok(())
}

/// Runs `sepval gateway`.
#[cfg(not(feature = "zenoh"))]
pub fn run(_: GatewayArgs) -> Result<()> {
    anyhow::bail!(
        "gateway: this sepval was built without the zenoh transport; rebuild with \
         `cargo build --release --features zenoh`"
    )
}
