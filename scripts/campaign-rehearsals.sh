#!/usr/bin/env bash
# Issue 58's yardstick ("a campaign that settles"): `sepval campaign rehearse` on the example
# aircraft with a side wall 0.3 m from the store (examples/campaign-wall/README.md), a 5 x 5
# grid of Mach 0.6-0.95 and altitude 1-9 km (alpha, beta and gamma the default scenario's 0),
# the prior of known accuracy (every factor's sd 1/12 of its range) and `--fly-risk 0.05`,
# against three truths, each a seeded draw of the factors from that prior:
#
#   null       no hidden cause                                  (truth-factors-null.json)
#   catalogue  a cause in the catalogue, --truth-effect ejector_cant=-0.03
#                                                               (truth-factors-catalogue.json)
#   extension  a cause outside it, --truth-extension extension-cn-mach.toml (Cn in Mach)
#                                                               (truth-factors-extension.json)
#
# and prints, per rehearsal, from CAMP/rehearsal.json (the per-condition states of every round
# from CAMP/rounds/NN/envelope.csv): the releases flown; the conditions cleared in any round
# that the truth fails (target 0); the releases flown where the truth does not clear (target
# 0); the share of the truly safe conditions cleared at the end (target >= 95 %); the share of
# all conditions decided right at the end (cleared and truly safe, or failing and truly
# failing; target >= 90 %); each release's forecast (`expected_settled`) against what it
# settled (target: realized / expected within 0.7-1.3 over all releases); then the averages
# (target <= 4 releases). With --check-settled, a rehearsal that settles with conditions
# undecided has the claim checked: each condition then safe to fly is flown in turn on a copy
# of the campaign (`campaign rehearse --check-settled`), and the table says how many candidates
# there were and how many would have settled a condition (target 0).
#
#   scripts/campaign-rehearsals.sh OUT [--samples N] [--releases MAX] [--generations G]
#       [--seed S] [--threads T] [--only NAME[,NAME...]] [--check-settled]
#   scripts/campaign-rehearsals.sh OUT --truths    (only the truths' envelopes: --releases 0,
#                                                   --samples 20, a few seconds each)
#   scripts/campaign-rehearsals.sh OUT --table     (print the table of a finished OUT again)
#
# OUT must not exist or be empty; each rehearsal goes to OUT/NAME, its output to OUT/NAME.log,
# the table to OUT/table.md and OUT/summary.json. A rehearsal that fails (its exit status not
# 0) is reported as such and the others still run. The binary is target/release/sepval, as
# built (`cargo build --release -p sepval`); the script does not build it.
set -euo pipefail
cd "$(dirname "$0")/.."
root="$PWD"
bin="$root/target/release/sepval"
ex="$root/examples/campaign-wall"

usage() { sed -n '/^#   scripts/,/^#   scripts.*--table/p' "$0" | sed 's/^#//' >&2; exit 2; }

[ $# -ge 1 ] || usage
out="$1"
shift
samples=500        # about 2-4 min a rehearsal on the 2-core machine (examples/campaign-wall/README.md)
releases=6         # rehearse's default
generations=20     # init's default
seed=1
threads=2
only="null,catalogue,extension"
table_only=0
check=()
while [ $# -gt 0 ]; do
    case "$1" in
        --samples) samples="$2"; shift 2 ;;
        --releases) releases="$2"; shift 2 ;;
        --generations) generations="$2"; shift 2 ;;
        --seed) seed="$2"; shift 2 ;;
        --threads) threads="$2"; shift 2 ;;
        --only) only="$2"; shift 2 ;;
        --check-settled) check=(--check-settled); shift ;;
        --truths) releases=0; samples=20; shift ;;
        --table) table_only=1; shift ;;
        *) echo "unknown option: $1" >&2; usage ;;
    esac
done

truth_args() {
    case "$1" in
        null) echo "--truth-factors $ex/truth-factors-null.json" ;;
        catalogue) echo "--truth-factors $ex/truth-factors-catalogue.json --truth-effect ejector_cant=-0.03" ;;
        extension) echo "--truth-factors $ex/truth-factors-extension.json --truth-extension $ex/extension-cn-mach.toml" ;;
        *) echo "unknown rehearsal: $1 (expected null, catalogue or extension)" >&2; exit 2 ;;
    esac
}

if [ "$table_only" = 0 ]; then
    [ -x "$bin" ] || { echo "no $bin: cargo build --release -p sepval" >&2; exit 2; }
    if [ -e "$out" ] && [ -n "$(ls -A "$out")" ]; then
        echo "$out exists and is not empty" >&2
        exit 2
    fi
    mkdir -p "$out"
    {
        echo "started_utc=$(date -u +%Y-%m-%dT%H:%M:%SZ)"
        echo "commit=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)"
        echo "binary_sha256=$(sha256sum "$bin" | cut -d' ' -f1)"
        echo "samples=$samples releases=$releases generations=$generations seed=$seed threads=$threads check_settled=${#check[@]}"
    } >"$out/settings.txt"
    IFS=, read -r -a names <<<"$only"
    for name in "${names[@]}"; do
        read -r -a truth <<<"$(truth_args "$name")"
        cmd=("$bin" campaign rehearse --out "$out/$name"
            --aircraft "$ex/aircraft.toml"
            --mach 0.6:0.95:5 --altitude-m 1000:9000:5
            --prior "$ex/prior.json" --fly-risk 0.05
            --samples "$samples" --generations "$generations" --seed "$seed"
            --releases "$releases" --evaluator inproc --threads "$threads"
            "${check[@]}" "${truth[@]}")
        echo "rehearsal $name: ${cmd[*]#"$root/"}" >&2
        start=$(date +%s.%N)
        status=0
        "${cmd[@]}" >"$out/$name.log" 2>&1 || status=$?
        end=$(date +%s.%N)
        wall=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.0f", b - a }')
        echo "$name $status $wall" >>"$out/runs.txt"
        echo "rehearsal $name: exit $status, ${wall} s" >&2
        [ "$status" = 0 ] || tail -5 "$out/$name.log" >&2
    done
    echo "finished_utc=$(date -u +%Y-%m-%dT%H:%M:%SZ)" >>"$out/settings.txt"
fi

[ -f "$out/runs.txt" ] || { echo "$out has no runs.txt: no rehearsal was run there" >&2; exit 2; }
python3 - "$out" <<'PY'
import csv
import json
import os
import sys

out = sys.argv[1]
settings = open(os.path.join(out, "settings.txt")).read().split()
runs = [line.split() for line in open(os.path.join(out, "runs.txt")) if line.strip()]


def key(mach, alt):
    return (round(float(mach), 9), round(float(alt), 6))


def pct(a, b):
    return 100.0 * a / b if b else float("nan")


rows, releases, maps, summary = [], [], [], {"settings": settings, "rehearsals": []}
for name, status, wall in runs:
    camp = os.path.join(out, name)
    path = os.path.join(camp, "rehearsal.json")
    if status != "0" or not os.path.exists(path):
        rows.append({"name": name, "error": f"exit {status}", "wall_s": int(wall)})
        summary["rehearsals"].append(rows[-1])
        continue
    r = json.load(open(path))
    truth = {key(t["condition"]["mach"], t["condition"]["altitude_m"]): t["fails"] for t in r["truth"]}
    n = len(truth)
    n_fail = sum(truth.values())
    n_safe = n - n_fail
    # Every round's state of every condition, from its envelope.csv (grid order, state column).
    false_clear_conditions = set()
    final = None
    for rd in r["rounds"]:
        env = os.path.join(camp, "rounds", "%02d" % rd["round"], "envelope.csv")
        states = {}
        with open(env) as f:
            for row in csv.DictReader(f):
                states[key(row["mach"], row["altitude_m"])] = row["state"]
        assert set(states) == set(truth), f"{env}: its conditions are not the truth's"
        fc = {c for c, s in states.items() if s == "cleared" and truth[c]}
        ff = {c for c, s in states.items() if s == "fails" and not truth[c]}
        # The record's own counts must agree with the states read.
        assert len(fc) == rd["false_clears"] and len(ff) == rd["false_fails"], env
        assert sum(s == "cleared" for s in states.values()) == rd["counts"]["cleared"], env
        false_clear_conditions |= fc
        final = states
    last = r["rounds"][-1]
    cleared_safe = sum(1 for c, s in final.items() if s == "cleared" and not truth[c])
    fails_right = sum(1 for c, s in final.items() if s == "fails" and truth[c])
    flown = r["flown"]
    unsafe = sum(1 for f in flown if not f["truly_safe"])
    expected = sum(f["expected_settled"] for f in flown)
    settled = sum(f["settled"] for f in flown)
    unsettled = sum(f["unsettled"] for f in flown)
    row = {
        "name": name, "wall_s": int(wall), "truth_fails": n_fail, "conditions": n,
        "releases": len(flown), "settled_flag": r["settled"],
        "false_clears_any_round": len(false_clear_conditions),
        "false_clears_summed_over_rounds": sum(rd["false_clears"] for rd in r["rounds"]),
        "unsafe_releases": unsafe,
        "safe_cleared_pct": pct(cleared_safe, n_safe), "safe_cleared": cleared_safe, "safe": n_safe,
        "decided_right_pct": pct(cleared_safe + fails_right, n), "decided_right": cleared_safe + fails_right,
        "final": last["counts"], "final_false_fails": last["false_fails"],
        "expected_settled": expected, "settled": settled, "unsettled": unsettled,
        "ratio": settled / expected if expected > 0 else float("nan"),
        "check_candidates": len(r.get("settled_check", [])),
        "check_settling": sum(1 for f in r.get("settled_check", []) if f["settled"] > 0),
        "check_most": max([f["settled"] for f in r.get("settled_check", [])], default=0),
    }
    row["truth_map"] = {f"{m:g},{h:g}": t["min_clearance_mm"] for t in r["truth"]
                        for m, h in [(t["condition"]["mach"], t["condition"]["altitude_m"])]}
    row["final_states"] = {f"{m:g},{h:g}": s for (m, h), s in final.items()}
    maps.append((name, r["truth"], final))
    rows.append(row)
    summary["rehearsals"].append(row)
    for i, f in enumerate(flown, 1):
        c = f["condition"]
        releases.append((name, i, c["mach"], c["altitude_m"], f["p_fail_planned"], f["truly_safe"],
                         f["expected_settled"], f["settled"], f["unsettled"]))

def check_cell(r):
    if not r["check_candidates"]:
        return "-"
    return f"{r['check_candidates']}, {r['check_settling']} (most {r['check_most']})"


lines = []
p = lines.append
p("settings: " + " ".join(settings))
p("")
p("| rehearsal | truth fails | releases | settled | final cleared / fail / undecided | false clears, any round | releases truly unsafe | truly safe cleared | decided right | settled / expected | settled check: candidates, settling | wall |")
p("|---|---|---|---|---|---|---|---|---|---|---|---|")
for r in rows:
    if "error" in r:
        p(f"| {r['name']} | {r['error']} | | | | | | | | | | {r['wall_s']} s |")
        continue
    fc = r["final"]
    p(f"| {r['name']} | {r['truth_fails']} of {r['conditions']} ({pct(r['truth_fails'], r['conditions']):.0f} %) "
      f"| {r['releases']} | {'yes' if r['settled_flag'] else 'no'} "
      f"| {fc['cleared']} / {fc['fails']} / {fc['undecided']} "
      f"| {r['false_clears_any_round']} | {r['unsafe_releases']} "
      f"| {r['safe_cleared']} of {r['safe']} ({r['safe_cleared_pct']:.0f} %) "
      f"| {r['decided_right']} of {r['conditions']} ({r['decided_right_pct']:.0f} %) "
      f"| {r['settled']} / {r['expected_settled']:.1f} = {r['ratio']:.2f} "
      f"| {check_cell(r)} | {r['wall_s']} s |")
ok = [r for r in rows if "error" not in r]
if ok:
    k = len(ok)
    exp_all = sum(r["expected_settled"] for r in ok)
    set_all = sum(r["settled"] for r in ok)
    avg = {
        "rehearsals": k,
        "releases": sum(r["releases"] for r in ok) / k,
        "false_clears_any_round": sum(r["false_clears_any_round"] for r in ok),
        "unsafe_releases": sum(r["unsafe_releases"] for r in ok),
        "safe_cleared_pct": sum(r["safe_cleared_pct"] for r in ok) / k,
        "decided_right_pct": sum(r["decided_right_pct"] for r in ok) / k,
        "expected_settled": exp_all, "settled": set_all,
        "ratio": set_all / exp_all if exp_all > 0 else float("nan"),
        "wall_s": sum(r["wall_s"] for r in ok) / k,
    }
    summary["average"] = avg
    p(f"| **average of {k}** | | {avg['releases']:.1f} | | | {avg['false_clears_any_round']} (total) "
      f"| {avg['unsafe_releases']} (total) | {avg['safe_cleared_pct']:.0f} % | {avg['decided_right_pct']:.0f} % "
      f"| {set_all} / {exp_all:.1f} = {avg['ratio']:.2f} | | {avg['wall_s']:.0f} s |")
    p("| **target** | 40-60 % | <= 4 | | | 0 | 0 | >= 95 % | >= 90 % | 0.7-1.3 | 0 settling | |")
p("")
p("| rehearsal | release | Mach | altitude [m] | P(fail) planned | truly safe | expected to settle | settled | unsettled |")
p("|---|---|---|---|---|---|---|---|---|")
for name, i, m, h, pf, safe, e, s, u in releases:
    p(f"| {name} | {i} | {m:g} | {h:g} | {pf:.3f} | {'yes' if safe else 'NO'} | {e:.1f} | {s} | {u} |")
# Each truth's smallest clearance [mm] (F: the truth fails there) and the final state
# (C cleared, F fails, U undecided; * where it contradicts the truth, ? undecided).
for name, truth, final in maps:
    machs = sorted({t["condition"]["mach"] for t in truth})
    alts = sorted({t["condition"]["altitude_m"] for t in truth}, reverse=True)
    cell = {(t["condition"]["mach"], t["condition"]["altitude_m"]): t for t in truth}
    p("")
    p(f"{name}: the truth's smallest clearance [mm] (F fails) / the final state (C, F, U; * wrong, ? undecided)")
    p("")
    p("| altitude [m] \\ Mach | " + " | ".join(f"{m:g}" for m in machs) + " |")
    p("|---" * (len(machs) + 1) + "|")
    for h in alts:
        cells = []
        for m in machs:
            t = cell[(m, h)]
            c = t["min_clearance_mm"]
            c = f"{float(c):.1f}" if c not in (None, "nan") else "tumbles"
            st = final[key(m, h)]
            mark = {"cleared": "C", "fails": "F", "undecided": "U"}[st]
            if st == "undecided":
                mark += "?"
            elif (st == "fails") != t["fails"]:
                mark += "*"
            cells.append(f"{c}{' F' if t['fails'] else ''} / {mark}")
        p(f"| {h:g} | " + " | ".join(cells) + " |")
summary["releases"] = [dict(zip(["rehearsal", "release", "mach", "altitude_m", "p_fail_planned", "truly_safe",
                                 "expected_settled", "settled", "unsettled"], x)) for x in releases]
text = "\n".join(lines) + "\n"
open(os.path.join(out, "table.md"), "w").write(text)
json.dump(summary, open(os.path.join(out, "summary.json"), "w"), indent=1)
sys.stdout.write(text)
PY
