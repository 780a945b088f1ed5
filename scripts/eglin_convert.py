#!/usr/bin/env python3
"""The four Eglin CFD releases of AbdullahElyas/GPR_StoreSeparation as sepval telemetry files.

    scripts/eglin_convert.py REPO OUT_DIR

REPO is a git clone of https://github.com/AbdullahElyas/GPR_StoreSeparation (the files are
read at commit 1949f78, the one ../shared/data/eglin-cfd/README.md cites); OUT_DIR receives
M085_AOA0.csv, M085_AOA4.csv, M095_AOA0.csv and M095_AOA4.csv. The conversion is the README's
(Fluent frame S: x aft, y up, z port; x_m = -CG_X, y_m = -CG_Z, z_m = -CG_Y; THETA_X/Y/Z as
Fluent's 6DOF Euler angles, body->S = Rz Ry Rx; 3-2-1 Euler angles of the body in the launch
frame; every 10th row, t = 0 to 0.5 s), so that M095_AOA0.csv has the same samples as the
shipped ../shared/data/eglin-cfd/M095_AOA0.csv (checked by `--check SHIPPED_CSV`). Each file
carries its flight condition as metadata (`# mach`, `# alpha_deg`, `# altitude_m`: 26 000 ft,
the repository's RegressionModel.m), which sepval reads (docs/model.md section 6).

The repository states no licence: the files are for measuring, not for shipping (the README's
caveat). Python's standard library only.
"""

import math
import subprocess
import sys

COMMIT = "1949f78123003af12447f2bde289f75cd0663c82"
CASES = [("M085_AOA0", 0.85, 0.0), ("M085_AOA4", 0.85, 4.0), ("M095_AOA0", 0.95, 0.0),
         ("M095_AOA4", 0.95, 4.0)]
ALTITUDE_M = 7924.8  # 26 000 ft
# S to L: x_L = -x_S, y_L = -z_S, z_L = -y_S (a proper rotation).
S_TO_L = [[-1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, -1.0, 0.0]]


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def transpose(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def rotation(axis, deg):
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    if axis == "x":
        return [[1, 0, 0], [0, c, -s], [0, s, c]]
    if axis == "y":
        return [[c, 0, s], [0, 1, 0], [-s, 0, c]]
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]]


def rows_of(repo, case):
    text = subprocess.run(
        ["git", "-C", repo, "show", f"{COMMIT}:Sim_Data/{case}/{case}_store.6dof"],
        capture_output=True, text=True, check=True).stdout
    return [[float(v) for v in line.split()] for line in text.splitlines()
            if line.strip() and not line.startswith("#")]


def samples(rows):
    """(t, x, y, z, roll, pitch, yaw) every 10th row to 0.5 s, in the launch frame."""
    origin = rows[0][1:4]
    out = []
    for t, x, y, z, tx, ty, tz in rows[::10]:
        if t > 0.5 + 1e-9:
            break
        body_to_s = matmul(matmul(rotation("z", tz), rotation("y", ty)), rotation("x", tx))
        r = matmul(matmul(S_TO_L, body_to_s), transpose(S_TO_L))
        yaw = math.degrees(math.atan2(r[1][0], r[0][0]))
        pitch = math.degrees(-math.asin(max(-1.0, min(1.0, r[2][0]))))
        roll = math.degrees(math.atan2(r[2][1], r[2][2]))
        d = [x - origin[0], y - origin[1], z - origin[2]]
        p = [sum(S_TO_L[i][k] * d[k] for k in range(3)) for i in range(3)]
        # + 0.0: no "-0.0000" where the angle is -0 at release.
        out.append([t] + [v + 0.0 for v in p + [roll, pitch, yaw]])
    return out


def write(path, case, mach, alpha, rows):
    with open(path, "w") as f:
        f.write(f"# event: Eglin wing/pylon/store, {case}\n")
        f.write(f"# source: https://github.com/AbdullahElyas/GPR_StoreSeparation (commit {COMMIT}) "
                f"path Sim_Data/{case}/{case}_store.6dof\n")
        f.write("# source licence: none stated - redistribution rights unclear: do not ship\n")
        f.write(f"# Fluent CFD trajectory (not flight test): Mach {mach}, aircraft angle of attack "
                f"{alpha:g} deg, 26000 ft; converted as ../shared/data/eglin-cfd/README.md says\n")
        f.write(f"# mach = {mach}\n# alpha_deg = {alpha:g}\n# altitude_m = {ALTITUDE_M}\n")
        f.write("t_s,x_m,y_m,z_m,roll_deg,pitch_deg,yaw_deg\n")
        for r in rows:
            f.write("%.3f,%.6f,%.6f,%.6f,%.4f,%.4f,%.4f\n" % tuple(r))


def data_lines(path):
    with open(path) as f:
        return [l for l in f if not l.startswith("#")]


def main(argv):
    if len(argv) not in (3, 5) or (len(argv) == 5 and argv[3] != "--check"):
        sys.exit("usage: scripts/eglin_convert.py REPO OUT_DIR [--check SHIPPED_M095_AOA0_CSV]")
    repo, out = argv[1], argv[2]
    for case, mach, alpha in CASES:
        write(f"{out}/{case}.csv", case, mach, alpha, samples(rows_of(repo, case)))
    if len(argv) == 5:
        if data_lines(f"{out}/M095_AOA0.csv") != data_lines(argv[4]):
            sys.exit(f"{out}/M095_AOA0.csv differs from {argv[4]}: the conversion is not the README's")
        print(f"{out}/M095_AOA0.csv has the samples of {argv[4]}")


if __name__ == "__main__":
    main(sys.argv)
