#!/usr/bin/env python3
"""The Eglin CFD store's own loads at the four conditions of AbdullahElyas/GPR_StoreSeparation.

    scripts/eglin_loads.py REPO                      (the table below)
    scripts/eglin_loads.py REPO --ca0-without NAME   (a scenario's `ca0` line)

REPO is a git clone of https://github.com/AbdullahElyas/GPR_StoreSeparation (read at the
commit scripts/eglin_convert.py reads). Its simData.mat holds, per condition, the store's
forces and moments at each of the 1001 CFD time steps (0 to 0.5 s), which the repository's
SimData.m integrates from the surface pressure: the store's aerodynamics measured directly, not
through its trajectory. The file is MATLAB objects (MCOS), which scipy reads only as opaque
data; this script takes the objects' property cells out of the file's function workspace, finds
each condition's block (Mach, alpha, sideslip, altitude, then the body-axis and inertial-axis
loads, then the condition's name: SimData.m's property order) and prints the body-axis axial
force as a coefficient, F_x / (qbar S), over 0.1 s windows, with qbar from the ISA at 26 000 ft
and S of the 20 in store (docs/model.md section 1). With `--ca0-without NAME` (e.g.
M095_AOA0) it prints instead the store's CA over Mach as a scenario's `ca0` table: at each
Mach, the mean over 0 to 0.5 s of the releases at that Mach other than NAME (for a study that
leaves NAME out, so that nothing of it is used).

The sign and axes of SimData.m's body frame are the author's (its x along the store, positive
aft as a drag); this script does not re-derive them. The repository states no licence: read
for measuring, nothing shipped. Needs numpy and scipy (not the CI's).
"""

import io
import math
import subprocess
import sys

import numpy as np
import scipy.io
from scipy.io.matlab._mio5 import MatFile5Reader

COMMIT = "1949f78123003af12447f2bde289f75cd0663c82"
ALTITUDE_M = 7924.8  # 26 000 ft
AREA_M2 = math.pi * 0.254**2  # the 20 in store's reference area


def isa(h_m):
    """ISA troposphere: (density [kg/m^3], speed of sound [m/s]) at h_m."""
    t = 288.15 - 0.0065 * h_m
    p = 101325.0 * (t / 288.15) ** 5.255877
    return p / (287.05287 * t), math.sqrt(1.4 * 287.05287 * t)


def property_cells(path):
    """The property cells of the MCOS objects in the MAT file at `path`."""
    workspace = scipy.io.loadmat(path)["__function_workspace__"].tobytes()
    # The workspace is a MAT stream without the file's 128-byte header: give it one.
    header = b"MATLAB 5.0 MAT-file".ljust(116, b" ") + b"\0" * 8 + workspace[0:4]
    reader = MatFile5Reader(io.BytesIO(header + workspace[8:]), squeeze_me=False)
    reader.initialize_read()
    reader.mat_stream.seek(128)
    var, _ = reader.read_var_header()
    mcos = reader.read_var_array(var, process=True)[0, 0]["MCOS"][0]
    return mcos["arr"].ravel()


def conditions(cells):
    """(name, mach, alpha_deg, body-axis force [3 x n]) of each condition's block."""
    out = []
    for i in range(len(cells) - 9):
        mach, name = cells[i], cells[i + 9]
        if (isinstance(mach, np.ndarray) and mach.shape == (1, 1) and mach.dtype == np.float64
                and isinstance(name, np.ndarray) and name.dtype.kind == "U"):
            force = np.asarray(cells[i + 7][0, 0]["Force"], dtype=float)
            out.append((str(name[0]), float(mach[0, 0]), float(cells[i + 1][0, 0]), force))
    return out


def ca0_line(found, without, rho, a):
    """The scenario line `ca0 = { mach = [...], values = [...] }` from the releases but
    `without`."""
    by_mach = {}
    for name, mach, _, force in found:
        if name != without:
            qs = 0.5 * rho * (mach * a) ** 2 * AREA_M2
            by_mach.setdefault(mach, []).append(force[0].mean() / qs)
    machs = sorted(by_mach)
    values = [sum(by_mach[m]) / len(by_mach[m]) for m in machs]
    return (f"ca0 = {{ mach = [{', '.join(repr(m) for m in machs)}], "
            f"values = [{', '.join(f'{v:.4f}' for v in values)}] }}")


def main():
    args = sys.argv[1:]
    if len(args) not in (1, 3) or (len(args) == 3 and args[1] != "--ca0-without"):
        sys.exit(__doc__)
    repo = args[0]
    data = subprocess.run(["git", "-C", repo, "show", f"{COMMIT}:simData.mat"], check=True,
                          capture_output=True).stdout
    found = conditions(property_cells(io.BytesIO(data)))
    if len(found) != 4:
        sys.exit(f"expected the four conditions' loads in simData.mat, found {len(found)}")
    rho, a = isa(ALTITUDE_M)
    if len(args) == 3:
        if args[2] not in [f[0] for f in found]:
            sys.exit(f"--ca0-without {args[2]}: no such condition in simData.mat")
        print(ca0_line(found, args[2], rho, a))
        return
    windows = [(0.0, 0.1), (0.1, 0.2), (0.2, 0.3), (0.3, 0.4), (0.4, 0.5)]
    print("| condition | qbar S [N] | " + " | ".join(f"CA {lo:.1f}-{hi:.1f} s" for lo, hi in windows)
          + " |")
    print("|---" * (2 + len(windows)) + "|")
    for name, mach, alpha, force in sorted(found):
        qs = 0.5 * rho * (mach * a) ** 2 * AREA_M2
        t = np.linspace(0.0, 0.5, force.shape[1])
        cells = []
        for lo, hi in windows:
            inside = (t >= lo) & (t < hi if hi < 0.5 else t <= hi)
            cells.append(f"{force[0, inside].mean() / qs:.3f}")
        print(f"| {name} (Mach {mach}, alpha {alpha:g} deg) | {qs:.0f} | " + " | ".join(cells)
              + " |")


if __name__ == "__main__":
    main()
