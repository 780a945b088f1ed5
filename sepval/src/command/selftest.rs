//! `sepval selftest`: the Pareto machinery on problems with known fronts.

use anyhow::Result;
use sepval_solve::zdt::{Zdt, run_zdt};

use crate::cli::{SelftestCommand, ZdtArg};

/// Runs `sepval selftest`.
pub fn run(command: SelftestCommand) -> Result<()> {
    let SelftestCommand::Zdt {
        problem,
        evaluations,
        seed,
        bits,
    } = command;
    if !(1..=52).contains(&bits) {
        anyhow::bail!("--bits {bits}: expected 1 to 52");
    }
    let (name, zdt) = match problem {
        ZdtArg::Zdt1 => ("zdt1", Zdt::Zdt1),
        ZdtArg::Zdt2 => ("zdt2", Zdt::Zdt2),
        ZdtArg::Zdt3 => ("zdt3", Zdt::Zdt3),
    };
    let (hv, front) = run_zdt(zdt, evaluations, seed, bits)?;
    say!("{hv:.6}");
    note!(
        "{name}: {} points on the final front, seed {seed}",
        front.len()
    );
    Ok(())
}
