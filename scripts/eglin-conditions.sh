#!/usr/bin/env bash
# The Eglin CFD releases at four conditions (Mach 0.85 and 0.95, alpha 0 and 4 deg), each left
# out in turn: the distance-decay model and the aircraft's flowfield (docs/model.md section 3b)
# fitted to the other three, then updated (`sepval update`), predict it (issue 37; the table is
# in docs/eglin-cfd.md, "Four conditions").
#
#   scripts/eglin-conditions.sh REPO [OUT_DIR]      (default bench-out/eglin-conditions)
#
# REPO is a git clone of https://github.com/AbdullahElyas/GPR_StoreSeparation (no licence
# stated: its files stay out of this repository; scripts/eglin_convert.py converts them).
# Models (the embedded default store, t_end 0.5 s as the CFD):
#   decay      the default model, its 17 factors (`fit --method ga+lm --seed 1`);
#   field      the flowfield set to the default's interference at carriage (upwash 5.99 deg,
#              its gradient -10.4 deg/m, sidewash -5.84 deg, 4.28 deg/m, eta 1.09, roll -0.03),
#              halving 0.42 m below it (as exp(-s / 0.6)), its factors' bounds widened to
#              [-1, 3];
#   +update    either, then `sepval update --seed 1` on the same three releases;
#   +CA        either with the store's CA over Mach from the CFD's own loads of the three
#              releases fitted (scripts/eglin_loads.py --ca0-without the one left out), its
#              17 factors fitted; only when PYTHON names a Python with numpy and scipy
#              (e.g. PYTHON=venv/bin/python), which that script needs.
# Writes OUT_DIR/conditions.csv (RMS position and attitude error of the release left out, over
# its 0.5 s) and prints it. About 10 minutes on 2 cores (15 with +CA).
set -euo pipefail
cd "$(dirname "$0")/.."
[ $# -ge 1 ] || { echo "usage: $0 REPO [OUT_DIR]" >&2; exit 2; }
REPO=$1
OUT=${2:-bench-out/eglin-conditions}
SEPVAL=target/release/sepval
[ -x "$SEPVAL" ] || { echo "build first: cargo build --release --workspace" >&2; exit 2; }
rm -rf "$OUT"
mkdir -p "$OUT"
python3 scripts/eglin_convert.py "$REPO" "$OUT"
BASE=common/scenarios/eglin_default.toml
sed -e 's/^t_end_s = .*/t_end_s = 0.5/' "$BASE" > "$OUT/decay.toml"
. scripts/eglin-field.sh
eglin_field "$BASE" "$OUT/field.toml"

CASES=(M085_AOA0 M085_AOA4 M095_AOA0 M095_AOA4)
# The error of the scenario `$2` with the factors `$3` at the condition of release `$1`.
predicted() {
    local mach alpha pos att
    mach=$(awk -F' = ' '/^# mach/ {print $2}' "$OUT/$1.csv")
    alpha=$(awk -F' = ' '/^# alpha_deg/ {print $2}' "$OUT/$1.csv")
    sed -e "s/^mach = .*/mach = $mach/" -e "s/^alpha_deg = .*/alpha_deg = $alpha/" "$2" > "$4/held.toml"
    "$SEPVAL" simulate --scenario "$4/held.toml" --factors "$3" --out "$4/held.csv" > /dev/null
    read -r pos att < <("$SEPVAL" goals --data "$OUT/$1.csv" --sim "$4/held.csv" \
        | awk '/J_pos/ {p = $3} /J_att/ {a = $3} END {print p, a}')
    echo "$1,$5,$(awk "BEGIN {printf \"%.1f\", $pos * 1000}"),$(awk "BEGIN {printf \"%.2f\", $att}")" >> "$OUT/conditions.csv"
}

# The best factors of the fit in `$1` (its ga+lm answer), written to `$1/factors.json`.
best_factors() {
    python3 -c 'import json, sys; r = json.load(open(sys.argv[1])); print(json.dumps(r["methods"]["ga+lm"]["best"]["factors"]))' \
        "$1/result.json" > "$1/factors.json"
}

echo "left_out,model,rms_position_mm,rms_attitude_deg" > "$OUT/conditions.csv"
for held in "${CASES[@]}"; do
    data=()
    for c in "${CASES[@]}"; do [ "$c" = "$held" ] || data+=(--data "$OUT/$c.csv"); done
    for model in decay field; do
        fit="$OUT/$held-$model"
        "$SEPVAL" fit --scenario "$OUT/$model.toml" "${data[@]}" --method ga+lm --seed 1 \
            --no-figures --out "$fit" > /dev/null 2>&1
        best_factors "$fit"
        predicted "$held" "$OUT/$model.toml" "$fit/factors.json" "$fit" "$model"
        up="$OUT/$held-$model-update"
        "$SEPVAL" update --scenario "$OUT/$model.toml" "${data[@]}" --seed 1 --out "$up" > /dev/null 2>&1
        predicted "$held" "$up/scenario.toml" "$up/factors.json" "$up" "$model+update"
        [ -n "${PYTHON:-}" ] || continue
        ca="$OUT/$held-$model-ca"
        mkdir -p "$ca"
        line=$("$PYTHON" scripts/eglin_loads.py "$REPO" --ca0-without "$held")
        sed -e "s/^ca0 = .*/$line/" "$OUT/$model.toml" > "$ca/scenario.toml"
        "$SEPVAL" fit --scenario "$ca/scenario.toml" "${data[@]}" --method ga+lm --seed 1 \
            --no-figures --out "$ca/fit" > /dev/null 2>&1
        best_factors "$ca/fit"
        predicted "$held" "$ca/scenario.toml" "$ca/fit/factors.json" "$ca" "$model+CA"
    done
done
column -s, -t < "$OUT/conditions.csv"
