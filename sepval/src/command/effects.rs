//! `sepval effects`: the effect catalogue.

use sepval_common::effects::CATALOGUE;

/// Runs `sepval effects`.
pub fn run() {
    say!("Effect catalogue (docs/model.md section 7): physics the baseline model leaves out.");
    say!("Give one to `sepval simulate` as --effect ID=V1,V2,... in the units below.\n");
    for e in CATALOGUE.iter() {
        say!("{}", e.id());
        say!("    adds: {}", e.adds());
        for p in e.params() {
            say!(
                "    {:<9} [{}]  neutral {}, fit range [{}, {}]",
                p.name,
                p.unit,
                p.neutral,
                p.min,
                p.max
            );
        }
    }
}
