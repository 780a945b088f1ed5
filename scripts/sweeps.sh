#!/usr/bin/env bash
# The statistical sweeps whole (docs/performance.md, "The sweeps"): the tests of the slow tier
# whose claim is a rate over random cases run all their cases with SEPVAL_SWEEPS=full, where
# the README's test command runs the first of them with the same assertions
# (sepval_tests::sweep_cases). These are measurements, as the benchmarks are: their figures are
# the ones the docs quote, with the date they were taken. About 35 minutes on two cores:
#
#   the closed loop after the planned release, 10 random bases   plan/tests/closing/after.rs
#   one release never a confident wrong answer, 15 cases         plan/tests/closing/after.rs
#   a short gust's onset interval, 10 seeds                      diagnose/tests/discovery/located.rs
#   the campaign beside the wall, three truths                   sepval/tests/cli/campaign_wall.rs
#
#   scripts/sweeps.sh [LOG_DIR]      (default target/sweeps; each sweep's table in NAME.log)
set -euo pipefail
cd "$(dirname "$0")/.."
logs="${1:-target/sweeps}"
mkdir -p "$logs"
export SEPVAL_SLOW_TESTS=1 SEPVAL_SWEEPS=full
cargo test --release --workspace --no-run
sweep() {
    local name=$1 package=$2 target=$3 filter=$4
    echo "== $name ($(date -u +%H:%M:%S) UTC)"
    cargo test --release -p "$package" --test "$target" -- --nocapture "$filter" \
        > "$logs/$name.log" 2>&1 || { tail -n 40 "$logs/$name.log"; exit 1; }
    grep -E '^test result|right|wrong|of 10|covered|releases' "$logs/$name.log" | tail -n 20
}
sweep after sepval-plan closing after::the_loop_keeps_its_word_on_random_bases
sweep first sepval-plan closing after::one_release_is_never_a_confident_wrong_answer
sweep located sepval-diagnose discovery located::a_short_gusts_onset
sweep wall sepval cli campaign_wall::wall_rehearsals_of_three_truths
echo "== done ($(date -u +%H:%M:%S) UTC): every sweep passed; logs in $logs"
