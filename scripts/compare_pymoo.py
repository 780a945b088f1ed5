#!/usr/bin/env python3
"""Compare sepval's Pareto GA with pymoo's NSGA-II on ZDT1, ZDT2 and ZDT3 (30 variables).

Creates a virtual environment (target/pymoo-venv), installs pymoo from PyPI, runs pymoo's
NSGA-II (population 100, its default operators) and `sepval selftest zdt` (the study's binary GA)
on the same evaluation budget over several seeds, and prints per problem the median hypervolume
of each (reference point (1.1, 1.1)) and their ratio.

    scripts/compare_pymoo.py [--evaluations 25000] [--seeds 1,2,3,4,5]

The sepval binary is taken from target/release (built with `cargo build --release` if missing).
"""
import argparse
import os
import statistics
import subprocess
import sys
import venv

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VENV = os.path.join(ROOT, "target", "pymoo-venv")
PY = os.path.join(VENV, "bin", "python")

PYMOO_RUN = r"""
import sys
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.problems import get_problem
from pymoo.optimize import minimize
from pymoo.indicators.hv import HV
problem, evaluations, seed = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
res = minimize(get_problem(problem, n_var=30), NSGA2(pop_size=100),
               ("n_eval", evaluations), seed=seed, verbose=False)
print(HV(ref_point=[1.1, 1.1])(res.F))
"""


def ensure_pymoo():
    if not os.path.exists(PY):
        print(f"creating {VENV}", file=sys.stderr)
        venv.EnvBuilder(with_pip=True).create(VENV)
    probe = subprocess.run([PY, "-c", "import pymoo"], capture_output=True)
    if probe.returncode != 0:
        print("installing pymoo from PyPI", file=sys.stderr)
        subprocess.run([PY, "-m", "pip", "install", "--quiet", "pymoo"], check=True)


def sepval_binary():
    exe = os.path.join(ROOT, "target", "release", "sepval")
    if not os.path.exists(exe):
        subprocess.run(["cargo", "build", "--release", "--bin", "sepval"], cwd=ROOT, check=True)
    return exe


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--evaluations", type=int, default=25000)
    ap.add_argument("--seeds", default="1,2,3,4,5")
    ap.add_argument("--problems", default="zdt1,zdt2,zdt3")
    args = ap.parse_args()
    seeds = [int(s) for s in args.seeds.split(",")]
    ensure_pymoo()
    exe = sepval_binary()
    print(f"{'problem':8} {'pymoo NSGA-II':>14} {'sepval GA':>10} {'ratio':>7}   ({args.evaluations} evaluations, seeds {args.seeds})")
    worst = None
    for p in args.problems.split(","):
        ours, theirs = [], []
        for s in seeds:
            out = subprocess.run([exe, "selftest", "zdt", "--problem", p, "--evaluations",
                                  str(args.evaluations), "--seed", str(s)],
                                 capture_output=True, text=True, check=True)
            ours.append(float(out.stdout.strip()))
            out = subprocess.run([PY, "-c", PYMOO_RUN, p, str(args.evaluations), str(s)],
                                 capture_output=True, text=True, check=True)
            theirs.append(float(out.stdout.strip().splitlines()[-1]))
        a, b = statistics.median(theirs), statistics.median(ours)
        ratio = b / a
        worst = ratio if worst is None else min(worst, ratio)
        print(f"{p:8} {a:14.4f} {b:10.4f} {ratio:7.3f}")
    print(f"lowest ratio {worst:.3f} (target >= 0.9)")


if __name__ == "__main__":
    main()
