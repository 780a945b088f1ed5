#!/usr/bin/env python3
"""An independent check of sepval-aero's build-up (docs/aero.md): the Basic Finner's and the
Arcas long model's CN_alpha, centre of pressure, Cm_alpha, Cm_q and Cl_p recomputed from the
equations of docs/aero.md with the standard library only (no code shared with the crate), and
printed beside the published values. The crate's test `independent_check` holds these numbers.

Usage: python3 scripts/aero_check.py
"""
import math

PI = math.pi


def k_factors(tau):
    """Pitts, Nielsen and Kaattari (NACA Report 1307), slender-body theory."""
    u = 1 / tau - tau
    kwb = (2 / PI) * ((1 + tau**4) * (0.5 * math.atan(0.5 * u) + PI / 4)
                      - tau**2 * (u + 2 * math.atan(tau))) / (1 - tau) ** 2
    return kwb, (1 + tau) ** 2 - kwb


def pair_slope(a, tan_half, mach):
    """Helmbold-Diederich below 0.8, Ackeret with the tip correction from M_sup, a line between."""
    m_sup = max(1.1, math.sqrt(1 + 1 / a**2))
    helm = lambda m: 2 * PI * a / (2 + math.sqrt(4 + a * a * (1 - m * m + tan_half**2)))
    ack = lambda m: 4 / math.sqrt(m * m - 1) * (1 - 1 / (2 * a * math.sqrt(m * m - 1)))
    if mach <= 0.8:
        return helm(mach), 0.0
    if mach >= m_sup:
        return ack(mach), 1.0
    w = (mach - 0.8) / (m_sup - 0.8)
    return helm(0.8) + w * (ack(m_sup) - helm(0.8)), w


def radius(x, s):
    r, ln = s["d"] / 2, s["ln"]
    if x < ln:
        if s["nose"] == "cone":
            return r * x / ln
        rho = (r * r + ln * ln) / (2 * r)
        return math.sqrt(max(rho * rho - (ln - x) ** 2, 0)) + r - rho
    start = s["L"] - s["lbt"]
    if s["lbt"] <= 0 or x <= start:
        return r
    return r + (s["db"] / 2 - r) * (x - start) / s["lbt"]


def estimate(s, mach):
    d, sref = s["d"], PI * s["d"] ** 2 / 4
    n = 20000
    h = s["ln"] / n
    vol = sum(PI * radius((i + 0.5) * h, s) ** 2 * h for i in range(n))  # midpoint
    cn_b, mom = 2.0, 2.0 * (s["ln"] - vol / sref)
    damp = 0.0
    hb = s["L"] / n
    for i in range(n):
        x0, x1 = i * hb, (i + 1) * hb
        ds = PI * (radius(x1, s) ** 2 - radius(x0, s) ** 2)
        damp += ds * ((x0 + x1) / 2 - s["cg"]) ** 2
    cm_q = -4 * damp / (sref * d * d)
    if s["lbt"] > 0:
        x1, x2 = s["L"] - s["lbt"], s["L"]
        s1, s2 = sref, PI * s["db"] ** 2 / 4
        r1, r2 = d / 2, s["db"] / 2
        vbt = PI * s["lbt"] / 3 * (r1 * r1 + r1 * r2 + r2 * r2)
        cn_bt = 2 * (s2 - s1) / sref
        cn_b += cn_bt
        mom += cn_bt * (x2 * s2 - x1 * s1 - vbt) / (s2 - s1)
    cr, ct, sp = s["cr"], s["ct"], s["span"]
    area = sp * (cr + ct) / 2
    a = 2 * sp * sp / area
    xt = cr - ct
    tan_half = (xt + (ct - cr) / 2) / sp
    cla, w = pair_slope(a, tan_half, mach)
    kwb, kbw = k_factors((d / 2) / (d / 2 + sp))
    cn_f = 0.5 * s["N"] * cla * area / sref * (kwb + kbw)
    sub = xt / 3 * (cr + 2 * ct) / (cr + ct) + (cr + ct - cr * ct / (cr + ct)) / 6
    # planform centroid by summing strips (the crate uses the closed form)
    m = 10000
    num = den = 0.0
    for j in range(m):
        e = (j + 0.5) / m
        c = cr - (cr - ct) * e
        num += c * (xt * e + c / 2)
        den += c
    xf = s["le"] + sub + w * (num / den - sub)
    cn = cn_b + cn_f
    xcp = (mom + cn_f * xf) / cn
    cm_a = -cn * (xcp - s["cg"]) / d
    cm_q += -2 * cn_f * ((xf - s["cg"]) / d) ** 2
    r = d / 2
    integ = sum((cr - (cr - ct) * (j + 0.5) / m) * (r + sp * (j + 0.5) / m) ** 2 * sp / m
                for j in range(m))
    cl_p = -2 * s["N"] * cla * integ / (sref * d * d)
    return dict(cn=cn, xcp=xcp, cm_a=cm_a, cm_q=cm_q, cl_p=cl_p, kwb=kwb, kbw=kbw)


ANF = dict(d=0.03, L=0.30, cg=0.165, ln=0.08508, nose="cone", lbt=0.0, db=0.03, N=4,
           cr=0.03, ct=0.03, span=0.03, le=0.27)
IN = 0.0254
ARCAS = dict(d=2.25 * IN, L=53.5 * IN, cg=26.75 * IN, ln=9.375 * IN, nose="ogive",
             lbt=1.81 * IN, db=1.308 * IN, N=4, cr=3.38 * IN, ct=2.165 * IN, span=2.103 * IN,
             le=49.85 * IN)

if __name__ == "__main__":
    for name, s, mach, pub in [
        ("ANF", ANF, 1.38, "CN_alpha 15.371, Cm_alpha -42.073 (DREV-TM-9703 Table VII)"),
        ("ANF", ANF, 1.293, "Cm_q + Cm_alphadot -487.4 (Table IX)"),
        ("ANF", ANF, 1.51, "Cl_p -33.6 (Barrowman 1967 Fig. 5-7)"),
        ("Arcas long", ARCAS, 0.6, "CN_alpha 11.14, x_cp 76.8 % (TN D-4013)"),
    ]:
        e = estimate(s, mach)
        print(f"{name} M {mach}: CN_alpha {e['cn']:.4f}  x_cp {e['xcp']:.5f} m "
              f"({100 * e['xcp'] / s['L']:.2f} % L)  Cm_alpha {e['cm_a']:.3f}  Cm_q {e['cm_q']:.2f}  "
              f"Cl_p {e['cl_p']:.3f}  K_W(B) {e['kwb']:.4f} K_B(W) {e['kbw']:.4f}   published: {pub}")
