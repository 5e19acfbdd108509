#!/usr/bin/env python3
"""Generate the stress_N.toml chains of four-bars (N = 10, 20, 30, 40, 50).

Deterministic, stdlib only.  Usage:  python3 tools/generate/stress.py [outdir]
(default outdir: <repo>/mechanisms).

Structure of stress_N (k = (N - 2) / 2 dyads, N links incl. ground, 3k + 1 joints):

    ground  pivots O0 = (0, 0), G1 .. Gk = (4 j, 0)
    crank   O0 (pivot, ground joint "O0", driven) and C1 (pin)
    dyad j  coupler_j : C<j> (pin on crank / rocker_<j-1>) and R<j>
            rocker_j  : G<j> (ground pivot), R<j>, and C<j+1> (arm driving dyad j+1)
            joints    C<j>: (crank | rocker_<j-1>).C<j> -- coupler_j.C<j>
                      R<j>: coupler_j.R<j> -- rocker_j.R<j>
                      G<j>: rocker_j.G<j>  -- ground.G<j>
    coupler_k also carries a tracer point P (traced), rocker_k a tip T.

Design: stage 1 is a Grashof crank-rocker (ground 4, crank 1, coupler 4, rocker 3).
Every later stage is a near-parallelogram four-bar driven by the previous rocker,
with pseudo-random (seeded) arm lengths, arm offsets and coupler lengths.  Each
candidate stage is simulated over a full crank turn (3600 samples, branch of the
drawn pose kept) and only accepted if the circle-circle intersection stays far
from tangency: half-chord h >= 0.30 * min(link radii) and transmission
|sin(mu)| >= 0.5, with the output rocker oscillation kept moderate
(20..70 deg amplitude, mean arm angle within 55..125 deg).  All files share the
same chain prefix: stress_10 is the first 4 dyads of stress_50.
"""
import math
import os
import random
import sys

SEED = 20240607
SPACING = 4.0
K_MAX = 24
SAMPLES = 3600
THETA0 = 30.0  # drawn crank angle (deg, absolute)
CRANK = 1.0

MIN_H_REL = 0.30
MIN_SIN_MU = 0.5


def fmt(v):
    if abs(v) < 1e-13:
        v = 0.0
    r = repr(float(v))
    return r


def pt(p):
    return "[%s, %s]" % (fmt(p[0]), fmt(p[1]))


def rot(v, a):
    c, s = math.cos(a), math.sin(a)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1])


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def norm(a):
    return math.hypot(a[0], a[1])


def cc(c1, r1, c2, r2, sign):
    """circle-circle intersection; returns (point, h) or (None, h2)."""
    d = sub(c2, c1)
    dd = norm(d)
    a = (dd * dd + r1 * r1 - r2 * r2) / (2 * dd)
    h2 = r1 * r1 - a * a
    if h2 < 0:
        return None, h2
    h = math.sqrt(h2)
    ex = (d[0] / dd, d[1] / dd)
    base = (c1[0] + a * ex[0], c1[1] + a * ex[1])
    p = (base[0] - sign * h * ex[1], base[1] + sign * h * ex[0])
    return p, h


def sin_mu(x, c1, c2):
    u, v = sub(c1, x), sub(c2, x)
    return abs(cross(u, v)) / (norm(u) * norm(v))


def simulate_stage(U_drawn, Gin, dpsi_in, R_drawn, Gout, sign):
    """Given the input-rocker rotation samples dpsi_in (rotation about Gin
    relative to the drawn pose), return (ok, out rotations, min h_rel, min sin mu)."""
    Lc = norm(sub(R_drawn, U_drawn))
    a = norm(sub(R_drawn, Gout))
    ang0 = math.atan2(R_drawn[1] - Gout[1], R_drawn[0] - Gout[0])
    out = []
    hmin = float("inf")
    smin = float("inf")
    for dp in dpsi_in:
        U = add(Gin, rot(sub(U_drawn, Gin), dp))
        X, h = cc(U, Lc, Gout, a, sign)
        if X is None:
            return False, None, 0.0, 0.0
        hmin = min(hmin, h / min(Lc, a))
        smin = min(smin, sin_mu(X, U, Gout))
        ang = math.atan2(X[1] - Gout[1], X[0] - Gout[0])
        d = ang - ang0
        d = (d + math.pi) % (2 * math.pi) - math.pi
        out.append(d)
    return True, out, hmin, smin


def design():
    rng = random.Random(SEED)
    th0 = math.radians(THETA0)
    G = [(SPACING * j, 0.0) for j in range(K_MAX + 1)]
    crank_pin = (CRANK * math.cos(th0), CRANK * math.sin(th0))
    # crank rotation samples over a full turn
    dcrank = [2 * math.pi * i / SAMPLES for i in range(SAMPLES)]
    stages = []  # list of dict(U=..., R=..., sign=..., hmin, smin, amp, mean)
    prev_rot = dcrank
    prev_psi0 = None  # drawn arm angle of previous rocker's R marker
    for j in range(1, K_MAX + 1):
        Gin, Gout = G[j - 1], G[j]
        for attempt in range(10000):
            if j == 1:
                U = crank_pin
                Lc, a = 4.0, 3.0
            else:
                delta = math.radians(rng.uniform(-25.0, 25.0))
                b_in = rng.uniform(2.0, 3.2)
                Lc = rng.uniform(3.6, 4.4)
                a = rng.uniform(2.2, 3.4)
                ang = prev_psi0 + delta
                U = (Gin[0] + b_in * math.cos(ang), Gin[1] + b_in * math.sin(ang))
            # drawn R: upper branch (arm pointing up-ish)
            sign = 1.0
            R, h = cc(U, Lc, Gout, a, sign)
            if R is None:
                continue
            if R[1] < 0:
                sign = -1.0
                R, h = cc(U, Lc, Gout, a, sign)
            # branch sign as seen from the circle centres (U, Gout) order
            ok, rots, hmin, smin = simulate_stage(U, Gin, prev_rot, R, Gout, sign)
            if not ok:
                continue
            psi0 = math.atan2(R[1] - Gout[1], R[0] - Gout[0])
            amp = math.degrees(max(rots) - min(rots))
            mean = math.degrees(psi0 + (max(rots) + min(rots)) / 2)
            if hmin < MIN_H_REL or smin < MIN_SIN_MU:
                if j == 1:
                    raise SystemExit("stage 1 design rejected")
                continue
            if j > 1 and not (20.0 <= amp <= 70.0 and 55.0 <= mean <= 125.0):
                continue
            stages.append(dict(U=U, R=R, Lc=Lc, a=a, hmin=hmin, smin=smin,
                               amp=amp, mean=mean, tries=attempt + 1))
            prev_rot = rots
            prev_psi0 = psi0
            break
        else:
            raise SystemExit("could not design stage %d" % j)
    return G, stages


def write(outdir, n, G, stages):
    k = (n - 2) // 2
    assert 2 + 2 * k == n
    st = stages[:k]
    # tracer on the last coupler: midpoint of its pins, 1.0 to the left of U->R
    U, R = st[-1]["U"], st[-1]["R"]
    d = sub(R, U)
    L = norm(d)
    P = (U[0] + d[0] / 2 - d[1] / L, U[1] + d[1] / 2 + d[0] / L)
    # tip on the last rocker: extend the arm G_k -> R_k by 1.0
    Gk = G[k]
    e = sub(R, Gk)
    T = (R[0] + e[0] / norm(e), R[1] + e[1] / norm(e))
    hmin = min(s["hmin"] for s in st)
    smin = min(s["smin"] for s in st)
    lines = []
    w = lines.append
    w("# stress_%d: chain of %d four-bars (%d links incl. ground, %d revolute joints)." % (n, k, n, 3 * k + 1))
    w("# Generated by tools/generate/stress.py (seed %d) -- do not edit by hand." % SEED)
    w("# ground pivots O0=(0,0), G1..G%d = (4 j, 0); crank O0->C1 (length 1, drawn at %g deg)" % (k, THETA0))
    w("# is driven through a full turn.  Dyad 1 (coupler_1, rocker_1) forms a Grashof")
    w("# crank-rocker with ground 4, crank 1, coupler 4, rocker 3; dyad j (coupler_j, rocker_j)")
    w("# is a near-parallelogram four-bar driven by rocker_<j-1> (marker C<j> on rocker_<j-1>).")
    w("# Grubler: D = 3(%d - 1) - 2*%d = %d." % (n, 3 * k + 1, 3 * (n - 1) - 2 * (3 * k + 1)))
    w("# Design property (checked by tools/check/mechanisms.py): over the whole crank turn every")
    w("# circle-circle intersection keeps half-chord h >= %.3f * min(radii) and transmission" % hmin)
    w("# |sin mu| >= %.3f, so the drawn-pose branch is never lost or flipped." % smin)
    w('name = "stress_%d"' % n)
    w("")
    w("[bodies.ground]")
    w("fixed = true")
    gm = ["O0 = %s" % pt(G[0])] + ["G%d = %s" % (j, pt(G[j])) for j in range(1, k + 1)]
    w("markers = { %s }" % ", ".join(gm))
    w("")
    w("[bodies.crank]")
    w("markers = { O0 = %s, C1 = %s }" % (pt(G[0]), pt(st[0]["U"])))
    for j in range(1, k + 1):
        s = st[j - 1]
        w("")
        w("[bodies.coupler_%d]" % j)
        m = ["C%d = %s" % (j, pt(s["U"])), "R%d = %s" % (j, pt(s["R"]))]
        if j == k:
            m.append("P = %s" % pt(P))
        w("markers = { %s }" % ", ".join(m))
        w("")
        w("[bodies.rocker_%d]" % j)
        m = ["G%d = %s" % (j, pt(G[j])), "R%d = %s" % (j, pt(s["R"]))]
        if j < k:
            m.append("C%d = %s" % (j + 1, pt(st[j]["U"])))
        else:
            m.append("T = %s" % pt(T))
        w("markers = { %s }" % ", ".join(m))
    w("")
    w("[joints.O0]")
    w('kind = "revolute"')
    w('markers = ["ground.O0", "crank.O0"]')
    for j in range(1, k + 1):
        prev = "crank" if j == 1 else "rocker_%d" % (j - 1)
        w("")
        w("[joints.C%d]" % j)
        w('kind = "revolute"')
        w('markers = ["%s.C%d", "coupler_%d.C%d"]' % (prev, j, j, j))
        w("[joints.R%d]" % j)
        w('kind = "revolute"')
        w('markers = ["coupler_%d.R%d", "rocker_%d.R%d"]' % (j, j, j, j))
        w("[joints.G%d]" % j)
        w('kind = "revolute"')
        w('markers = ["ground.G%d", "rocker_%d.G%d"]' % (j, j, j))
    w("")
    w("[inputs.theta]")
    w('kind = "angle"')
    w('joint = "O0"')
    w("")
    w("[sweep]")
    w('input = "theta"')
    w("from = 0.0")
    w("to = 360.0")
    w("steps = 361")
    w('trace = ["coupler_%d.P", "rocker_%d.T"]' % (k, k))
    path = os.path.join(outdir, "stress_%d.toml" % n)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path, hmin, smin


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    outdir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "..", "mechanisms")
    os.makedirs(outdir, exist_ok=True)
    G, stages = design()
    for j, s in enumerate(stages, 1):
        print("stage %2d: tries %3d  h_rel_min %.3f  sin_mu_min %.3f  amp %.1f deg  mean %.1f deg"
              % (j, s["tries"], s["hmin"], s["smin"], s["amp"], s["mean"]))
    for n in (10, 20, 30, 40, 50):
        path, hmin, smin = write(outdir, n, G, stages)
        print("wrote %s  (h_rel_min %.3f, sin_mu_min %.3f)" % (os.path.normpath(path), hmin, smin))


if __name__ == "__main__":
    main()
