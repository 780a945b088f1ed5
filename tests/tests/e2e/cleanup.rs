//! What a run killed with SIGKILL leaves on the host, and its removal: after `kill -9` of a
//! coordinator or of a worker, every file of the run (shared memory, iceoryx2's node and service
//! directories) is gone once `sepval clean-ipc` has run, or before, and a run is named cleaned
//! once, never again for resources that stay. Each test has its own run id.

use std::path::Path;
use std::time::Duration;

use sepval_tests::*;
use sepval_transport::RunId;
use sepval_transport::ipc::files_of_run;

/// Starts an iceoryx2 fit of run `run` with two spawned workers and waits for its
/// checkpoint of generation 2.
fn start_fit(dir: &Path, run: &str) -> std::process::Child {
    let fit = spawn_sepval(
        &[
            "fit",
            "--method",
            "ga",
            "--generations",
            "500",
            "--population",
            "20",
            "--no-figures",
            "--out",
            "ipc",
            "--run-id",
            run,
            "--workers",
            "2",
        ],
        dir,
    );
    let ckpt = dir.join("ipc/generations/gen-0002.json");
    wait_for("the first generations", Duration::from_secs(60), || {
        ckpt.exists()
    });
    fit
}

/// The files of run `run` on this host.
fn files(run: &str) -> Vec<std::path::PathBuf> {
    files_of_run(&RunId::new(run).unwrap())
}

/// Runs `sepval clean-ipc` and returns what it says.
fn clean_ipc(dir: &Path) -> String {
    ok(&sepval(&["clean-ipc"], dir))
}

#[test]
fn after_kill_9_of_a_coordinator_clean_ipc_removes_the_run_and_names_it_once() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_id("kill-coord");
    let mut fit = start_fit(dir.path(), &run);
    signal(fit.id() as i32, libc::SIGKILL);
    let _ = fit.wait();
    // Its workers see it gone and leave.
    wait_for("the workers to leave", Duration::from_secs(10), || {
        workers_of_run(&run).is_empty()
    });
    let left = files(&run);
    let first = clean_ipc(dir.path());
    assert_eq!(files(&run), Vec::<std::path::PathBuf>::new(), "{first}");
    let named = first.split_whitespace().filter(|w| *w == run).count();
    assert_eq!(named, usize::from(!left.is_empty()), "{left:?}\n{first}");
    // Nothing of it is left to find again.
    let second = clean_ipc(dir.path());
    assert!(!second.contains(&run), "{second}");
}

#[test]
fn after_kill_9_of_a_worker_the_run_leaves_nothing_behind() {
    let dir = tempfile::tempdir().unwrap();
    let run = run_id("kill-worker");
    let mut fit = start_fit(dir.path(), &run);
    let workers = workers_of_run(&run);
    assert_eq!(workers.len(), 2, "{workers:?}");
    signal(workers[0], libc::SIGKILL);
    // The replacement serves on; the coordinator, stopped, removes what the dead worker left.
    wait_for("the replacement worker", Duration::from_secs(30), || {
        let now = workers_of_run(&run);
        now.len() == 2 && !now.contains(&workers[0])
    });
    signal(fit.id() as i32, libc::SIGTERM);
    let out = wait_exit(&mut fit, "the fit", Duration::from_secs(30));
    assert_eq!(out.status.code(), Some(130), "{out:?}");
    assert_run_gone(&run);
    assert_eq!(files(&run), Vec::<std::path::PathBuf>::new());
    let said = clean_ipc(dir.path());
    assert!(!said.contains(&run), "{said}");
}

#[test]
fn what_iceoryx2_cannot_reach_is_removed_once() {
    // What `kill -9` of an envelope between two conditions left (issue 33, item 11): a node
    // killed between writing its details and making its monitor, a service's configuration
    // whose nodes are gone, and the run's node counter. No iceoryx2 call reaches them;
    // `clean-ipc` said it cleaned the run every time and removed nothing.
    let dir = tempfile::tempdir().unwrap();
    let run = run_id("half-made");
    let prefix = format!("sepval_{run}_");
    let id = format!("{}0000000000000000", std::process::id());
    let nodes = sepval_transport::ipc::nodes_dir();
    let services = nodes.parent().unwrap().join("services");
    std::fs::create_dir_all(nodes.join(&id)).unwrap();
    std::fs::create_dir_all(&services).unwrap();
    let made = [
        nodes.join(&id).join(format!("{prefix}node.details")),
        services.join(format!(
            "{prefix}e126c29cc6cd74da4c4813b5a015f56675139187.service"
        )),
        Path::new("/dev/shm").join(format!(
            "{prefix}9204dd183d1c4d8e1ff592a30766ffa6765aa8b5_node.0_10_0.global_mgmt"
        )),
    ];
    // Made before the grace that spares a node being made by a starting process.
    let then = std::time::SystemTime::now() - 4 * sepval_transport::ipc::LEFTOVER_GRACE;
    for f in &made {
        std::fs::write(f, b"left").unwrap();
        std::fs::File::options()
            .write(true)
            .open(f)
            .and_then(|h| h.set_modified(then))
            .unwrap();
    }
    assert_eq!(files(&run).len(), 3);
    let first = clean_ipc(dir.path());
    assert_eq!(files(&run), Vec::<std::path::PathBuf>::new(), "{first}");
    assert!(!nodes.join(&id).exists(), "the node's directory is removed");
    let named = first.split_whitespace().filter(|w| *w == run).count();
    assert_eq!(named, 1, "{first}");
    let second = clean_ipc(dir.path());
    assert!(!second.contains(&run), "{second}");
}
