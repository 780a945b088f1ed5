//! `sepval aero`: the flags made into a [`sepval_aero::Request`] (the store TOML read by
//! `sepval-geometry`, the grids checked), the estimate asked of [`sepval_aero::estimate`] and
//! written by [`sepval_aero::output::write_dir`] into a new directory (docs/aero.md).

use anyhow::Result;
use sepval_aero::{Request, grid, output};
use sepval_geometry::StoreShape;

use crate::cli::AeroArgs;

/// Runs `sepval aero`.
pub fn run(args: AeroArgs) -> Result<()> {
    let request = Request {
        shape: StoreShape::read(&args.store_shape)?,
        mach: grid::parse("--mach", &args.mach, grid::MACH_DOMAIN)?,
        alpha_deg: grid::parse("--alpha-deg", &args.alpha_deg, grid::ALPHA_DOMAIN_DEG)?,
        altitude_m: args.altitude_m,
    };
    let estimate = sepval_aero::estimate(&request)?;
    output::write_dir(&estimate, &args.out)?;
    say!("{}", output::summary(&estimate).trim_end());
    say!(
        "wrote {}: aero.toml ([aero] tables), store.dml (DAVE-ML with uncertainties), summary.txt",
        args.out.display()
    );
    Ok(())
}
