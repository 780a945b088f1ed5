#!/usr/bin/env bash
# How wide `sepval predict`'s bands are where the model's form is right (issue 37): for each of
# the three truths of scripts/flowfield-study.sh (a field and a store), the flowfield model (the
# truth's form, its strengths unknown) is fitted to releases at C1 and C2 (and C3), and its
# 95 % bands at C4 (400 samples) are compared with the noise-free truth there: per channel, the
# RMS half-width over the RMS error of the median ("ratio"; 1.96 for a calibrated normal band)
# and the fraction of the times after release inside the band ("cov").
#
#   scripts/flowfield-bands.sh [OUT_DIR]      (default bench-out/flowfield-bands; about 20 s)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-bench-out/flowfield-bands}
SEPVAL=$PWD/target/release/sepval
[ -x "$SEPVAL" ] || { echo "build first: cargo build --release --workspace" >&2; exit 2; }
BASE=$PWD/common/scenarios/eglin_default.toml
# The studies' three truths: STORE_*, FIELD_* and `truth K`.
. scripts/flowfield-truths.sh
rm -rf "$OUT"
mkdir -p "$OUT"
cd "$OUT"

# A scenario from the default: $1 the store's changes, $2 the [flowfield] table, $3 Mach, $4 alpha.
scenario() {
    local text
    text=$(sed -e "$1" -e "s/^mach = .*/mach = $3/" -e "s/^alpha_deg = .*/alpha_deg = $4/" "$BASE" \
        | sed -E 's/^(dc[xyzlmn]0) = .*/\1 = 0.0/')
    printf '%s\n%s\n' "$text" "$2"
}

# Per channel: ratio and coverage of the bands in $1/bands.csv against the truth $2.
compare() {
    python3 - "$1/bands.csv" "$2" <<'PY'
import csv, math, sys
def load(p):
    return list(csv.DictReader([l for l in open(p) if not l.startswith('#')]))
bands, truth = load(sys.argv[1]), {round(float(r['t_s']), 6): r for r in load(sys.argv[2])}
cells = []
for ch in ['x_m', 'y_m', 'z_m', 'roll_deg', 'pitch_deg', 'yaw_deg']:
    e2 = h2 = n = inside = 0
    for r in bands:
        t = round(float(r['t_s']), 6)
        if t <= 0 or t not in truth:
            continue
        y, lo, mid, hi = (float(truth[t][ch]), float(r[ch + '_lo']), float(r[ch + '_mid']),
                          float(r[ch + '_hi']))
        e2 += (mid - y) ** 2; h2 += ((hi - lo) / 2) ** 2; n += 1; inside += lo <= y <= hi
    ratio = math.sqrt(h2 / n) / max(math.sqrt(e2 / n), 1e-12)
    cells.append(f"{ratio:.1f}x, {inside / n:.2f}")
print(" | ".join(cells))
PY
}

echo "| truth | releases | x | y | z | roll | pitch | yaw |"
echo "|---|---|---|---|---|---|---|---|"
for k in 1 2 3; do
    truth $k
    d=truth-$k
    mkdir -p $d
    scenario "$store" "$field" 0.80 0.0 > $d/c1.toml
    scenario "$store" "$field" 0.95 3.0 > $d/c2.toml
    scenario "$store" "$field" 0.90 -2.0 > $d/c3.toml
    scenario "$store" "$field" 0.85 1.5 > $d/c4.toml
    for i in 1 2 3; do
        "$SEPVAL" simulate --scenario $d/c$i.toml --factors truth --noise-seed $((10 + i)) \
            --out $d/c$i.csv > /dev/null
    done
    "$SEPVAL" simulate --scenario $d/c4.toml --factors truth --out $d/c4.csv > /dev/null
    for n in 2 3; do
        data=(--data $d/c1.csv --data $d/c2.csv)
        [ $n = 3 ] && data+=(--data $d/c3.csv)
        "$SEPVAL" fit --scenario $d/c1.toml "${data[@]}" --method ga+lm --seed 1 --no-figures \
            --evaluator inproc --threads 2 --out $d/fit-$n > /dev/null
        "$SEPVAL" predict --from $d/fit-$n --scenario $d/c4.toml --samples 400 \
            --evaluator inproc --threads 2 --out $d/predict-$n > /dev/null
        echo "| $k | $n | $(compare $d/predict-$n $d/c4.csv) |"
    done
done
