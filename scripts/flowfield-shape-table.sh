#!/usr/bin/env bash
# `sepval update` correcting a flowfield's shape table over depth (docs/update.md section 15.3a,
# "A shape given as a table"): the guide's example store under the conformance case's table
# (docs/model.md section 3b) flown at three conditions with the default flight test's noise,
# updated from a store whose table is wrong, then the condition never flown predicted.
#
#   scripts/flowfield-shape-table.sh [OUT_DIR]      (default bench-out/flowfield-shape-table)
#
# Prints the update's verdict, the corrected table, and the RMS errors at Mach 0.85 alpha
# 1.5 deg of the updated store and of the store as given with its factors fitted. About a
# minute on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-bench-out/flowfield-shape-table}
SEPVAL=target/release/sepval
[ -x "$SEPVAL" ] || { echo "build first: cargo build --release --workspace" >&2; exit 2; }
rm -rf "$OUT"
mkdir -p "$OUT"
EXAMPLE=examples/flowfield-store/scenario.toml
TRUTH='shape = { depth_m = [0.0, 0.3, 0.9, 1.6, 2.5], g = [1.0, 0.62, 0.2, -0.07, 0.0] }'
GIVEN='shape = { depth_m = [0.0, 0.5, 1.0, 2.0, 4.0], g = [1.0, 0.5, 0.333333, 0.2, 0.111111] }'
grep -v '^reversal_m' "$EXAMPLE" | sed -e "s/^half_depth_m = .*/$TRUTH/" > "$OUT/truth.toml"
grep -v '^reversal_m' "$EXAMPLE" | sed -e "s/^half_depth_m = .*/$GIVEN/" > "$OUT/given.toml"
# The scenario $1 at Mach $2, alpha $3.
at() { sed -e "s/^mach = .*/mach = $2/" -e "s/^alpha_deg = .*/alpha_deg = $3/" "$1"; }
data=()
k=0
for c in "0.80 0.0 11" "0.95 3.0 12" "0.90 -2.0 13"; do
    read -r mach alpha seed <<< "$c"
    at "$OUT/truth.toml" "$mach" "$alpha" > "$OUT/t.toml"
    "$SEPVAL" simulate --scenario "$OUT/t.toml" --factors truth --noise-seed "$seed" \
        --out "$OUT/r$k.csv" > /dev/null
    data+=(--data "$OUT/r$k.csv")
    k=$((k + 1))
done
at "$OUT/truth.toml" 0.85 1.5 > "$OUT/t4.toml"
"$SEPVAL" simulate --scenario "$OUT/t4.toml" --factors truth --out "$OUT/c4.csv" > /dev/null
"$SEPVAL" update --scenario "$OUT/given.toml" "${data[@]}" --generations 20 --evaluator inproc \
    --threads 2 --out "$OUT/up" | grep '^update:'
sed -n '/^\[flowfield.shape\]/,/^$/p' "$OUT/up/scenario.toml"
# The RMS errors at the condition never flown of scenario $1 with the factors $2 (the scenario
# at that condition beside it: its table files are relative to it).
predicted() {
    local p
    p="$(dirname "$1")/at-c4.toml"
    at "$1" 0.85 1.5 > "$p"
    "$SEPVAL" simulate --scenario "$p" --factors "$2" --out "$OUT/p.csv" > /dev/null 2>> "$OUT/log"
    "$SEPVAL" goals --data "$OUT/c4.csv" --sim "$OUT/p.csv" | awk '/J_pos|J_att/ {printf "%s %s  ", $1, $3} END {print ""}'
}
echo -n "Mach 0.85 alpha 1.5, the updated store:           "
predicted "$OUT/up/scenario.toml" "$OUT/up/factors.json"
python3 -c 'import json, sys; r = json.load(open(sys.argv[1])); print(json.dumps(r["methods"]["ga+lm"]["best"]["factors"]))' \
    "$OUT/up/baseline/result.json" > "$OUT/base.json"
echo -n "Mach 0.85 alpha 1.5, the store as given, fitted:  "
predicted "$OUT/given.toml" "$OUT/base.json"
