#!/usr/bin/env python3
"""Generate the mechanisms that NEED a numeric cluster (Brunkhart 1994, Figure 30 rows
6-bar (b), 8-bar, 10-bar, Duplex, Chain-4 .. Chain-15) into a staging folder.

Deterministic, stdlib only (Python >= 3.11).  Usage:

    python3 tools/generate/clusters.py [outdir]          # default <repo>/mechanisms
    python3 tools/generate/clusters.py --search NAME [COUNT]
                                                    # re-run the seeded design search of
                                                    # eightbar | tenbar | duplex (minutes)

Files written: sixbar_b, eightbar, tenbar, duplex, chain_4, chain_6, chain_8, chain_10,
chain_15 (.toml).  The checker is tools/check/clusters.py (independent code).

None of these can be placed by closed-form propagation + RRR dyads alone from their input:

- sixbar_b: sixbar_a's Stephenson III six-bar (same bodies, markers and joints, built by
  tools/generate/mechanisms.py), driven instead at ground joint F.  The driven link5 leaves the
  triad crank + coupler + rocker + link4 (a 4-body loop): no dyad, numeric cluster 6/6.
- eightbar, tenbar, duplex: a crank driving one irreducible Assur group (no proper subset of
  its links is placeable first), sized so that Brunkhart's mixed count (a cluster body pinned
  to an already placed body has 1 unknown, its angle; any other has 3; every joint inside
  the cluster that is not such a pin gives 2 equations) equals Figure 30's Mixed column;
  tenbar and duplex then hang an RRR dyad off the cluster, placed in closed form after it.
  Their geometry comes from a seeded random search (run with --search) maximising the
  smallest singular value of the square Newton Jacobian over a full crank turn, rounded to
  0.001; the rounded design is what is stored below and re-validated on every run.
- chain_n: n unit links in series between two ground pivots, link_1 driven (Grubler
  mobility n - 2, under-constrained from n = 4).

Pose parametrisation of the numeric code here: world(p) = c_b + t + R(phi) (p - c_b), with
c_b the centroid of the body's drawn markers (the conditioning numbers in the headers are
smallest singular values of the Jacobian in these coordinates).  Chain sweeps follow
minimum-norm Gauss-Newton steps in the runtime's own coordinates instead
(world(p) = t + R(phi) p, i.e. c_b = 0), frame after frame from the drawn pose.

Coordinates are written with repr() and both markers of a revolute joint come from the
same float, so every joint holds exactly in the drawn pose.
"""
import math
import os
import random
import sys
import textwrap
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import mechanisms as gm  # noqa: E402  (Mech writer, geometry helpers, sixbar_a)

sub, add, mul, norm, cross, polar, cc = gm.sub, gm.add, gm.mul, gm.norm, gm.cross, gm.polar, gm.cc

# ----------------------------------------------------------------------------
# dense linear algebra (small, pure Python)


def lu(A):
    n = len(A)
    M = [r[:] for r in A]
    perm = list(range(n))
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(M[r][c]))
        if M[p][c] == 0.0:
            raise ZeroDivisionError("singular matrix")
        M[c], M[p] = M[p], M[c]
        perm[c], perm[p] = perm[p], perm[c]
        pv, Mc = M[c][c], M[c]
        for r in range(c + 1, n):
            Mr = M[r]
            f = Mr[c] / pv
            Mr[c] = f
            if f:
                for k in range(c + 1, n):
                    Mr[k] -= f * Mc[k]
    return M, perm


def lu_solve(F, b):
    M, perm = F
    n = len(M)
    y = [b[perm[i]] for i in range(n)]
    for i in range(n):
        Mi, s = M[i], y[i]
        for k in range(i):
            s -= Mi[k] * y[k]
        y[i] = s
    for i in range(n - 1, -1, -1):
        Mi, s = M[i], y[i]
        for k in range(i + 1, n):
            s -= Mi[k] * y[k]
        y[i] = s / Mi[i]
    return y


def lu_solve_t(F, b):
    """solve A^T x = b with the factors of P A = L U"""
    M, perm = F
    n = len(M)
    z = b[:]
    for i in range(n):
        s = z[i]
        for k in range(i):
            s -= M[k][i] * z[k]
        z[i] = s / M[i][i]
    for i in range(n - 1, -1, -1):
        s = z[i]
        for k in range(i + 1, n):
            s -= M[k][i] * z[k]
        z[i] = s
    x = [0.0] * n
    for i in range(n):
        x[perm[i]] = z[i]
    return x


def smin_square(J, iters=40, early=True):
    """smallest singular value of a square J: inverse iteration on J^T J"""
    F = lu(J)
    n = len(J)
    x = [1.0 / math.sqrt(n)] * n
    lam = 1.0
    for _ in range(iters):
        z = lu_solve(F, lu_solve_t(F, x))
        nz = math.sqrt(sum(v * v for v in z))
        if early and abs(nz - lam) <= 1e-12 * nz:
            lam = nz
            break
        lam = nz
        x = [v / nz for v in z]
    return 1.0 / math.sqrt(lam)


def smax_of(J, iters=200):
    """largest singular value: power iteration on J^T J"""
    n = len(J[0])
    x = [1.0 / math.sqrt(n)] * n
    lam = 0.0
    for _ in range(iters):
        y = [sum(a * b for a, b in zip(row, x)) for row in J]
        z = [sum(J[i][c] * y[i] for i in range(len(J))) for c in range(n)]
        nz = math.sqrt(sum(v * v for v in z))
        x = [v / nz for v in z]
        if abs(nz - lam) <= 1e-13 * nz:
            break
        lam = nz
    return math.sqrt(nz)


def gram(J):
    """J J^T"""
    return [[sum(a * b for a, b in zip(ri, rj)) for rj in J] for ri in J]


def smin_wide(J, iters=60):
    """smallest singular value of a wide full-row-rank J: inverse iteration on J J^T"""
    G = gram(J)
    F = lu(G)
    n = len(G)
    x = [1.0 / math.sqrt(n)] * n
    lam = 1.0
    for _ in range(iters):
        z = lu_solve(F, x)
        nz = math.sqrt(sum(v * v for v in z))
        if abs(nz - lam) <= 1e-12 * nz:
            lam = nz
            break
        lam = nz
        x = [v / nz for v in z]
    return 1.0 / math.sqrt(lam)


# ----------------------------------------------------------------------------
# numeric model of a gm.Mech (revolute joints only, one angle input at a ground joint)


class Num:
    def __init__(self, m, input_joint, centroid=True):
        self.bodies = {b: {mk[0]: mk[1] for mk in markers} for b, fixed, markers in m.bodies}
        self.ground = [b for b, fixed, _ in m.bodies if fixed][0]
        self.joints = {}
        for jn, kind, m1, m2 in m.joints:
            assert kind == "revolute"
            (b1, k1), (b2, k2) = m1.split("."), m2.split(".")
            self.joints[jn] = (b1, k1, b2, k2)
        b1, k1, b2, k2 = self.joints[input_joint]
        assert b1 == self.ground
        self.driver, self.pivot = b2, self.bodies[b1][k1]
        self.mobile = [b for b, _, _ in m.bodies if b not in (self.ground, self.driver)]
        self.idx = {b: i for i, b in enumerate(self.mobile)}
        self.cen = {}
        for b, mk in self.bodies.items():
            pts = list(mk.values())
            self.cen[b] = ((sum(p[0] for p in pts) / len(pts), sum(p[1] for p in pts) / len(pts))
                           if centroid else (0.0, 0.0))
        self.eqj = [j for j in self.joints if j != input_joint]
        self.n = 3 * len(self.mobile)

    def world(self, q, th, b, k):
        p = self.bodies[b][k]
        if b == self.ground:
            return p
        if b == self.driver:
            c, x, y, phi = self.pivot, 0.0, 0.0, th
        else:
            i = 3 * self.idx[b]
            c, x, y, phi = self.cen[b], q[i], q[i + 1], q[i + 2]
        cs, sn = math.cos(phi), math.sin(phi)
        dx, dy = p[0] - c[0], p[1] - c[1]
        return (c[0] + x + cs * dx - sn * dy, c[1] + y + sn * dx + cs * dy)

    def resid(self, q, th):
        r = []
        for j in self.eqj:
            b1, k1, b2, k2 = self.joints[j]
            w1, w2 = self.world(q, th, b1, k1), self.world(q, th, b2, k2)
            r += [w1[0] - w2[0], w1[1] - w2[1]]
        return r

    def jac(self, q, th):
        J = []
        for j in self.eqj:
            b1, k1, b2, k2 = self.joints[j]
            rx, ry = [0.0] * self.n, [0.0] * self.n
            for b, k, s in ((b1, k1, 1.0), (b2, k2, -1.0)):
                if b in self.idx:
                    i = 3 * self.idx[b]
                    w = self.world(q, th, b, k)
                    ox, oy = w[0] - self.cen[b][0] - q[i], w[1] - self.cen[b][1] - q[i + 1]
                    rx[i] += s
                    ry[i + 1] += s
                    rx[i + 2] -= s * oy
                    ry[i + 2] += s * ox
            J += [rx, ry]
        return J

    def newton(self, q, th, tol=1e-13, its=40):
        """square systems: Newton; wide systems: minimum-norm Gauss-Newton steps"""
        for _ in range(its):
            r = self.resid(q, th)
            if max(abs(v) for v in r) < tol:
                break
            J = self.jac(q, th)
            if len(J) == len(J[0]):
                dq = lu_solve(lu(J), [-v for v in r])
            else:
                y = lu_solve(lu(gram(J)), [-v for v in r])
                dq = [sum(J[i][c] * y[i] for i in range(len(J))) for c in range(self.n)]
            q = [a + b for a, b in zip(q, dq)]
        return q, max(abs(v) for v in self.resid(q, th))

    def smin(self, q, th):
        J = self.jac(q, th)
        return smin_square(J) if len(J) == len(J[0]) else smin_wide(J)

    def run(self, values, jump=0.5):
        """frames in order from the drawn pose; returns [(value, q, smin)] or raises"""
        q = [0.0] * self.n
        out = []
        for v in values:
            q2, res = self.newton(q, math.radians(v))
            if res > 1e-11:
                raise RuntimeError("frame %g does not converge (residual %.3g)" % (v, res))
            if max(abs(a - b) for a, b in zip(q, q2)) > jump:
                raise RuntimeError("frame %g jumps" % v)
            q = q2
            out.append((v, q, self.smin(q, math.radians(v))))
        return out

    def rot_deg(self, q, b):
        return math.degrees(q[3 * self.idx[b] + 2])


def recentre(num, num2, q):
    """the same poses in num2's pose coordinates: c + t + R (p - c) = c2 + t2 + R (p - c2)"""
    q2 = list(q)
    for b, i in num.idx.items():
        phi = q[3 * i + 2]
        cs, sn = math.cos(phi), math.sin(phi)
        c, c2 = num.cen[b], num2.cen[b]
        d = (c2[0] - c[0], c2[1] - c[1])
        q2[3 * i] = q[3 * i] + cs * d[0] - sn * d[1] - d[0]
        q2[3 * i + 1] = q[3 * i + 1] + sn * d[0] + cs * d[1] - d[1]
    return q2


def sweep_values(s):
    n = s["steps"]
    return [s["from"] + (s["to"] - s["from"]) * i / (n - 1) for i in range(n)]


def periodic(q):
    return all(abs(q[i]) < 1e-8 if i % 3 != 2 else abs(math.remainder(q[i], 2 * math.pi)) < 1e-8
               for i in range(len(q)))


def sin_mu_at(num, q, th, k_marker, a_ref, b_ref):
    """|sin| of the angle at the dyad's middle joint between its two links"""
    X = num.world(q, th, *k_marker)
    u, v = sub(num.world(q, th, *a_ref), X), sub(num.world(q, th, *b_ref), X)
    return abs(cross(u, v)) / (norm(u) * norm(v))


# ----------------------------------------------------------------------------
# 1. sixbar_b: sixbar_a driven at ground joint F


def sixbar_a_psi(m6):
    """closed form of sixbar_a: link5's rotation psi (deg) as a function of the crank
    rotation t (deg) from the drawn pose, branches of the drawn pose kept"""
    B = {b: {k: p for k, p in mk} for b, f, mk in m6.bodies}
    A, D, F = B["ground"]["A"], B["ground"]["D"], B["ground"]["F"]
    B0, C0, E0, G0 = B["crank"]["B"], B["coupler"]["C"], B["coupler"]["E"], B["link4"]["G"]
    a, b, c = norm(sub(B0, A)), norm(sub(C0, B0)), norm(sub(D, C0))
    l4, l5 = norm(sub(G0, E0)), norm(sub(F, G0))
    s1 = 1.0 if cross(sub(D, B0), sub(C0, B0)) > 0 else -1.0
    s2 = 1.0 if cross(sub(F, E0), sub(G0, E0)) > 0 else -1.0
    phi0 = math.atan2(B0[1] - A[1], B0[0] - A[0])
    u0 = sub(C0, B0)
    loc = (gm.dot(sub(E0, B0), u0) / gm.dot(u0, u0), cross(u0, sub(E0, B0)) / gm.dot(u0, u0))
    psi0 = math.atan2(G0[1] - F[1], G0[0] - F[0])

    def psi(t):
        Bp = polar(a, math.degrees(phi0) + t, A)
        C, _ = cc(Bp, b, D, c, s1)
        u = sub(C, Bp)
        E = add(Bp, add(mul(u, loc[0]), mul((-u[1], u[0]), loc[1])))
        G, _ = cc(E, l4, F, l5, s2)
        return math.degrees(math.remainder(math.atan2(G[1] - F[1], G[0] - F[0]) - psi0, 2 * math.pi))
    return psi


def golden(f, a, b, sign):
    """extremum of f on [a, b]: sign=+1 maximum, -1 minimum"""
    g = (math.sqrt(5) - 1) / 2
    x1, x2 = b - g * (b - a), a + g * (b - a)
    f1, f2 = sign * f(x1), sign * f(x2)
    for _ in range(120):
        if f1 > f2:
            b, x2, f2 = x2, x1, f1
            x1 = b - g * (b - a)
            f1 = sign * f(x1)
        else:
            a, x1, f1 = x1, x2, f2
            x2 = a + g * (b - a)
            f2 = sign * f(x2)
    x = (a + b) / 2
    return x, f(x)


SIXB_SWEEP = dict(input="theta", **{"from": 2.0, "to": 24.0}, steps=45, trace=["link4.P"])


def sixbar_b():
    m6 = gm.sixbar_a()
    psi = sixbar_a_psi(m6)
    vals = [psi(float(t)) for t in range(361)]
    tmin = min(range(361), key=lambda i: vals[i])
    tmax = max(range(361), key=lambda i: vals[i])
    cmin, pmin = golden(psi, tmin - 2.0, tmin + 2.0, -1)
    cmax, pmax = golden(psi, tmax - 2.0, tmax + 2.0, +1)
    m6.name = "sixbar_b"
    m6.inputs = [("theta", "angle", "F")]
    m6.sweep = dict(SIXB_SWEEP)
    num = Num(m6, "F")
    fr = num.run(sweep_values(m6.sweep))
    sm = [s for v, q, s in fr]
    cr = [num.rot_deg(q, "crank") for v, q, s in fr]
    # smallest singular value at the drawn pose (input 0), for the header
    s0 = num.smin([0.0] * num.n, 0.0)
    m6.header = """\
sixbar_b: Figure 30's "6-bar (b)": the SAME Stephenson III six-bar as sixbar_a (bodies,
markers and joints identical, built by tools/generate/mechanisms.py), driven instead at ground
joint F: input theta turns link5 about F (counter-clockwise positive, from the drawn pose).
Why it needs a numeric cluster (Brunkhart 3.4.4 / 4.2): once link5 is placed from the input,
the unplaced links pinned to placed ones are crank (at A), rocker (at D) and link4 (at G),
and no two of them share a joint, so no RRR dyad exists; the ternary coupler (B, C, E) ties
all three together: crank, coupler, rocker and link4 form one numeric cluster (an Assur
triad; the loop ground-crank-coupler-link4-link5 has more than 3 nodes).  Mixed count:
crank, rocker, link4 pinned (1 unknown each) + coupler free (3) = 6 unknowns; joints B, C, E
= 6 equations (Figure 30: 12/12 Newton, 6/6 mixed; 4 mobile links, 6 active joints);
hinging the coupler on the crank (joint coordinates) leaves 4 unknowns, 4 equations.
Range: over a full crank turn of sixbar_a, link5 rocks between theta = %(pmin).4f deg
(crank at %(cmin).2f deg from sixbar_a's drawn pose) and theta = %(pmax).4f deg (crank at
%(cmax).2f deg).  Those are the dead points of the F-driven linkage (the triad is singular);
driven from F it only assembles for theta in [%(pmin).4f, %(pmax).4f], and the drawn pose
(theta = 0) lies just %(gap).4f deg above the lower dead point (smallest singular value of
the 12x12 Newton Jacobian there: %(s0).3f).  The sweep therefore runs from theta = %(f)g to %(t)g
deg in %(st)d steps: %(lo).2f deg inside the lower and %(hi).2f deg inside the upper dead point,
on the branch of the drawn pose (crank turning from %(c0).1f to %(c1).1f deg, ascending).
Smallest singular value of the Newton Jacobian (centroid-referenced poses) over the sweep:
%(smin).3f (at the sweep's best: %(smax).3f).  The first frame is reached from the drawn pose
by Newton on the same side of the fold (psi is convex in the crank angle there).
Grubler: L = 6, J = 7, D = 3*5 - 2*7 = 1.""" % dict(
        pmin=pmin, pmax=pmax, cmin=cmin % 360.0, cmax=cmax % 360.0, gap=-pmin, s0=s0,
        f=m6.sweep["from"], t=m6.sweep["to"], st=m6.sweep["steps"], lo=m6.sweep["from"] - pmin,
        hi=pmax - m6.sweep["to"], c0=cr[0], c1=cr[-1], smin=min(sm), smax=max(sm))
    info = "dead points %.4f / %.4f deg; sweep %g..%g; min sigma %.3f" % (
        pmin, pmax, m6.sweep["from"], m6.sweep["to"], min(sm))
    return m6, info


# ----------------------------------------------------------------------------
# 2. eightbar, tenbar, duplex: a crank driving one irreducible Assur group
#
# A design is a topology (bodies -> the names of their joint points; every point shared
# by exactly two bodies is a revolute joint of that name, its markers named the same) plus
# the drawn position of every point.

TOPO = {
    # hexagonal ring: ternary rockers r1 (on the crank), r2, r3 (on ground pivots) and
    # floating binary couplers c1 = r1-r2, c2 = r2-r3, c3 = r3-r1
    "eightbar": dict(order=["ground", "crank", "r1", "r2", "r3", "c1", "c2", "c3"], bodies={
        "ground": ["O", "O2", "O3"], "crank": ["O", "P"],
        "r1": ["P", "A", "B"], "r2": ["O2", "C", "D"], "r3": ["O3", "E", "F"],
        "c1": ["A", "C"], "c2": ["D", "E"], "c3": ["F", "B"]}),
    # two quadrilateral contours sharing the plate_1 - plate_2 joint E, plus a dyad
    "tenbar": dict(order=["ground", "crank", "rocker_a", "rocker_b", "plate_1", "link_bf",
                          "link_dg", "plate_2", "dyad_1", "dyad_2"], bodies={
        "ground": ["O", "Q", "T"], "crank": ["O", "P"],
        "rocker_a": ["P", "A", "B"], "rocker_b": ["Q", "C", "D"],
        "plate_1": ["A", "C", "E"], "link_bf": ["B", "F"],
        "link_dg": ["D", "G", "H"], "plate_2": ["E", "F", "G"],
        "dyad_1": ["H", "K"], "dyad_2": ["K", "T"]}),
    # two quadrilateral loops cross-pinned at X1, X2, plus a dyad
    "duplex": dict(order=["ground", "crank", "rocker_a", "rocker_b", "b_left", "b_right", "b_tie",
                          "a_tie", "a_left", "a_right", "dyad_1", "dyad_2"], bodies={
        "ground": ["O", "Q", "T"], "crank": ["O", "P"],
        "rocker_a": ["P", "A1", "A2"], "a_left": ["A1", "X1", "A3"], "a_tie": ["A3", "A4"],
        "a_right": ["A2", "X2", "A4"],
        "rocker_b": ["Q", "B1", "B2"], "b_left": ["B1", "B3", "X1"], "b_tie": ["B3", "B4", "H"],
        "b_right": ["B2", "B4", "X2"],
        "dyad_1": ["H", "K"], "dyad_2": ["K", "T"]}),
}

# the rounded results of `--search NAME` (seeds and budgets in SEARCH below)
DESIGN = {
    "eightbar": {"O": (0.0, 0.0), "P": (-0.226, -0.838), "O2": (4.365, -1.437), "O3": (5.701, 0.052),
                 "A": (1.153, 2.15), "B": (1.459, 0.09), "C": (3.56, 0.986), "D": (6.861, 0.349),
                 "E": (4.204, 1.826), "F": (2.055, 1.441)},
    "tenbar": {"O": (0.0, 0.0), "P": (-0.044, -1.049), "Q": (5.426, -0.14), "T": (7.277, -1.27),
               "A": (2.4, 0.495), "B": (-0.425, 0.16), "C": (3.002, 2.475), "D": (5.936, 1.932),
               "E": (0.868, 2.09), "F": (-0.375, 1.38), "G": (2.225, 0.464), "H": (4.536, 0.257),
               "K": (6.758, 2.451)},
    "duplex": {"O": (0.0, 0.0), "P": (1.071, 0.514), "Q": (5.965, 0.304), "T": (5.533, -1.312),
               "A1": (3.677, 3.373), "A2": (1.925, 4.262), "A3": (3.692, 1.004), "A4": (1.157, 2.655),
               "B1": (2.186, 0.646), "B2": (5.105, 2.687), "B3": (4.312, 1.499), "B4": (3.534, 2.089),
               "X1": (1.532, 2.143), "X2": (2.733, 3.738), "H": (2.717, 1.144), "K": (5.577, 1.262)},
}

# tracer markers: (body, marker name, joint points it is placed from: midpoint + offset left)
TRACER = {
    "eightbar": ("c2", "Z", ("D", "E"), 0.5),
    "tenbar": ("dyad_1", "Z", ("H", "K"), 0.5),
    "duplex": ("a_tie", "Z", ("A3", "A4"), 0.5),
}

SEARCH = {  # seed, crank radius range, number of designs drawn (the stored one is the last
    "eightbar": (11, (0.8, 1.2), 35575),  # improvement; the searches ran longer, in vain)
    "tenbar": (21, (0.8, 1.2), 28029),
    "duplex": (31, (0.8, 1.2), 7973),
}
SAMPLE_ORDER = {
    "eightbar": ["P", "O2", "O3", "A", "B", "C", "D", "E", "F"],
    "tenbar": ["P", "Q", "A", "B", "C", "D", "E", "F", "G", "H", "T", "K"],
    "duplex": ["P", "Q", "A1", "A2", "B1", "B2", "X1", "X2", "A3", "A4", "B3", "B4", "H", "T", "K"],
}
BOXES = {  # (xmin, xmax, ymin, ymax) of the ground pivots; moving points: (-1, 7, 0, 5)
    "eightbar": {"O2": (1.5, 6, -1.5, 0.5), "O3": (1.5, 7, -1.5, 0.5)},
    "tenbar": {"Q": (1.5, 6, -1.5, 0.5), "T": (1.5, 8, -1.5, 0.5)},
    "duplex": {"Q": (1.5, 6, -1.5, 0.5), "T": (1.5, 8, -1.5, 0.5)},
}

FULL_TURN = dict(**{"from": 0.0, "to": 360.0}, steps=361)


def joints_of(topo):
    owners = {}
    for b in topo["order"]:
        for p in topo["bodies"][b]:
            owners.setdefault(p, []).append(b)
    out = []
    for p, bs in owners.items():
        assert len(bs) == 2, (p, bs)
        out.append((p, bs[0], bs[1]))
    return out


def build(name, P, header="", tracer=True):
    topo = TOPO[name]
    m = gm.Mech(name, header)
    extra = {}
    if tracer and name in TRACER:
        b, mk, (p1, p2), off = TRACER[name]
        u = sub(P[p2], P[p1])
        nrm = mul((-u[1], u[0]), 1.0 / norm(u))
        extra[b] = (mk, add(mul(add(P[p1], P[p2]), 0.5), mul(nrm, off)))
    for b in topo["order"]:
        markers = [(p, P[p]) for p in topo["bodies"][b]]
        if b in extra:
            markers.append(extra[b])
        m.body(b, markers, fixed=(b == "ground"))
    for p, b1, b2 in joints_of(topo):
        # ground first (the input's second marker is the driven crank); otherwise body order
        m.joint(p, "revolute", "%s.%s" % (b1, p), "%s.%s" % (b2, p))
    m.inputs.append(("theta", "angle", "O"))
    trace = ["%s.%s" % (extra_b, extra[extra_b][0]) for extra_b in extra]
    m.sweep = dict(input="theta", **FULL_TURN, trace=trace)
    return m


def evaluate(name, P, values, step_jump=0.6, cut=-1.0, smin_iters=40):
    """continuation over values from the drawn pose; returns (min sigma, frames) or (-1, None)"""
    m = build(name, P, tracer=False)
    num = Num(m, "O")
    q = [0.0] * num.n
    worst = 1e9
    frames = []
    for v in values:
        q2, res = num.newton(q, math.radians(v), tol=1e-12, its=25)
        if res > 1e-9 or max(abs(a - b) for a, b in zip(q, q2)) > step_jump:
            return -1.0, None
        q = q2
        J = num.jac(q, math.radians(v))
        s = smin_square(J, smin_iters, early=smin_iters > 8)
        worst = min(worst, s)
        frames.append((v, q, s))
        if worst <= cut:
            return worst, None
    return worst, frames


def sampler(name, rng):
    """one drawn design: the points in SAMPLE_ORDER, each drawn uniformly in its box (the crank
    pin P on a circle of radius CR about O = (0, 0)) until it passes the shape rules against
    the points already drawn: binary links 1.2..4 long, plate sides 0.8..4, plate angles
    >= 25 deg, ground pivots >= 1.5 apart; after 300 failures the whole design restarts"""
    topo = TOPO[name]
    CR = SEARCH[name][1]
    pairs = {}
    for b in topo["order"]:
        pts = topo["bodies"][b]
        for i, x in enumerate(pts):
            for y in pts[i + 1:]:
                pairs.setdefault(x, []).append((y, b))
                pairs.setdefault(y, []).append((x, b))
    plates = [pts for b, pts in topo["bodies"].items() if len(pts) == 3 and b != "ground"]

    def angle_at(p, q, r):
        u, v = sub(q, p), sub(r, p)
        return math.degrees(math.acos(max(-1, min(1, gm.dot(u, v) / (norm(u) * norm(v))))))
    while True:
        P = {"O": (0.0, 0.0)}
        for p in SAMPLE_ORDER[name]:
            for _ in range(300):
                if p == "P":
                    a = rng.uniform(0, 360)
                    r = rng.uniform(CR[0], CR[1])
                    X = (r * math.cos(math.radians(a)), r * math.sin(math.radians(a)))
                else:
                    bx = BOXES[name].get(p, (-1, 7, 0, 5))
                    X = (rng.uniform(bx[0], bx[1]), rng.uniform(bx[2], bx[3]))
                ok = True
                for y, b in pairs.get(p, []):
                    if y not in P:
                        continue
                    d = norm(sub(X, P[y]))
                    if b == "ground":
                        ok = d >= 1.5
                    elif b == "crank":
                        pass
                    elif len(topo["bodies"][b]) == 2:
                        ok = 1.2 <= d <= 4.0
                    else:
                        ok = 0.8 <= d <= 4.0
                    if not ok:
                        break
                if ok:
                    for pts in plates:
                        if p in pts and all(z in P or z == p for z in pts):
                            Q = dict(P)
                            Q[p] = X
                            a, b2, c = (Q[z] for z in pts)
                            if min(angle_at(a, b2, c), angle_at(b2, c, a), angle_at(c, a, b2)) < 25:
                                ok = False
                                break
                if ok:
                    P[p] = X
                    break
            else:
                break
        else:
            return P


def search(name, count=None):
    """seeded random search: score = smallest singular value of the Newton Jacobian over a
    full crank turn sampled every 5 deg (8 inverse iterations), the motion must close
    (periodic); the best of `count` designs is printed, rounded to 0.001"""
    seed, CR, n_best = SEARCH[name]
    count = n_best if count is None else count
    rng = random.Random(seed)
    values = [5.0 * i for i in range(1, 73)]
    best, t0 = None, time.time()
    for n in range(1, count + 1):
        P = sampler(name, rng)
        try:
            s, fr = evaluate(name, P, values, cut=best[0] if best else -1.0, smin_iters=8)
        except ZeroDivisionError:
            continue
        if fr is None or not periodic(fr[-1][1]):
            continue
        if best is None or s > best[0]:
            best = (s, P)
            print("candidate %6d (%6.1f s): min sigma %.4f" % (n, time.time() - t0, s), flush=True)
    if best:
        r = {k: (round(v[0], 3), round(v[1], 3)) for k, v in best[1].items()}
        print(r)
        print("stored design reproduced:", r == DESIGN[name])
    return best


HEADERS = {
    "eightbar": """\
eightbar: Figure 30's "8-bar": 8 links (ground, crank, 6 mobile), 10 revolute joints.
Built as a crank driving a HEXAGONAL RING of six links: three ternary rockers r1 (pinned to
the crank at P), r2 (ground pivot O2), r3 (ground pivot O3) alternating with three floating
binary couplers c1 (r1-r2, joints A, C), c2 (r2-r3, D, E), c3 (r3-r1, F, B).  The ring is a
6-link Assur group with 3 outer pairs (P, O2, O3) whose only closed contour is the hexagon:
no two of r1, r2, r3 share a joint, so once the crank is placed no RRR dyad exists, and no
proper subset of the ring is rigid against the ground and crank.  The whole ring is ONE
numeric cluster (a 6-node loop); nothing is left for closed form after it.  Mixed count:
r1, r2, r3 pinned (1 unknown each) + c1, c2, c3 free (3 each) = 12 unknowns; joints A..F =
12 equations, as in Figure 30 (Newton 18/18, mixed 12/12; 6 mobile links, 9 active joints).
(A closed-form tail is impossible at that count: with 12/12 every mobile link must be in
the cluster; a dyad hanging off a 4-link cluster would give 6/6.)
Independent loops: J - L + 1 = 3.  The crank turns fully: sweep 0..360 deg, 361 steps.
Geometry: seeded random search (seed %(seed)d, best of %(count)d drawn designs; rerun it with
`python3 tools/generate/clusters.py --search eightbar`), 
maximising the smallest singular value of the 18x18 Newton Jacobian over a full crank turn,
coordinates rounded to 0.001.  Over the sweep that value stays >= %(smin).3f (largest
singular value <= %(smax).3f); the motion is periodic (frame 360 = drawn pose) and the
solution moves at most %(step).4f per 1-deg step.  Rotations over the turn (deg):
%(rots)s.
Tracer c2.Z: 0.5 left of the middle of c2.
Grubler: L = 8, J = 10, D = 3*7 - 2*10 = 1.""",
    "tenbar": """\
tenbar: Figure 30's "10-bar": 10 links (ground, crank, 8 mobile), 13 revolute joints.
Built as a crank driving a 6-link Assur group with 2 outer pairs, then an RRR dyad:
rocker_a (pinned to the crank at P) and rocker_b (ground pivot Q) carry the ternary plate_1
(A on rocker_a, C on rocker_b, E); the ternary plate_2 (E, F, G) hangs on plate_1 at E and
is tied back to rocker_a by link_bf (B-F) and to rocker_b by link_dg (D-G).  Contours:
rocker_a-plate_1-plate_2-link_bf (A, E, F, B) and rocker_b-plate_1-plate_2-link_dg (C, E,
G, D), two quadrilaterals sharing joint E.  rocker_a and rocker_b share no joint, so no
dyad exists after the crank, and no proper subset of the group is rigid against ground and
crank: ONE numeric cluster of 6 links.  After it, dyad_1 (H on link_dg, K) and dyad_2 (K,
ground pivot T) form an RRR dyad placed in closed form (circle about H meets circle about
T at K).  Mixed count: rocker_a, rocker_b pinned (1 each) + 4 free links (3 each) = 14
unknowns; joints A..G = 14 equations; the dyad adds none, as in Figure 30 (Newton 24/24,
mixed 14/14; 8 mobile links, 12 active joints).  Independent loops: J - L + 1 = 4.
The crank turns fully: sweep 0..360 deg, 361 steps.
Geometry: seeded random search (seed %(seed)d, best of %(count)d drawn designs; rerun it with
`python3 tools/generate/clusters.py --search tenbar`), 
maximising the smallest singular value of the 24x24 Newton Jacobian over a full crank turn,
coordinates rounded to 0.001.  Over the sweep that value stays >= %(smin).3f (largest
singular value <= %(smax).3f); periodic; at most %(step).4f per 1-deg step.  The dyad's
transmission |sin mu| at K stays in [%(mu0).3f, %(mu1).3f].  Rotations over the turn (deg):
%(rots)s.
Tracer dyad_1.Z: 0.5 left of the middle of dyad_1.
Grubler: L = 10, J = 13, D = 3*9 - 2*13 = 1.""",
    "duplex": """\
duplex: Figure 30's "Duplex": 12 links (ground, crank, 10 mobile), 16 revolute joints.
Built as a crank driving an 8-link Assur group with 2 outer pairs made of TWO quadrilateral
loops, then an RRR dyad.  Loop A hangs on the crank: rocker_a (pinned to the crank at P) -
a_left (A1) - a_tie (A3) - a_right (A4) - back to rocker_a (A2).  Loop B hangs on the
ground: rocker_b (ground pivot Q) - b_left (B1) - b_tie (B3) - b_right (B4) - back to
rocker_b (B2).  Each loop alone would keep 3 freedoms; the cross pins X1 (a_left-b_left)
and X2 (a_right-b_right) lock them into one group.  rocker_a and rocker_b share no joint,
so no dyad exists after the crank, and no proper subset of the 8 links is rigid against
ground and crank: ONE numeric cluster of 8 links.  After it, dyad_1 (H on b_tie, K) and
dyad_2 (K, ground pivot T) form an RRR dyad placed in closed form.  Mixed count: rocker_a,
rocker_b pinned (1 each) + 6 free links (3 each) = 20 unknowns; joints A1..A4, B1..B4, X1,
X2 = 20 equations, as in Figure 30 (Newton 30/30, mixed 20/20; 10 mobile links, 15 active
joints).  Independent loops: J - L + 1 = 5.  The crank turns fully: sweep 0..360, 361 steps.
Geometry: seeded random search (seed %(seed)d, best of %(count)d drawn designs; rerun it with
`python3 tools/generate/clusters.py --search duplex`), 
maximising the smallest singular value of the 30x30 Newton Jacobian over a full crank turn,
coordinates rounded to 0.001.  Over the sweep that value stays >= %(smin).3f (largest
singular value <= %(smax).3f); periodic; at most %(step).4f per 1-deg step.  The dyad's
transmission |sin mu| at K stays in [%(mu0).3f, %(mu1).3f].  Rotations over the turn (deg):
%(rots)s.
Tracer a_tie.Z: 0.5 left of the middle of a_tie.
Grubler: L = 12, J = 16, D = 3*11 - 2*16 = 1.""",
}


def cluster_mech(name):
    P = DESIGN[name]
    m = build(name, P)
    num = Num(m, "O")
    fr = num.run(sweep_values(m.sweep))
    assert periodic(fr[-1][1]), name + ": motion not periodic"
    sm = [s for v, q, s in fr]
    smax = max(smax_of(num.jac(q, math.radians(v))) for v, q, s in fr[::5])
    step = max(max(abs(a - b) for a, b in zip(fr[i][1], fr[i - 1][1])) for i in range(1, len(fr)))
    rots = []
    for b in num.mobile:
        r = [num.rot_deg(q, b) for v, q, s in fr]
        rots.append("%s %.1f..%.1f" % (b, min(r), max(r)))
    d = dict(seed=SEARCH[name][0], count=SEARCH[name][2], smin=min(sm), smax=smax, step=step, rots=", ".join(rots))
    if "dyad_1" in num.idx:
        mus = [sin_mu_at(num, q, math.radians(v), ("dyad_1", "K"), ("dyad_1", "H"), ("dyad_2", "T"))
               for v, q, s in fr]
        d.update(mu0=min(mus), mu1=max(mus))
    d["rots"] = "\n".join(textwrap.wrap(d["rots"], 90))
    m.header = HEADERS[name] % d
    return m, "min sigma %.3f, periodic, step %.4f" % (min(sm), step)


# ----------------------------------------------------------------------------
# 3. chains


CHAIN_TURN = 100.0  # total turning of the drawn arch (deg): link_1 at +50, link_n at -50
CHAIN_SWEEP = dict(**{"from": 0.0, "to": -30.0}, steps=31)


def chain_points(n, turn=CHAIN_TURN):
    x = math.radians(turn) / 2
    beta = 2 * x / n
    R = 1.0 / (2 * math.sin(beta / 2))
    raw = [(R * math.cos(math.pi / 2 + x - k * beta), R * math.sin(math.pi / 2 + x - k * beta)) for k in range(n + 1)]
    o = raw[0]
    pts = []
    for p in raw:
        q = (p[0] - o[0], p[1] - o[1])
        pts.append(tuple(0.0 if abs(c) < 1e-13 else c for c in q))
    return pts, R


def chain(n):
    pts, R = chain_points(n)
    span = pts[n][0]
    m = gm.Mech("chain_%d" % n, "")
    m.body("ground", [("G0", pts[0]), ("G1", pts[n])], fixed=True)
    for k in range(1, n + 1):
        m.body("link_%d" % k, [("S", pts[k - 1]), ("E", pts[k])])
    m.joint("G0", "revolute", "ground.G0", "link_1.S")
    for k in range(1, n):
        m.joint("J%d" % k, "revolute", "link_%d.E" % k, "link_%d.S" % (k + 1))
    m.joint("G1", "revolute", "ground.G1", "link_%d.E" % n)
    m.inputs.append(("theta", "angle", "G0"))
    mid = n // 2
    m.sweep = dict(input="theta", **CHAIN_SWEEP, trace=["link_%d.E" % mid])
    # min-norm frames in the runtime's coordinates (c_b = 0), from the drawn pose
    num = Num(m, "G0", centroid=False)
    fr = num.run(sweep_values(m.sweep))
    numc = Num(m, "G0", centroid=True)
    sm = []
    reach = 0.0
    for v, q, s in fr:
        sm.append(numc.smin(recentre(num, numc, q), math.radians(v)))
        B = num.world(q, math.radians(v), "link_1", "E")
        reach = max(reach, norm(sub(B, pts[n])) / (n - 1))
    # where the rest of the chain would be pulled straight (|J1 - G1| = n - 1), theta > 0
    a0 = math.atan2(pts[1][1], pts[1][0])
    cs = (span * span + 1 - (n - 1) ** 2) / (2 * span)
    straight = math.degrees(math.acos(cs)) - math.degrees(a0) if abs(cs) <= 1 else float("nan")
    ref = {4: (3, 4, 9, 8, 5, 4), 6: (5, 6, 15, 12, 11, 8), 8: (7, 8, 21, 16, 17, 12),
           10: (9, 10, 27, 20, 23, 16), 15: (15, 14, 42, 30, 38, 26)}[n]
    note = ""
    if n == 15:
        note = """
Figure 30's Chain-15 row reads 15 mobile links and 14 active joints, which is inconsistent
with its own Newton column 42/30 (= 3*14 / 2*15) and with the other chain rows; this file
follows the general rule (n = 15 links: 14 mobile, 15 active joints), which reproduces
Newton 42/30 and mixed 38/26 exactly: the reference row has the two counts swapped."""
    m.header = """\
chain_%(n)d: Figure 30's "Chain-%(n)d": %(n)d unit links in series between two ground pivots,
link_1 driven.  Bodies link_1..link_%(n)d (markers S, E), joints G0 (ground-link_1, the input),
J1..J%(n1)d (link_k.E - link_k+1.S), G1 (link_%(n)d - ground): %(J)d joints.
Grubler: L = %(L)d, J = %(J)d, D = 3*%(n)d - 2*%(J)d = %(D)d; the one input leaves %(free)d idle
freedom%(pl)s: under-constrained, the solver picks the minimum-norm motion.
Figure 30 counts (driving link and its ground joint excluded): %(mob)d mobile links, %(act)d active
joints, Newton %(nu)d/%(ne)d, mixed %(mu)d/%(me)d (link_2, pinned to link_1, and link_%(n)d, pinned to
the ground, keep 1 unknown each and spend their pin's 2 equations).
Reference row: %(ref)s.%(note)s
Not dyad-solvable: after link_1, the unplaced links pinned to placed ones are link_2 and
link_%(n)d, which share no joint (n >= 4): links 2..%(n)d are left for the numeric cluster.
Drawn pose: a gentle arch, the joints on a circle of radius %(R).4f, %(turn)g deg of total
turning (link_1 at +%(h)g deg, link_%(n)d at -%(h)g deg); ground pivots %(span).6f apart for a
total length %(n)d (ratio %(ratio).4f), so the chain has slack.
Sweep: theta from %(f)g to %(t)g deg (clockwise: link_1 dips towards G1, giving the rest of
the chain more slack), %(st)d steps, each frame by minimum-norm Gauss-Newton steps from the
previous one (poses world = t + R(phi) p, as the runtime's Pose).  Turning link_1 the other
way pulls the rest of the chain straight at theta = +%(straight).2f deg (|J1 - G1| = %(n1)d).
Over the sweep |J1 - G1| / %(n1)d <= %(reach).4f and the smallest singular value of the
%(ne)dx%(nu)d Jacobian (centroid-referenced poses) stays >= %(smin).4f (at most %(s0).4f).
Traced: the middle joint J%(mid)d (link_%(mid)d.E).""" % dict(
        n=n, pl="" if n == 4 else "s", n1=n - 1, L=n + 1, J=n + 1, D=3 * n - 2 * (n + 1), free=n - 3, mob=n - 1, act=n,
        nu=3 * (n - 1), ne=2 * n, mu=3 * (n - 1) - 4, me=2 * n - 4,
        ref="%d mobile, %d joints, Newton %d/%d, mixed %d/%d" % ref, note=note, R=R,
        turn=CHAIN_TURN, h=CHAIN_TURN / 2, span=span, ratio=span / n, f=m.sweep["from"],
        t=m.sweep["to"], st=m.sweep["steps"], straight=straight, reach=reach, smin=min(sm),
        s0=max(sm), mid=mid)
    return m, "min sigma %.4f, |J1-G1|/(n-1) <= %.4f, straight at +%.2f deg" % (min(sm), reach, straight)


# ----------------------------------------------------------------------------


def main(argv):
    if argv and argv[0] == "--search":
        name = argv[1]
        search(name, int(argv[2]) if len(argv) > 2 else None)
        return 0
    outdir = argv[0] if argv else os.path.join(HERE, "..", "..", "mechanisms")
    os.makedirs(outdir, exist_ok=True)
    makers = [sixbar_b] + [lambda nm=nm: cluster_mech(nm) for nm in ("eightbar", "tenbar", "duplex")] + \
             [lambda n=n: chain(n) for n in (4, 6, 8, 10, 15)]
    for mk in makers:
        m, info = mk()
        L, J, D = m.grubler()
        with open(os.path.join(outdir, m.name + ".toml"), "w") as f:
            f.write(m.text())
        print("wrote %-14s L=%2d J=%2d D=%2d  %s" % (m.name + ".toml", L, J, D, info), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
