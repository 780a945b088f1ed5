#!/usr/bin/env bash
# What a flowfield fitted at two or three flight conditions predicts at a new one, against
# today's distance-decay model fitted and updated on the same releases (issue 37, "done when").
#
#   scripts/flowfield-study.sh [OUT_DIR]       (default bench-out/flowfield-study)
#
# For each of three truths (a field and a store, docs/model.md section 3b), releases are made
# by `sepval simulate` from the truth scenario at the truth factors, with the default flight
# test's noise (3 mm, 0.1 deg; seeds 11, 12, 13) at the fitted conditions
#   C1 Mach 0.80 alpha 0,  C2 Mach 0.95 alpha 3,  C3 Mach 0.90 alpha -2
# and noise-free at the condition predicted, C4 Mach 0.85 alpha 1.5. Each model is then fitted
# to C1 and C2 (and to C1, C2 and C3) and its prediction at C4 compared with the truth there
# (`sepval goals`: the RMS position and attitude errors over 1 s):
#   decay      the default model (distance-decay increments), its 17 factors fitted (ga+lm);
#   decay+upd  the same, then `sepval update` (corrections kept as far as they cross-validate);
#   flowfield  the truth's field form with its strengths unknown: the 17 factors fitted (the
#              interference factors scale the field's upwash, gradient, sidewash, dynamic
#              pressure and roll).
# Writes OUT_DIR/study.csv and prints it. About 15 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-bench-out/flowfield-study}
SEPVAL=target/release/sepval
[ -x "$SEPVAL" ] || { echo "build first: cargo build --release --workspace" >&2; exit 2; }
rm -rf "$OUT"
mkdir -p "$OUT"
BASE=common/scenarios/eglin_default.toml

# A scenario from the default: $1 the store's changes (sed expressions), $2 the [flowfield]
# table (empty: the decay model), $3 Mach, $4 alpha.
scenario() {
    local text
    text=$(sed -e "$1" -e "s/^mach = .*/mach = $3/" -e "s/^alpha_deg = .*/alpha_deg = $4/" "$BASE")
    if [ -n "$2" ]; then
        text=$(printf '%s\n' "$text" | sed -E 's/^(dc[xyzlmn]0) = .*/\1 = 0.0/')
        printf '%s\n%s\n' "$text" "$2"
    else
        printf '%s\n' "$text"
    fi
}

# The three truths: STORE_*, FIELD_* and `truth K`.
. scripts/flowfield-truths.sh

# The prediction at C4 of the model `$2` with the factors `$3/factors.json`, against the truth
# `$1/c4.csv`: a row of study.csv starting with `$4`.
predicted() {
    "$SEPVAL" simulate --scenario "$2" --factors "$3/factors.json" --out "$3/c4.csv" > /dev/null
    local pos att
    read -r pos att < <("$SEPVAL" goals --data "$1/c4.csv" --sim "$3/c4.csv" \
        | awk '/J_pos/ {p = $3} /J_att/ {a = $3} END {print p, a}')
    echo "$4,$(awk "BEGIN {print $pos * 1000}"),$att" >> "$OUT/study.csv"
}

CONDITIONS=("0.80 0.0" "0.95 3.0" "0.90 -2.0")
PREDICTED="0.85 1.5"

echo "truth,model,releases,rms_position_mm,rms_attitude_deg" > "$OUT/study.csv"
for k in 1 2 3; do
    truth $k
    dir="$OUT/truth-$k"
    mkdir -p "$dir"
    for i in 0 1 2; do
        read -r mach alpha <<< "${CONDITIONS[$i]}"
        scenario "$store" "$field" "$mach" "$alpha" > "$dir/truth-c$((i + 1)).toml"
        "$SEPVAL" simulate --scenario "$dir/truth-c$((i + 1)).toml" --factors truth \
            --noise-seed $((11 + i)) --out "$dir/c$((i + 1)).csv" > /dev/null
    done
    read -r mach alpha <<< "$PREDICTED"
    scenario "$store" "$field" "$mach" "$alpha" > "$dir/truth-c4.toml"
    "$SEPVAL" simulate --scenario "$dir/truth-c4.toml" --factors truth --out "$dir/c4.csv" > /dev/null
    # The models at C1 (the releases' metadata set each one's condition) and at C4.
    scenario "$store" "" 0.80 0.0 > "$dir/decay.toml"
    scenario "$store" "" "$mach" "$alpha" > "$dir/decay-c4.toml"
    cp "$dir/truth-c1.toml" "$dir/flowfield.toml"
    cp "$dir/truth-c4.toml" "$dir/flowfield-c4.toml"
    for n in 2 3; do
        data=(--data "$dir/c1.csv" --data "$dir/c2.csv")
        [ "$n" = 3 ] && data+=(--data "$dir/c3.csv")
        for model in decay flowfield; do
            fit="$dir/$model-fit-$n"
            "$SEPVAL" fit --scenario "$dir/$model.toml" "${data[@]}" --method ga+lm --seed 1 \
                --no-figures --out "$fit" > /dev/null
            # The refined optimum's factors, as `simulate --factors` reads them.
            python3 -c 'import json, sys; r = json.load(open(sys.argv[1])); print(json.dumps(r["methods"]["ga+lm"]["best"]["factors"]))' \
                "$fit/result.json" > "$fit/factors.json"
            predicted "$dir" "$dir/$model-c4.toml" "$fit" "$k,$model,$n"
        done
        up="$dir/decay-update-$n"
        "$SEPVAL" update --scenario "$dir/decay.toml" "${data[@]}" --seed 1 --out "$up" > /dev/null
        sed -e "s/^mach = .*/mach = $mach/" -e "s/^alpha_deg = .*/alpha_deg = $alpha/" \
            "$up/scenario.toml" > "$up/scenario-c4.toml"
        predicted "$dir" "$up/scenario-c4.toml" "$up" "$k,decay+update,$n"
    done
done
column -s, -t < "$OUT/study.csv"
