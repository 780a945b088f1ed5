#!/usr/bin/env python3
"""The Eglin CFD store's own loads at the four conditions of AbdullahElyas/GPR_StoreSeparation.

    scripts/eglin_loads.py REPO                      (the axial force table)
    scripts/eglin_loads.py REPO --moments            (normal force, moments, derivatives)
    scripts/eglin_loads.py REPO --ca0-without NAME   (a scenario's `ca0` line)
    scripts/eglin_loads.py REPO --depth              (the late loads against the depth)

REPO is a git clone of https://github.com/AbdullahElyas/GPR_StoreSeparation (read at COMMIT).
Its simData.mat holds, per condition, the store's pressure force and moment about the CG at
each of the 1001 CFD time steps (0 to 0.5 s), which the repository's SimData.m integrates from
the surface pressure: the store's aerodynamics measured directly, not through its trajectory.
The file is MATLAB objects (MCOS), which scipy reads only as opaque data; this script takes the
objects' property cells out of the file's function workspace and finds each condition's block
(Mach, alpha, sideslip, altitude, then the body-axis and the inertial-axis loads, then the
condition's name: SimData.m's property order).

**The axes.** SimData.m's "body-axis" loads are its inertial ones multiplied by T, where T
(axang2rotm of the 6DOF file's THETA) maps body to inertial axes, as its own mapping of the
store's surface shows (centroid = T * body point + CG); body axes need T's transpose. The
file's body loads are therefore rotated twice the store's attitude the wrong way: after release,
where the store pitches 6 to 12 deg, its axial force takes in 20 to 40 % of the normal force
(checked at t = 0.3 s of M085_AOA0: the file's body force equals R times its inertial force
to 1 % of its magnitude, R below, not R^T times it). This script reads the
INERTIAL loads and rotates them itself, body = R^T inertial, R = Rz(THETA_Z) Ry(THETA_Y)
Rx(THETA_X) (Fluent's 6DOF Euler angles, shared/data/eglin-cfd/README.md; SimData.m's
axis-angle reading differs by at most 1.5 deg). The inertial loads are checked against the
trajectory: m a - F equals the weight (8 896 N, less 0.3 % at alpha 4 deg) in y, 0 +- 50 N in z,
and in x a constant 240 to 300 N of drag the pressure does not hold (the viscous force; at the
aircraft's alpha 4 deg plus m g sin 4 deg): the pressure loads are the whole aerodynamic load
but the friction, which the script prints as `CA visc`.

Frames: the CFD's (x aft, y up, z to port; the store's body axes the same at t = 0); the store's
flow angles from its velocity (the 6DOF file's CG differenced) against the freestream
V (cos alpha_a, sin alpha_a, 0) in those axes. Printed in docs/model.md's sense: CA aft, CN up,
CY right, Cm nose up, Cn nose right, Cl right wing down (about the forward axis: minus the
moment about the CFD's aft x), about the CG, on qbar S d of the 20 in store, qbar from the
ISA at 26 000 ft (the nose's stagnation pressure in the pressure files agrees: 25.9 kPa gauge
against 28.3 at Mach 0.95 there, 80 at sea level).

With `--depth` it asks whether the late loads are the store's alone (issue 61): for a store in
uniform flow the crossflow force and moment depend on the flow angles and Mach only, not on
where the store is. Per release every 0.025 s from 0.15 s it prints the depth below carriage,
the total incidence sigma (alpha and beta combined), the force along the crossflow direction
(alpha, -beta) / sigma and its secant over sigma, and the centre of pressure's distance behind
the CG in calibres in the pitch plane (-Cm / CN), the yaw plane (-Cn / CY) and combined (the
moment along the crossflow over the force along it). A cruciform store in uniform flow has the
same arm in both planes (its fins at +-45 deg are symmetric under a quarter turn). Then, per
Mach, least squares over t >= 0.2 s of both releases: arm = a + b sigma + c depth and the same
for the secant, with and without the depth term.

With `--ca0-without NAME` (e.g. M095_AOA0) it prints the store's CA over Mach as a scenario's
`ca0` table: at each Mach, the mean over 0 to 0.5 s of the releases at that Mach other than
NAME, pressure and viscous parts. The repository states no licence: read for measuring, nothing
shipped. Needs numpy and scipy (not the CI's).
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
DIAMETER_M = 0.508
AREA_M2 = math.pi * (DIAMETER_M / 2) ** 2  # the 20 in store's reference area
MASS_KG = 907.185  # 2000 lb
INERTIA_KG_M2 = (27.116, 488.094, 488.094)  # Ixx (the axis), Iyy = Izz: the CFD's store
G_M_S2 = 9.80665
# The late part of a release, where the store is 0.9 m or more below its carriage (at 0.25 s).
LATE_S = (0.25, 0.35)


def isa(h_m):
    """ISA troposphere: (density [kg/m^3], speed of sound [m/s]) at h_m."""
    t = 288.15 - 0.0065 * h_m
    p = 101325.0 * (t / 288.15) ** 5.255877
    return p / (287.05287 * t), math.sqrt(1.4 * 287.05287 * t)


def property_cells(data):
    """The property cells of the MCOS objects in the MAT file `data` (a file or path)."""
    workspace = scipy.io.loadmat(data)["__function_workspace__"].tobytes()
    # The workspace is a MAT stream without the file's 128-byte header: give it one.
    header = b"MATLAB 5.0 MAT-file".ljust(116, b" ") + b"\0" * 8 + workspace[0:4]
    reader = MatFile5Reader(io.BytesIO(header + workspace[8:]), squeeze_me=False)
    reader.initialize_read()
    reader.mat_stream.seek(128)
    var, _ = reader.read_var_header()
    mcos = reader.read_var_array(var, process=True)[0, 0]["MCOS"][0]
    return mcos["arr"].ravel()


def conditions(cells):
    """(name, mach, alpha_deg, inertial force [3 x n], inertial moment [3 x n]) per block."""
    out = []
    for i in range(len(cells) - 9):
        mach, name = cells[i], cells[i + 9]
        if (isinstance(mach, np.ndarray) and mach.shape == (1, 1) and mach.dtype == np.float64
                and isinstance(name, np.ndarray) and name.dtype.kind == "U"):
            loads = cells[i + 8][0, 0]
            out.append((str(name[0]), float(mach[0, 0]), float(cells[i + 1][0, 0]),
                        np.asarray(loads["Force"], dtype=float),
                        np.asarray(loads["Moment"], dtype=float)))
    return out


def git_show(repo, path):
    """The bytes of `path` at COMMIT in `repo`."""
    return subprocess.run(["git", "-C", repo, "show", f"{COMMIT}:{path}"], check=True,
                          capture_output=True).stdout


def rotation(theta_deg):
    """Body to CFD axes, Rz Ry Rx of Fluent's 6DOF angles (THETA_X, _Y, _Z) [deg]."""
    x, y, z = np.radians(theta_deg)
    cx, sx, cy, sy, cz, sz = math.cos(x), math.sin(x), math.cos(y), math.sin(y), math.cos(z), \
        math.sin(z)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


class Release:
    """One condition's loads as coefficients in the store's body axes, with its flow angles."""

    def __init__(self, repo, name, mach, alpha_deg, force, moment):
        self.name, self.mach, self.alpha_a_deg = name, mach, alpha_deg
        text = git_show(repo, f"Sim_Data/{name}/{name}_store.6dof").decode()
        six = np.loadtxt(io.StringIO(text), comments="#")
        if six.shape[0] != force.shape[1]:
            sys.exit(f"{name}: {six.shape[0]} 6DOF rows against {force.shape[1]} load steps")
        self.t = six[:, 0]
        rho, a = isa(ALTITUDE_M)
        v = mach * a
        self.qs = 0.5 * rho * v * v * AREA_M2
        self.depth_m = six[0, 2] - six[:, 2]  # below the carriage position (y is up)
        self.six, self.moment = six, moment
        velocity = np.gradient(six[:, 1:4], self.t, axis=0)
        acc = np.gradient(velocity, self.t, axis=0)
        al = math.radians(alpha_deg)
        wind = v * np.array([math.cos(al), math.sin(al), 0.0])
        rs = np.array([rotation(th) for th in six[:, 4:7]])
        rates = np.gradient(rs, self.t, axis=0)
        self.coef = np.zeros((len(self.t), 9))
        for k, r in enumerate(rs):
            w = r.T @ (wind - velocity[k])
            omega = r.T @ rates[k]  # skew: body rates
            f, m = r.T @ force[:, k], r.T @ moment[:, k]
            speed = np.linalg.norm(w)
            hat = DIAMETER_M / (2 * speed)
            self.coef[k] = (math.atan2(w[1], w[0]), math.asin(w[2] / speed),
                            -omega[1, 0] * hat, f[0] / self.qs, f[1] / self.qs, -f[2] / self.qs,
                            -m[2] / (self.qs * DIAMETER_M), -m[1] / (self.qs * DIAMETER_M),
                            -m[0] / (self.qs * DIAMETER_M))
        gravity_x = MASS_KG * G_M_S2 * math.sin(al)
        inside = (self.t >= 0.1) & (self.t <= 0.45)
        self.ca_visc = np.mean(MASS_KG * acc[inside, 0] - force[0, inside] - gravity_x) / self.qs

    def column(self, name):
        """alpha, beta [rad], qhat, CA, CN, CY, Cm, Cn or Cl over time."""
        return self.coef[:, ["alpha", "beta", "qhat", "CA", "CN", "CY", "Cm", "Cn", "Cl"]
                         .index(name)]

    def window_mean(self, name, lo, hi):
        """The mean of column `name` over lo <= t < hi (t <= hi at the end)."""
        inside = (self.t >= lo) & (self.t < hi if hi < 0.5 else self.t <= hi)
        return float(self.column(name)[inside].mean())

    def slopes(self, t0, with_rate):
        """Least squares over t >= t0 of CN = n0 + CN_alpha alpha and Cm = m0 + Cm_alpha alpha
        (+ Cm_q qhat with `with_rate`): (CN_alpha, Cm_alpha, Cm_q or None, rms of Cm)."""
        late = self.t >= t0
        alpha = self.column("alpha")[late]
        ones = np.ones(late.sum())
        x_cn = np.array([ones, alpha]).T
        cn_fit = np.linalg.lstsq(x_cn, self.column("CN")[late], rcond=None)[0]
        cols = [ones, alpha] + ([self.column("qhat")[late]] if with_rate else [])
        x_cm = np.array(cols).T
        cm = self.column("Cm")[late]
        cm_fit = np.linalg.lstsq(x_cm, cm, rcond=None)[0]
        rms = float(np.sqrt(np.mean((x_cm @ cm_fit - cm) ** 2)))
        return cn_fit[1], cm_fit[1], (cm_fit[2] if with_rate else None), rms


def releases(repo):
    """The four releases, read and rotated."""
    found = conditions(property_cells(io.BytesIO(git_show(repo, "simData.mat"))))
    if len(found) != 4:
        sys.exit(f"expected the four conditions' loads in simData.mat, found {len(found)}")
    return sorted((Release(repo, *f) for f in found), key=lambda r: r.name)


def ca0_line(found, without):
    """The scenario line `ca0 = { mach = [...], values = [...] }` from the releases but
    `without` (pressure and viscous axial force, body axes)."""
    by_mach = {}
    for r in found:
        if r.name != without:
            by_mach.setdefault(r.mach, []).append(r.window_mean("CA", 0.0, 0.5) + r.ca_visc)
    machs = sorted(by_mach)
    values = [sum(by_mach[m]) / len(by_mach[m]) for m in machs]
    return (f"ca0 = {{ mach = [{', '.join(repr(m) for m in machs)}], "
            f"values = [{', '.join(f'{v:.4f}' for v in values)}] }}")


def axial_table(found):
    """The pressure axial force over 0.1 s windows, and the viscous part."""
    windows = [(0.0, 0.1), (0.1, 0.2), (0.2, 0.3), (0.3, 0.4), (0.4, 0.5)]
    heads = " | ".join(f"CA {lo:.1f}-{hi:.1f} s" for lo, hi in windows)
    print(f"| condition | qbar S [N] | {heads} | CA visc |")
    print("|---" * (3 + len(windows)) + "|")
    for r in found:
        cells = [f"{r.window_mean('CA', lo, hi):.3f}" for lo, hi in windows]
        print(f"| {r.name} (Mach {r.mach}, alpha {r.alpha_a_deg:g} deg) | {r.qs:.0f} | "
              + " | ".join(cells) + f" | {r.ca_visc:.3f} |")


def moments_table(found):
    """Every 0.05 s: the flow angles and the six coefficients; then the late slopes."""
    for r in found:
        print(f"\n{r.name} (Mach {r.mach}, aircraft alpha {r.alpha_a_deg:g} deg; "
              f"CA visc {r.ca_visc:.3f})")
        print("| t [s] | alpha [deg] | beta [deg] | CA | CN | CY | Cm | Cn | Cl |")
        print("|---" * 9 + "|")
        for k in range(0, len(r.t), 50):
            c = r.coef[k]
            print(f"| {r.t[k]:.2f} | {math.degrees(c[0]):.2f} | {math.degrees(c[1]):.2f} | "
                  + " | ".join(f"{v:.3f}" for v in c[3:]) + " |")
    print("\nLate slopes (least squares over t >= t0; alpha in rad; x_cp - x_cg = -Cm_alpha / "
          "CN_alpha calibres):")
    print("| condition | t0 [s] | alpha range [deg] | max abs beta [deg] | CN_alpha | Cm_alpha | "
          "x_cp - x_cg [cal] | with Cm_q: Cm_alpha, Cm_q | rms Cm |")
    print("|---" * 9 + "|")
    for r in found:
        for t0 in LATE_S:
            late = r.t >= t0
            al = np.degrees(r.column("alpha")[late])
            be = np.degrees(np.abs(r.column("beta")[late])).max()
            cn_a, cm_a, _, rms = r.slopes(t0, False)
            _, cm_a_q, cm_q, rms_q = r.slopes(t0, True)
            print(f"| {r.name} | {t0:.2f} | {al.min():.1f} to {al.max():.1f} | {be:.1f} | "
                  f"{cn_a:.2f} | {cm_a:.2f} | {-cm_a / cn_a:.2f} | {cm_a_q:.2f}, {cm_q:.0f} | "
                  f"{rms:.3f}, {rms_q:.3f} |")


def incidence(r, k):
    """(sigma [rad], force along the crossflow, pitch arm, yaw arm, combined arm [cal]) at k."""
    alpha, beta, cn, cy, cm, cn_yaw = (r.coef[k, i] for i in (0, 1, 4, 5, 6, 7))
    sigma = math.hypot(alpha, beta)
    e_n, e_y = alpha / sigma, -beta / sigma
    along = cn * e_n + cy * e_y
    pitch = -cm / cn if abs(cn) > 0.2 else float("nan")
    yaw = -cn_yaw / cy if abs(cy) > 0.2 else float("nan")
    return sigma, along, pitch, yaw, -(cm * e_n + cn_yaw * e_y) / along


def depth_fit(found, mach):
    """Least squares over the samples at `mach` after 0.15 s where the crossflow is mostly in
    the pitch plane (abs alpha >= 2 abs beta): the pitch arm and the secant against sigma and
    depth. (n, depth range, [(coef, rms, rms without depth) for arm and secant])."""
    rows = [(r.depth_m[k],) + incidence(r, k) for r in found if r.mach == mach
            for k in range(len(r.t))
            if r.t[k] >= 0.15 and abs(r.coef[k, 0]) >= 2 * abs(r.coef[k, 1])]
    depth, sigma, along, pitch, _, _ = (np.array(c) for c in zip(*rows))
    out = []
    for y in (pitch, along / sigma):
        full = np.array([np.ones_like(depth), sigma, depth]).T
        coef = np.linalg.lstsq(full, y, rcond=None)[0]
        rms = float(np.sqrt(np.mean((full @ coef - y) ** 2)))
        part = full[:, :2]
        rms_without = float(np.sqrt(np.mean((part @ np.linalg.lstsq(part, y, rcond=None)[0]
                                             - y) ** 2)))
        out.append((coef, rms, rms_without))
    return len(rows), depth.min(), depth.max(), out


def quarter_turn(found):
    """Samples with abs alpha = abs beta to 0.3 deg (t >= 0.15 s): a store whose fins sit at
    +-45 deg is symmetric about the plane between pitch and yaw, so in uniform flow there
    abs CN = abs CY and abs Cm = abs Cn."""
    print("\nThe quarter-turn test: abs alpha = abs beta (to 0.3 deg), where a symmetric store in "
          "uniform flow has abs CN = abs CY and abs Cm = abs Cn")
    print("| release | t [s] | depth [m] | alpha, beta [deg] | CN, CY | Cm, Cn | "
          "CN/CY | Cm/Cn |")
    print("|---" * 8 + "|")
    for r in found:
        for k in range(len(r.t)):
            alpha, beta, cn, cy, cm, cn_yaw = (r.coef[k, i] for i in (0, 1, 4, 5, 6, 7))
            near = abs(abs(alpha) - abs(beta)) < math.radians(0.3)
            if r.t[k] >= 0.15 and near and k % 10 == 0:
                print(f"| {r.name} | {r.t[k]:.3f} | {r.depth_m[k]:.2f} | "
                      f"{math.degrees(alpha):.2f}, {math.degrees(beta):.2f} | {cn:.3f}, {cy:.3f} | "
                      f"{cm:.3f}, {cn_yaw:.3f} | {abs(cn / cy):.2f} | {abs(cm / cn_yaw):.2f} |")


def motion_check(found):
    """The moments read against the rigid-body motion over 0.1 to 0.48 s (after the stroke):
    I dw/dt + w x I w (body axes, w from the 6DOF angles) against the pressure moment rotated
    to body axes: the gain (least squares) and the rms difference per axis."""
    inertia = np.diag(INERTIA_KG_M2)
    print("\nThe moments against the motion, 0.1 to 0.48 s: I w' + w x I w = gain M (least "
          "squares), rms of the difference against rms M [N m]")
    print("| release | roll (CFD x) | pitch (CFD z) | yaw (CFD y) |")
    print("|---" * 4 + "|")
    for r in found:
        rs = np.array([rotation(th) for th in r.six[:, 4:7]])
        rates = np.gradient(rs, r.t, axis=0)
        w = np.array([[(a.T @ b)[2, 1], (a.T @ b)[0, 2], (a.T @ b)[1, 0]]
                      for a, b in zip(rs, rates)])
        lhs = np.gradient(w, r.t, axis=0) @ inertia + np.cross(w, w @ inertia)
        m = np.array([a.T @ r.moment[:, k] for k, a in enumerate(rs)])
        inside = (r.t >= 0.1) & (r.t <= 0.48)
        cells = []
        for axis in (0, 2, 1):
            a, b = lhs[inside, axis], m[inside, axis]
            gain = float(a @ b / (b @ b))
            cells.append(f"{gain:.3f}, {np.sqrt(np.mean((a - b) ** 2)):.0f} of "
                         f"{np.sqrt(np.mean(b ** 2)):.0f}")
        print(f"| {r.name} | " + " | ".join(cells) + " |")


def depth_table(found):
    """The late loads against the depth below carriage, the quarter-turn test, the fits."""
    for r in found:
        print(f"\n{r.name} (Mach {r.mach}, aircraft alpha {r.alpha_a_deg:g} deg)")
        print("| t [s] | depth [m] | alpha [deg] | beta [deg] | sigma [deg] | force along | "
              "secant [1/rad] | arm pitch [cal] | arm yaw | arm combined |")
        print("|---" * 10 + "|")
        for k in range(300, len(r.t), 50):
            sigma, along, pitch, yaw, arm = incidence(r, k)
            print(f"| {r.t[k]:.3f} | {r.depth_m[k]:.2f} | {math.degrees(r.coef[k, 0]):.2f} | "
                  f"{math.degrees(r.coef[k, 1]):.2f} | {math.degrees(sigma):.2f} | {along:.3f} | "
                  f"{along / sigma:.2f} | {pitch:.2f} | {yaw:.2f} | {arm:.2f} |")
    quarter_turn(found)
    motion_check(found)
    print("\nBoth releases at each Mach, t >= 0.15 s, abs alpha >= 2 abs beta (sigma in rad, "
          "depth in m): y = a + b sigma + c depth")
    print("| Mach | samples | depth [m] | y | a, b, c | rms | rms without depth |")
    print("|---" * 7 + "|")
    for mach in sorted({r.mach for r in found}):
        n, lo, hi, fits = depth_fit(found, mach)
        for label, (coef, rms, rms_without) in zip(("pitch arm [cal]", "secant [1/rad]"), fits):
            print(f"| {mach} | {n} | {lo:.2f} to {hi:.2f} | {label} | "
                  f"{coef[0]:.2f}, {coef[1]:.2f}, {coef[2]:.2f} | {rms:.3f} | "
                  f"{rms_without:.3f} |")


def main():
    args = sys.argv[1:]
    ok = (len(args) == 1 or (len(args) == 2 and args[1] in ("--moments", "--depth"))
          or (len(args) == 3 and args[1] == "--ca0-without"))
    if not ok:
        sys.exit(__doc__)
    found = releases(args[0])
    if len(args) == 3:
        if args[2] not in [r.name for r in found]:
            sys.exit(f"--ca0-without {args[2]}: no such condition in simData.mat")
        print(ca0_line(found, args[2]))
    elif len(args) == 1:
        axial_table(found)
    elif args[1] == "--depth":
        depth_table(found)
    else:
        moments_table(found)


if __name__ == "__main__":
    main()
