#!/bin/sh
# The separation envelope from a fresh clone, in one command:
#
#     sh examples/envelope.sh [OUT]
#
# builds sepval, fits the 17 factors to the embedded default flight test (the Eglin benchmark
# store, ga+lm so the fit has a covariance), and maps the store's clearance to the example
# wing-and-pylon aircraft over Mach 0.6-0.95 and 1-9 km with 1 000 samples per condition.
# OUT (default envelope-example) receives fit/ and envelope/; open envelope/report.html.
set -eu
cd "$(dirname "$0")/.."
out=${1:-envelope-example}
cargo build --release --quiet
sepval=target/release/sepval
"$sepval" fit --method ga+lm --out "$out/fit" --overwrite
"$sepval" envelope --from "$out/fit" --aircraft examples/geometry/aircraft.toml \
    --mach 0.6:0.95:10 --altitude-m 1000:9000:10 --out "$out/envelope" --overwrite
