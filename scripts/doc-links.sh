#!/usr/bin/env bash
# The API docs without broken links: rustdoc with warnings as errors (a link to a private or
# missing item fails). Not in .ci/run, for the cold CI's 15 minutes (docs/performance.md, CI);
# run it before a change to the crates' docs lands. In the release profile, as .ci/run's lints,
# so that after .ci/run it only documents the workspace's crates (about 35 s).
set -euo pipefail
cd "$(dirname "$0")/.."
RUSTDOCFLAGS="-D warnings" cargo doc --release --workspace --no-deps --features zenoh
