//! `sepval-worker`: the simulation server of a distributed fit. It receives the job setup
//! (scenario and measured data) and batches of factor sets from a coordinator and answers with
//! goals. The transport arrives with the iceoryx2 issue; until then this binary only
//! describes itself.

use std::process::ExitCode;

use clap::Parser;

#[derive(Parser)]
#[command(
    name = "sepval-worker",
    version,
    about = "Runs store-separation simulations for a sepval coordinator",
    long_about = "Runs store-separation simulations for a sepval coordinator. Workers are started \
                  by `sepval fit --workers N`; the shared-memory transport that connects them \
                  is not built yet, so this binary has no work mode."
)]
struct Cli {}

fn main() -> ExitCode {
    let _ = Cli::parse();
    eprintln!("sepval-worker: no transport is built yet; start workers through `sepval fit`.");
    ExitCode::from(2)
}
