#!/usr/bin/env bash
# The campaign's speed against issue 35's targets: `campaign init`, six `campaign add`s of one
# release each and `campaign next --count 3`, on a 5 x 5 grid (Mach 0.6-1.2, alpha -6 to 10
# deg) x SAMPLES samples (default 1 000) of a 1-s release at 200 Hz against the example
# aircraft, over WORKERS iceoryx2 workers (default 2). The targets: each add at most 2 min up to
# 6 releases, next at most 30 s. The releases are the store flown with the truth factors and
# noise (`sepval simulate --factors truth --noise-seed K`) at six conditions of the grid.
#
#   scripts/campaign-bench.sh            (writes bench-out/campaign.csv and prints it)
#
# Wall times of whole commands, so a figure is of this machine on the day it was taken: say so
# when quoting one (docs/performance.md, "Campaign").
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
cargo build --release --workspace --features zenoh
bin="$root/target/release/sepval"
out="${OUT:-bench-out}"
mkdir -p "$out"
csv="$root/$out/campaign.csv"
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir"
evaluator=(--evaluator ipc --workers "${WORKERS:-2}")

"$bin" scenario --out base.toml >/dev/null
k=0
for condition in "0.6 -6" "0.9 2" "1.2 10" "0.75 6" "1.05 -2" "0.9 10"; do
    k=$((k + 1))
    read -r mach alpha <<<"$condition"
    # The first `mach =` and `alpha_deg =` lines are the [flight] table's.
    awk -v m="$mach" -v a="$alpha" '
        /^mach = / && !dm { print "mach = " m; dm = 1; next }
        /^alpha_deg = / && !da { print "alpha_deg = " a; da = 1; next }
        { print }' base.toml >"r$k.toml"
    "$bin" simulate --scenario "r$k.toml" --factors truth --noise-seed "$k" --out "r$k.csv" >/dev/null
done

# Seconds taken by a command, its output discarded; a command that fails stops the script.
timed() {
    local start end
    start=$(date +%s.%N)
    if ! "$@" >/dev/null 2>"$dir/stderr"; then
        echo "failed: $*" >&2
        cat "$dir/stderr" >&2
        exit 1
    fi
    end=$(date +%s.%N)
    awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }'
}

echo "command,releases_flown,wall_s,target_s" >"$csv"
t=$(timed "$bin" campaign init --aircraft "$root/examples/geometry/aircraft.toml" \
    --mach 0.6:1.2:5 --alpha-deg -6:10:5 --samples "${SAMPLES:-1000}" "${evaluator[@]}" --out camp)
echo "init,0,$t," >>"$csv"
for k in 1 2 3 4 5 6; do
    t=$(timed "$bin" campaign add camp --data "r$k.csv" "${evaluator[@]}")
    echo "add,$k,$t,120" >>"$csv"
done
t=$(timed "$bin" campaign next camp --count 3)
echo "next,6,$t,30" >>"$csv"
echo "taken $(date -u +%Y-%m-%dT%H:%MZ) on $(nproc) cores; $(uptime | sed 's/.*load/load/')"
cat "$csv"
