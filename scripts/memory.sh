#!/usr/bin/env bash
# Peak memory of a fit on a long record: coordinator and worker processes together, as PSS
# (proportional set size: shared memory counted once across the processes that map it).
#
#   scripts/memory.sh [ROWS [METHOD]]   (default 2 000 000 rows, the limit issue 13 set: under
#                                        500 MB; METHOD: ga (default), hill, both, ga+lm, hill+lm)
#   scripts/memory.sh diagnose [ROWS]   (a diagnosis, default 10 001 rows: a 10 kHz, 1-s record,
#                                        issue 21 item 7; in process on 2 threads, the tests'
#                                        reduced budget, about a minute)
#
# Simulates ROWS telemetry rows at 10 kHz (200 s for 2 million: a long record that stays within
# the plausible-position bound) with noise, fits them with METHOD on one worker, each search as
# short as it goes (a one-generation GA of four candidates, a hill climb of 4 simulations, a
# refinement of 30: its start and one Jacobian), samples /proc/PID/smaps_rollup of `sepval`
# and `sepval-worker` every 0.1 s, and prints the peak of their sum. Build first:
# cargo build --release. The hill climber starts from the nominal factors, whose run diverges
# at t = 58 s: hill, both and hill+lm need ROWS <= 570 000 (e.g. scripts/memory.sh 500000 both).
set -euo pipefail
cd "$(dirname "$0")/.."
bin=./target/release
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
rate=10000

# The peak PSS of process $1 and its children until it ends, in kB: "total coordinator worker".
peak_pss() {
    local run=$1 peak=0 peak_coordinator=0 peak_worker=0
    while kill -0 "$run" 2>/dev/null; do
        local total=0 coordinator=0 worker=0
        # This run and the workers it started (its children), not other sepval processes on
        # the host (a pattern on the command line would also match another checkout's binaries).
        for pid in "$run" $(pgrep -P "$run" || true); do
            kb=$(awk '/^Pss:/ {print $2}' "/proc/$pid/smaps_rollup" 2>/dev/null || echo 0)
            kb=${kb:-0}
            total=$((total + kb))
            if grep -q sepval-worker "/proc/$pid/cmdline" 2>/dev/null; then
                worker=$((worker + kb))
            else
                coordinator=$((coordinator + kb))
            fi
        done
        ((total > peak)) && peak=$total
        ((coordinator > peak_coordinator)) && peak_coordinator=$coordinator
        ((worker > peak_worker)) && peak_worker=$worker
        sleep 0.1
    done
    echo "$peak $peak_coordinator $peak_worker"
}

if [[ ${1:-} == diagnose ]]; then
    rows=${2:-10001}
    t_end=$(python3 -c "print(($rows - 1) / $rate)")
    "$bin/sepval" simulate --t-end "$t_end" --rate "$rate" --noise-seed 5 --out "$dir/d.csv" >/dev/null
    start=$(date +%s.%N)
    "$bin/sepval" diagnose --data "$dir/d.csv" --generations 20 --evaluator inproc --threads 2 \
        --out "$dir/diag" >"$dir/diagnose.log" 2>&1 &
    run=$!
    read -r peak _ _ < <(peak_pss "$run")
    wait "$run" || { cat "$dir/diagnose.log"; exit 1; }
    wall=$(python3 -c "print(f'{$(date +%s.%N) - $start:.0f}')")
    echo "diagnose of $rows rows: peak PSS $((peak / 1024)) MB, wall time $wall s"
    exit 0
fi

rows=${1:-2000000}
method=${2:-ga}
# The last sample is at (rows - 1) / rate: t_end gives exactly `rows` samples from t = 0.
t_end=$(python3 -c "print(($rows - 1) / $rate)")
"$bin/sepval" simulate --t-end "$t_end" --rate "$rate" --noise-seed 1 --out "$dir/long.csv" >/dev/null
echo "telemetry: $(($(grep -vc '^#' "$dir/long.csv") - 1)) rows, $(du -m "$dir/long.csv" | cut -f1) MB"

"$bin/sepval" fit --data "$dir/long.csv" --method "$method" --generations 1 --population 4 \
    --hill-budget 4 --lm-budget 30 --workers 1 --out "$dir/run" >"$dir/fit.log" 2>&1 &
fit=$!
read -r peak peak_coordinator peak_worker < <(peak_pss "$fit")
wait "$fit" || { cat "$dir/fit.log"; exit 1; }
echo "$method: peak PSS, coordinator + worker: $((peak / 1024)) MB" \
    "(coordinator alone $((peak_coordinator / 1024)) MB, worker alone $((peak_worker / 1024)) MB)"
