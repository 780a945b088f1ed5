#!/usr/bin/env python3
"""Linear slender-body theory of a store whose fins may span its boattail (docs/aero.md, "Which
of the three"): a by-hand check beside the component build-up of `sepval aero`, not part of it.

    python3 examples/eglin-store/slender_body.py examples/eglin-store/shape.toml
    python3 examples/eglin-store/slender_body.py aero/tests/data/arcas-long.toml

The store TOML of docs/geometry.md (a tangent-ogive or conical nose, a cylinder, an optional
conical boattail, four clipped-delta fins with the trailing edge square to the axis). Slender-
body theory (Munk, NACA Rep. 184; Nielsen, *Missile Aerodynamics*, 1960, ch. 3 and 5): the normal
force per length is dN/dx = 2 qbar alpha dS_app/dx, where the apparent-mass area is S_app = pi r^2
for the body alone and pi (s^2 - r^2 + r^4 / s^2) for the body of radius r with fins of tip
radius s (the planar pair; slender-body theory gives a cruciform the same lift at any roll). The
fins' lift is held behind their trailing edge (their wake), and the bare body behind them is
taken alone, from its radius at the trailing edge to the base. It is the theory the build-up's
interference factors come from (Pitts, Nielsen and Kaattari, NACA Rep. 1307): over a cylinder its
fins give K_W(B) + K_B(W) = (1 + tau)^2 times the panels' slender-wing lift; it differs from the
build-up where the fins span a boattail (the build-up takes the bare boattail's lift loss there).
Standard library only; midpoint sums over 200 000 steps.
"""

import math
import sys
import tomllib

STEPS = 200_000


def read(path):
    """The shape's dimensions from the store TOML at `path`."""
    with open(path, "rb") as f:
        cfg = tomllib.load(f)
    body, fins = cfg["body"], cfg["fins"]
    if fins.get("count") != 4:
        sys.exit(f"{path}: fins.count must be 4 for this check")
    return body, fins


def radius_fn(body):
    """The body's radius at x from the nose tip."""
    length, r0, ln = body["length_m"], body["diameter_m"] / 2, body["nose_length_m"]
    lbt = body.get("boattail_length_m", 0.0)
    rb = body.get("base_diameter_m", body["diameter_m"]) / 2
    big_r = (r0 * r0 + ln * ln) / (2 * r0)
    ogive = body.get("nose_shape", "ogive") == "ogive"

    def radius(x):
        if x <= 0:
            return 0.0
        if x < ln:
            return math.sqrt(big_r ** 2 - (ln - x) ** 2) + r0 - big_r if ogive else r0 * x / ln
        if lbt <= 0 or x < length - lbt:
            return r0
        return r0 - (r0 - rb) * (x - (length - lbt)) / lbt

    return radius


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    body, fins = read(sys.argv[1])
    radius = radius_fn(body)
    length, d, x_cg = body["length_m"], body["diameter_m"], body["cg_from_nose_m"]
    r0 = d / 2
    x_le, c_r, c_t = fins["leading_edge_from_nose_m"], fins["root_chord_m"], fins["tip_chord_m"]
    span = fins["span_m"]
    x_te, s_tip = x_le + c_r, r0 + span
    # The leading edge's run along the axis per unit of span (0: a rectangular panel).
    run = (c_r - c_t) / span

    def tip(x):
        if x < x_le or x > x_te:
            return 0.0
        return s_tip if run == 0 else min(r0 + (x - x_le) / run, s_tip)

    def s_app(x):
        r, s = radius(x), tip(x)
        return math.pi * (s * s - r * r + r ** 4 / (s * s)) if s > r else math.pi * r * r

    area = math.pi * r0 * r0
    step = x_te / STEPS
    cn = moment = 0.0
    prev = s_app(0.0)
    for i in range(1, STEPS + 1):
        now = s_app(i * step)
        cn += 2 * (now - prev) / area
        moment += 2 * (now - prev) / area * (i - 0.5) * step
        prev = now
    rb = body.get("base_diameter_m", d) / 2
    behind = 2 * math.pi * (rb * rb - radius(x_te) ** 2) / area
    cn += behind
    moment += behind * (x_te + length) / 2
    x_cp = moment / cn
    print(f"{sys.argv[1]}: CN_alpha {cn:.3f} per rad, x_cp {x_cp:.3f} m from the nose "
          f"({100 * x_cp / length:.1f} % of the length), Cm_alpha {-cn * (x_cp - x_cg) / d:.3f} "
          f"per rad about the CG at {x_cg} m")


if __name__ == "__main__":
    main()
