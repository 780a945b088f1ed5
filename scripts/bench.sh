#!/usr/bin/env bash
# Throughput per worker count for each transport (scalar, single, pool, ipc, uds, zenoh), and the
# criterion benchmarks of one simulation (scalar) and of one run in a lane batch (simulate_lanes). Writes bench-out/bench/bench.csv and bench.png (an earlier run there replaced).
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --workspace --features zenoh
cargo bench -p sepval-common --bench simulate -- --output-format bencher
./target/release/sepval bench --workers "${WORKERS:-1,2,4}" --evals "${EVALS:-4000}" --repeat "${REPEAT:-3}" --overwrite --out "${OUT:-bench-out/bench}"
