#!/usr/bin/env python3
"""Writes prior.json and the truths' factor files of this directory (README.md says why).

The prior: every one of the 17 factors normal about its nominal value (docs/model.md
section 4) with a standard deviation of 1/12 of its range. A truth's factors: one draw from
that prior, truncated to the range by redrawing, from Python's random.Random(seed).gauss, the
factors in the table order of docs/model.md section 4. Run from any directory:

    python3 examples/campaign-wall/draw.py [SEED ...]

With no seed it writes the three files the rehearsals use (seeds 4, 8 and 10); with seeds it
prints each draw and writes nothing.
"""
import json
import os
import random
import sys

# name, min, max, nominal (docs/model.md section 4, in its table order)
FACTORS = [
    ("fwdfac", 0.2, 1.0, 0.5), ("aftfac", 0.2, 1.0, 0.5),
    ("xinerfac", 0.9, 1.1, 1.0), ("yinerfac", 0.9, 1.1, 1.0), ("zinerfac", 0.9, 1.1, 1.0),
    ("caoff", -0.1, 0.1, 0.0), ("cyoff", -0.2, 0.2, 0.0), ("czoff", -0.2, 0.2, 0.0),
    ("cmoff", -0.5, 0.5, 0.0), ("cnoff", -0.5, 0.5, 0.0), ("cloff", -0.5, 0.5, 0.0),
    ("caintfac", 0.25, 2.0, 1.0), ("cyintfac", 0.25, 2.0, 1.0), ("czintfac", 0.25, 2.0, 1.0),
    ("cmintfac", 0.25, 2.0, 1.0), ("cnintfac", 0.25, 2.0, 1.0), ("clintfac", 0.25, 2.0, 1.0),
]
TRUTHS = {"null": 4, "catalogue": 8, "extension": 10}


def draw(seed):
    rng = random.Random(seed)
    out = {}
    for name, lo, hi, mean in FACTORS:
        sd = (hi - lo) / 12.0
        while True:
            v = rng.gauss(mean, sd)
            if lo <= v <= hi:
                break
        out[name] = round(v, 6)
    return out


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    if len(sys.argv) > 1:
        for s in sys.argv[1:]:
            print(s, json.dumps(draw(int(s))))
        return
    prior = {"format": "sepval-prior/1",
             "factors": {n: {"mean": m, "sd": (hi - lo) / 12.0} for n, lo, hi, m in FACTORS}}
    with open(os.path.join(here, "prior.json"), "w") as f:
        json.dump(prior, f, indent=2)
        f.write("\n")
    for truth, seed in TRUTHS.items():
        with open(os.path.join(here, f"truth-factors-{truth}.json"), "w") as f:
            json.dump(draw(seed), f, indent=2)
            f.write("\n")


if __name__ == "__main__":
    main()
