#!/usr/bin/env python3
"""Reference values of sepval's elementary functions, from mpmath at 300 bits (more for the
argument reduction of sin and cos at large x).

Writes common/tests/model/elementary_reference.txt, read by common/tests/model/elementary.rs:

    python3 scripts/elementary_reference.py > common/tests/model/elementary_reference.txt

(needs `pip install mpmath`; deterministic: the inputs come from a seeded generator). For a
denser check, not committed: `--scale 10 --seed 777` writes ten times as many values from
another seed (3 MB), and the same test reads them if they replace the file.

One line per value: the function, its arguments as the hex bit patterns of doubles, the
correctly rounded result (hex bits; `inf`/`-inf`/`nan` for those) and the exact result's
distance from it in units in the last place of the rounded result, to three decimals:

    exp 0xc0862e42fefa39ef 0x0000000000000001 -0.271

Inputs cover each function's whole domain: uniform over the main interval, log-uniform over
every binade (subnormals included), the boundaries of the kernels' reduced ranges (0.625 for
asin, t = 0.66 for atan2, +-700 for exp, 2^20 for sin and cos), and hard cases (arguments next
to multiples of pi/2, sqrt(1/2), 1).
"""

import math
import random
import struct
import sys

from mpmath import mp, mpf

mp.prec = 300


def bits(x):
    return struct.unpack("<Q", struct.pack("<d", x))[0]


def from_bits(b):
    return struct.unpack("<d", struct.pack("<Q", b))[0]


def hexd(x):
    return "0x%016x" % bits(x)


def ulp(d):
    """The unit in the last place of a finite double d (as the Rust test defines it)."""
    e = bits(abs(d)) >> 52
    if e == 0:
        return mpf(2) ** -1074
    return mpf(2) ** (e - 1075)


def next_up(d):
    if d == 0:
        return from_bits(1)
    return from_bits(bits(d) + 1) if d > 0 else from_bits(bits(d) - 1)


def next_down(d):
    return -next_up(-d)


def rounded(v):
    """The double nearest to the mpf v (ties to even), and the distance in its ulps."""
    if mp.isnan(v):
        return None, None
    if mp.isinf(v):
        return (math.inf if v > 0 else -math.inf), None
    limit = mpf(2) ** 1024 * (1 - mpf(2) ** -54)
    if abs(v) >= limit:
        return (math.inf if v > 0 else -math.inf), None
    d = float(v)
    best = min((next_down(d), d, next_up(d)), key=lambda c: (abs(mpf(c) - v), bits(c) & 1))
    if math.isinf(best):
        best = d
    return best, (v - mpf(best)) / ulp(best)


def line(name, args, v):
    d, frac = rounded(v)
    if d is None:
        result = "nan"
    elif math.isinf(d):
        result = "inf" if d > 0 else "-inf"
    else:
        result = hexd(d) + " %.3f" % frac
    return "%s %s %s" % (name, " ".join(hexd(a) for a in args), result)


SEED = 20261123
rng = random.Random(SEED)


def uniform(lo, hi):
    return rng.uniform(lo, hi)


def log_uniform(lo_exp, hi_exp, signed=True):
    m = 2.0 ** uniform(lo_exp, hi_exp)
    if m == 0.0:
        m = from_bits(1)
    return -m if signed and rng.random() < 0.5 else m


def any_positive():
    """A positive finite double with a random bit pattern (every binade equally likely)."""
    while True:
        x = from_bits(rng.getrandbits(63))
        if math.isfinite(x) and x > 0:
            return x


def near(x, k=4):
    """x moved by up to k ulps (a zero to a subnormal of either sign)."""
    if x == 0.0:
        return rng.choice((1.0, -1.0)) * from_bits(rng.randint(0, k))
    return from_bits(bits(x) + rng.randint(-k, k))


def exp_inputs(n):
    xs = [uniform(-746.0, 710.0) for _ in range(n // 4)]
    xs += [log_uniform(-60, 9.5) for _ in range(n // 4)]
    xs += [uniform(-16.0, 1.0) for _ in range(n // 4)]
    for c in (700.0, -700.0, 709.782712893384, -708.3964185322641, -745.1332191019411, 0.0):
        xs += [near(c, 1000) for _ in range(n // 24)]
    return xs


def ln_inputs(n):
    xs = [any_positive() for _ in range(n // 4)]
    xs += [uniform(0.5, 2.0) for _ in range(n // 4)]
    xs += [1.0 + log_uniform(-52, -1) for _ in range(n // 4)]
    for c in (math.sqrt(0.5), math.sqrt(2.0), 1.0, 2.2250738585072014e-308):
        xs += [near(c, 50) for _ in range(n // 16)]
    return xs


def pow_inputs(n):
    pairs = [(uniform(0.7, 1.0), 5.25588) for _ in range(n // 4)]
    for _ in range(n // 4):
        x = any_positive()
        lx = math.log(x)
        y = uniform(-700.0, 700.0) / lx if lx != 0 else 1.0
        pairs.append((x, y))
    for _ in range(n // 4):
        pairs.append((log_uniform(-20, 20, signed=False), uniform(-30.0, 30.0)))
    for _ in range(n // 4):
        pairs.append((near(1.0, 10**6), uniform(-1e6, 1e6)))
    return pairs


def sin_cos_inputs(n):
    xs = [uniform(-math.pi, math.pi) for _ in range(n // 5)]
    xs += [log_uniform(-30, 20) for _ in range(n // 5)]
    xs += [log_uniform(20, 1024) for _ in range(n // 5)]
    for _ in range(n // 5):
        k = rng.choice((rng.randint(1, 100), rng.randint(1, 2**20), rng.randint(1, 2**40)))
        xs.append(near(k * math.pi / 2, 3))
    xs += [near(2.0**20, 3) for _ in range(n // 20)]
    xs += [near(c, 2) for c in (6381956970095103 * 2.0**797, 5261692873635770 * 2.0**499)]
    xs += [near(math.pi / 4, 3) for _ in range(n // 20)]
    return xs


def asin_inputs(n):
    xs = [uniform(-1.0, 1.0) for _ in range(n // 4)]
    xs += [log_uniform(-60, 0) for _ in range(n // 4)]
    xs += [uniform(0.625, 1.0) * rng.choice((1, -1)) for _ in range(n // 4)]
    xs += [near(0.625, 100) for _ in range(n // 16)]
    xs += [(1.0 - log_uniform(-53, -1, signed=False)) for _ in range(n // 16)]
    xs += [near(0.5, 100) for _ in range(n // 16)]
    xs += [near(math.sin(0.9999), 100) for _ in range(n // 16)]
    return xs


def atan2_inputs(n):
    pairs = []
    for _ in range(n // 4):
        t, r = uniform(-math.pi, math.pi), log_uniform(-20, 20, signed=False)
        pairs.append((r * math.sin(t), r * math.cos(t)))
    for _ in range(n // 4):
        pairs.append((log_uniform(-1074, 1023), log_uniform(-1074, 1023)))
    for _ in range(n // 4):
        pairs.append((log_uniform(-40, 40), log_uniform(-40, 40)))
    for _ in range(n // 8):
        x = log_uniform(-20, 20)
        pairs.append((near(0.66 * x, 50) * rng.choice((1, -1)), x))
    for _ in range(n // 8):
        x = log_uniform(-20, 20)
        pairs.append((near(x, 50) * rng.choice((1, -1)), x))
    return pairs


def main():
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scale", type=int, default=1, help="values per function, times this")
    parser.add_argument("--seed", type=int, default=SEED, help="seed of the inputs")
    args = parser.parse_args()
    rng.seed(args.seed)
    n = 800 * args.scale
    out = []
    for x in exp_inputs(n):
        out.append(line("exp", [x], mp.exp(x)))
    for x in ln_inputs(n):
        out.append(line("ln", [x], mp.log(x)))
    for x, y in pow_inputs(n):
        out.append(line("pow", [x, y], mp.power(mpf(x), mpf(y))))
    for x in sin_cos_inputs(n):
        with mp.workprec(300 + max(0, math.frexp(x)[1])):
            s, c = mp.sin(mpf(x)), mp.cos(mpf(x))
        out.append(line("sin", [x], s))
        out.append(line("cos", [x], c))
    for x in asin_inputs(n):
        out.append(line("asin", [x], mp.asin(x)))
    for y, x in atan2_inputs(3 * n // 2):
        out.append(line("atan2", [y, x], mp.atan2(mpf(y), mpf(x))))
    sys.stdout.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
