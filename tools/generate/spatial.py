#!/usr/bin/env python3
"""Generate the bundled 3D mechanisms mechanisms/spatial/*.toml.

Deterministic, stdlib only.  Usage:  python3 tools/generate/spatial.py [outdir]
(default outdir: <repo>/mechanisms/spatial), or
python3 tools/generate/spatial.py --stress N outdir for one longer chain.  Check the result with
tools/check/spatial.py (an independent solver).

Every coordinate is written with repr() of a Python float, and both markers of
a joint are written from the same floats, so every joint holds exactly in the
drawn pose.  Each mechanism's design is checked here before it is written
(assembly margins over the whole sweep, computed in closed form); each file's
header says how it was designed, why it assembles over its sweep, which closed
form checks it, and its expected counts (the line "Expected counts: ..." that
tools/check/spatial.py compares with its own rank computation).

Counts (n moving bodies, Sum = joint equations, Grubler 6n - Sum, mobility =
6n - rank, redundant = Sum - rank, idle = 6n - rank with the input rows):

    cardan              2   3 joints  14  -2   1   3   0
    double_cardan       3   4         18   0   1   1   0
    rssr                3   4         16   2   2   0   1   (coupler spin)
    spherical_fourbar   3   4         20  -2   1   3   0
    bennett             3   4         20  -2   1   3   0
    tilted_fourbar      3   4         20  -2   1   3   0
    excavator           8  10         49  -1   3   4   0
    sofa_bed           16  22        116 -20   2  22   0
    stewart            13  18         66  12  12   0   6   (rod spins)
    spatial_stress_N  2N+1 3N+1    11N+5  N+1 N+1  0   N   (coupler spins)
"""
import math
import os
import random
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


# ---------------------------------------------------------------------------
# vectors

def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def mul(a, k):
    return (a[0] * k, a[1] * k, a[2] * k)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(dot(a, a))


def unit(a):
    n = norm(a)
    return (a[0] / n, a[1] / n, a[2] / n)


def lerp(a, b, f):
    return add(a, mul(sub(b, a), f))


def rot(v, axis, th):
    """Rotate v about the unit axis by th (right-handed), Rodrigues."""
    a = unit(axis)
    c, s = math.cos(th), math.sin(th)
    return add(add(mul(v, c), mul(cross(a, v), s)), mul(a, dot(a, v) * (1.0 - c)))


def rotp(p, centre, axis, th):
    return add(centre, rot(sub(p, centre), axis, th))


def wrap(x):
    return (x + math.pi) % (2.0 * math.pi) - math.pi


def rocker_solve(Bw, Cd, Dp, a, l, prev):
    """Rocker angle phi about the axis (Dp, a) taking its drawn point Cd to C with
    |C - Bw| = l, the root nearest prev.  Returns (phi, |c| / rho) or (None, m)."""
    a = unit(a)
    foot = add(Dp, mul(a, dot(sub(Cd, Dp), a)))
    rv = sub(Cd, foot)
    r = norm(rv)
    u = mul(rv, 1.0 / r)
    w = cross(a, u)
    E = sub(foot, Bw)
    A, B = dot(E, u), dot(E, w)
    c = (l * l - dot(E, E) - r * r) / (2.0 * r)
    rho = math.hypot(A, B)
    m = c / rho
    if abs(m) > 1.0:
        return None, m
    base, d = math.atan2(B, A), math.acos(m)
    best = min((base + d, base - d), key=lambda x: abs(wrap(x - prev)))
    return prev + wrap(best - prev), abs(m)


def fmt(v):
    v = float(v)
    if abs(v) < 1e-14:
        v = 0.0
    return repr(v)


def vec(p):
    return "[%s, %s, %s]" % (fmt(p[0]), fmt(p[1]), fmt(p[2]))


# ---------------------------------------------------------------------------
# document

class Doc:
    def __init__(self, name):
        self.name = name
        self.header = []
        self.bodies = {}
        self.joints = []
        self.inputs = []
        self.sweep = None
        self.counts = None

    def h(self, *lines):
        self.header.extend(lines)

    def body(self, name, fixed=False):
        if name not in self.bodies:
            self.bodies[name] = {"fixed": fixed, "markers": {}}
        return self

    def marker(self, body, name, at, z=None, x=None):
        self.body(body)
        mk = self.bodies[body]["markers"]
        assert name not in mk, (body, name)
        mk[name] = (at, z, x)
        return body + "." + name

    def pin(self, jname, kind, b1, b2, at, z=None, z2=None, n1=None, n2=None, **kw):
        """Joint jname between b1 (first marker) and b2, both markers at `at`."""
        m1 = self.marker(b1, n1 or jname, at, z)
        m2 = self.marker(b2, n2 or jname, at, z if z2 is None else z2)
        self.joint(jname, kind, m1, m2, **kw)

    def joint(self, name, kind, m1, m2, pitch=None):
        self.joints.append((name, kind, m1, m2, pitch))

    def input(self, name, kind, joint):
        self.inputs.append((name, kind, joint))

    def expect(self, n, joints, eqs, mob, red, idle):
        self.counts = (n, joints, eqs, 6 * n - eqs, mob, red, idle)
        assert sum(1 for b in self.bodies.values() if not b["fixed"]) == n, self.name
        assert len(self.joints) == joints, self.name
        per = {"revolute": 5, "prismatic": 5, "cylindrical": 4, "spherical": 3,
               "universal": 4, "planar": 3, "fixed": 6, "helical": 5}
        assert sum(per[j[1]] for j in self.joints) == eqs, self.name

    def text(self):
        out = ["# " + ln if ln else "#" for ln in self.header]
        c = self.counts
        out.append("# Expected counts: moving bodies %d, joints %d, joint equations %d, Grubler %d, "
                   "mobility %d, redundant %d, idle %d." % c)
        out.append("# (mobility = 6n - rank of the joint Jacobian at the drawn pose, redundant = equations - rank,")
        out.append("# idle = 6n - rank with the input equations added.)")
        out.append("# Generated by tools/generate/spatial.py -- do not edit by hand; checked by tools/check/spatial.py.")
        out.append('name = "%s"' % self.name)
        out.append("dimension = 3")
        for bname, b in self.bodies.items():
            out.append("")
            out.append("[bodies.%s]" % bname)
            if b["fixed"]:
                out.append("fixed = true")
            for mname, (at, z, x) in b["markers"].items():
                if z is None:
                    out.append("markers.%s = %s" % (mname, vec(at)))
                else:
                    s = "markers.%s = { at = %s, z = %s" % (mname, vec(at), vec(z))
                    if x is not None:
                        s += ", x = %s" % vec(x)
                    out.append(s + " }")
        out.append("")
        for name, kind, m1, m2, pitch in self.joints:
            out.append("[joints.%s]" % name)
            out.append('kind = "%s"' % kind)
            out.append('markers = ["%s", "%s"]' % (m1, m2))
            if pitch is not None:
                out.append("pitch = %s" % fmt(pitch))
        for name, kind, joint in self.inputs:
            out.append("")
            out.append("[inputs.%s]" % name)
            out.append('kind = "%s"' % kind)
            out.append('joint = "%s"' % joint)
        out.append("")
        out.append("[sweep]")
        sw = self.sweep
        if "input" in sw:
            out.append('input = "%s"' % sw["input"])
            out.append("from = %s" % fmt(sw["from"]))
            out.append("to = %s" % fmt(sw["to"]))
            out.append("steps = %d" % sw["steps"])
        else:
            out.append("steps = %d" % sw["steps"])
            out.append("inputs = { %s }" % ", ".join(
                "%s = [%s, %s]" % (k, fmt(a), fmt(b)) for k, (a, b) in sw["inputs"].items()))
        out.append("trace = [%s]" % ", ".join('"%s"' % t for t in sw["trace"]))
        return "\n".join(out) + "\n"


X = (1.0, 0.0, 0.0)
Y = (0.0, 1.0, 0.0)
Z = (0.0, 0.0, 1.0)
O = (0.0, 0.0, 0.0)


# ---------------------------------------------------------------------------
# 1. single Cardan joint

def cardan():
    beta = math.radians(30.0)
    a1 = X
    a2 = (math.cos(beta), math.sin(beta), 0.0)
    d = Doc("cardan")
    d.body("ground", fixed=True)
    d.pin("A", "revolute", "ground", "shaft1", mul(a1, -2.0), a1)
    d.pin("B", "revolute", "ground", "shaft2", mul(a2, 2.5), a2)
    # the cross: shaft1's yoke axis y (in the plane of the shafts), shaft2's yoke axis z
    d.pin("U", "universal", "shaft1", "shaft2", O, Y, z2=Z)
    d.marker("shaft1", "tip", add(mul(a1, -1.0), mul(Y, 0.5)))
    d.marker("shaft2", "tip", add(mul(a2, 1.5), mul(Z, 0.5)))
    d.input("theta", "angle", "A")
    d.sweep = {"input": "theta", "from": 0.0, "to": 360.0, "steps": 361,
               "trace": ["shaft2.tip", "shaft1.tip"]}
    # design check: the closed form is smooth and 1-to-1 (no lock-up at beta = 30 deg)
    ratio = [1.0 / (math.cos(beta) * (math.cos(t) ** 2 + math.sin(t) ** 2 / math.cos(beta) ** 2))
             for t in (math.radians(k) for k in range(361))]
    d.h("cardan: a single Cardan (Hooke) joint between two shafts at beta = 30 deg.",
        "shaft1 turns about the x axis (ground revolute A at (-2, 0, 0), z = +x; angle input theta);",
        "shaft2 turns about a2 = (cos 30, sin 30, 0) (ground revolute B at 2.5 a2, z = +a2); both",
        "axes pass through the origin, where the universal joint U (the cross) joins the shafts",
        "directly: U's first marker (shaft1) has z = y, shaft1's yoke axis, normal to shaft1 and IN",
        "THE PLANE OF THE SHAFTS; the second (shaft2) has z = +z, shaft2's yoke axis, normal to",
        "shaft2 and to shaft1's yoke.",
        "Convention: with the input yoke in the plane of the shafts at theta1 = 0, the output angle",
        "theta2 (right-handed about +a2, from the drawn pose) obeys tan theta2 = tan theta1 / cos beta",
        "in the same quadrant, so w_out / w_in = 1 / cos beta = %.6f at theta1 = 0 and cos beta =" % (1 / math.cos(beta)),
        "%.6f at theta1 = 90 deg (computed range over the sweep: %.6f .. %.6f)." % (math.cos(beta), min(ratio), max(ratio)),
        "A Cardan joint at beta < 90 deg never locks: the output is a smooth bijection of the input,",
        "so the sweep (theta 0..360, 361 steps) assembles everywhere.  shaft1.tip and shaft2.tip are",
        "off-axis points (along the yokes as drawn) that show each shaft's angle.",
        "Closed form checked: tan theta2 = tan theta1 / cos beta, theta2 = atan2(sin th1, cos th1 cos beta).",
        "Counts: 2 moving bodies, 2 revolutes + 1 universal = 5 + 5 + 4 = 14 equations, Grubler",
        "12 - 14 = -2; the cross's centre lies on both shaft axes, so its 3 coincident rows repeat",
        "what the revolutes already fix: 3 redundant, mobility 1.")
    d.expect(2, 3, 14, 1, 3, 0)
    return d


# ---------------------------------------------------------------------------
# 2. double Cardan, Z arrangement

def double_cardan():
    beta = math.radians(30.0)
    m = (math.cos(beta), math.sin(beta), 0.0)
    ell = 3.0
    U1 = O
    U2 = mul(m, ell)
    d = Doc("double_cardan")
    d.body("ground", fixed=True)
    d.pin("A", "revolute", "ground", "input", mul(X, -2.0), X)
    d.pin("U1", "universal", "input", "intermediate", U1, Y, z2=Z)
    d.pin("U2", "universal", "intermediate", "output", U2, Z, z2=Y)
    d.pin("B", "revolute", "ground", "output", add(U2, mul(X, 2.0)), X)
    d.marker("input", "tip", add(mul(X, -1.0), mul(Y, 0.5)))
    d.marker("intermediate", "mid", add(mul(m, 0.5 * ell), mul(Z, 0.4)))
    d.marker("output", "tip", add(add(U2, X), mul(Y, 0.5)))
    d.input("theta", "angle", "A")
    d.sweep = {"input": "theta", "from": 0.0, "to": 360.0, "steps": 361,
               "trace": ["output.tip", "intermediate.mid"]}
    d.h("double_cardan: two Cardan joints in the Z arrangement, output angle = input angle exactly.",
        "input shaft: ground revolute A at (-2, 0, 0), axis +x through the origin (angle input theta).",
        "intermediate shaft: from U1 = (0, 0, 0) to U2 = 3 (cos 30, sin 30, 0) = (%.6f, %.6f, 0)," % U2[:2],
        "held ONLY by the two universal joints, at beta = 30 deg to both other shafts.",
        "output shaft: ground revolute B at U2 + (2, 0, 0), axis +x (parallel to the input).",
        "Yokes: U1 = [input z = y (in the plane of the shafts), intermediate z = +z]; U2 =",
        "[intermediate z = +z, output z = y].  The intermediate's two yoke axes are both +z:",
        "in phase.  Joint 1 gives tan phi = tan theta / cos beta (phi: intermediate spin), joint 2,",
        "whose input yoke is normal to the plane, gives tan theta_out = tan phi cos beta, so",
        "theta_out = theta for every theta: no lock-up, the sweep (0..360, 361 steps) assembles",
        "everywhere.  Closed form checked: output angle = input angle.",
        "Counts: 3 moving bodies, 2 R + 2 U = 18 equations, Grubler 0.  U1 and U2 are points of the",
        "fixed input and output axes, so the intermediate's length between them is checked twice:",
        "1 redundant row, mobility 1, no idle freedom (the universals fix the intermediate's spin).")
    d.expect(3, 4, 18, 1, 1, 0)
    return d


# ---------------------------------------------------------------------------
# 3. RSSR

def rssr():
    A = O
    B = (1.0, 0.0, 0.0)
    Dp = (-0.5, 3.2, 2.0)
    u = (1.0, 0.0, 1.0)
    s = math.sqrt(75.0 / 32.0)            # C - D = (s, 1.25, -s): normal to u, |C - D| = 2.5
    C = add(Dp, (s, 1.25, -s))
    M = lerp(B, C, 0.6)
    ell = norm(sub(C, B))
    # design check over a full crank turn
    prev, worst, phis = 0.0, 0.0, []
    for k in range(3601):
        th = math.radians(k / 10.0)
        phi, mg = rocker_solve(rotp(B, A, Z, th), C, Dp, u, ell, prev)
        assert phi is not None
        prev, worst = phi, max(worst, mg)
        phis.append(phi)
    assert worst < 0.4 and abs(phis[-1]) < 1e-9
    swing = math.degrees(max(phis) - min(phis))
    d = Doc("rssr")
    d.body("ground", fixed=True)
    d.marker("ground", "A", A, Z)
    d.marker("ground", "D", Dp, u)
    d.marker("crank", "A", A, Z)
    d.marker("crank", "B", B)
    d.marker("coupler", "B", B)
    d.marker("coupler", "C", C)
    d.marker("coupler", "M", M)
    d.marker("rocker", "C", C)
    d.marker("rocker", "D", Dp, u)
    d.joint("A", "revolute", "ground.A", "crank.A")
    d.joint("B", "spherical", "crank.B", "coupler.B")
    d.joint("C", "spherical", "coupler.C", "rocker.C")
    d.joint("D", "revolute", "ground.D", "rocker.D")
    d.input("theta", "angle", "A")
    d.sweep = {"input": "theta", "from": 0.0, "to": 360.0, "steps": 361, "trace": ["coupler.M"]}
    d.h("rssr: spatial four-bar R-S-S-R (crank-rocker), the example of docs/design/spatial.md §3.",
        "crank: revolute A to ground about +z through the origin, B = (1, 0, 0) (radius 1; input theta).",
        "rocker: revolute D to ground at D = (-0.5, 3.2, 2.0) about the skew axis (1, 0, 1)/sqrt2;",
        "its spherical joint C is at C = D + (s, 1.25, -s), s = sqrt(75/32): radius 2.5, C - D normal",
        "to the axis.  coupler: spherical at both ends, |BC| = %.6f; M = B + 0.6 (C - B) is traced" % ell,
        "(a point ON the B-C line, so its path does not depend on the coupler's idle spin).",
        "Why it turns fully: the rocker angle solves a cos phi + b sin phi = c with B(theta) on the",
        "crank circle; over a full crank turn (3600 samples) |c| / sqrt(a^2 + b^2) <= %.3f (1 would be" % worst,
        "a dead point), so the crank turns 360 deg and the rocker oscillates over %.1f deg." % swing,
        "Closed form checked: that one-angle equation, branch by continuity from the drawn pose.",
        "Counts: 3 moving bodies, R + S + S + R = 5 + 3 + 3 + 5 = 16 equations, Grubler 18 - 16 = 2,",
        "no redundancy; mobility 2 = the crank + the coupler's idle spin about B-C (idle 1).")
    d.expect(3, 4, 16, 2, 0, 1)
    return d


# ---------------------------------------------------------------------------
# 4. spherical four-bar

def spherical_fourbar():
    ag, ac, ak, ar = 70.0, 25.0, 60.0, 55.0     # ground, crank, coupler, rocker arcs (deg)
    R = 2.0
    aA = Z
    aD = (math.sin(math.radians(ag)), 0.0, math.cos(math.radians(ag)))
    th0 = math.radians(40.0)                     # drawn crank angle (from the plane of aA, aD)
    aB = rot((math.sin(math.radians(ac)), 0.0, math.cos(math.radians(ac))), aA, th0)
    # aC: angle ar from aD and ak from aB (cone-cone intersection), the branch with aC.y < 0
    w1, w2 = aD, aB
    c1, c2 = math.cos(math.radians(ar)), math.cos(math.radians(ak))
    c = dot(w1, w2)
    x = (c1 - c2 * c) / (1 - c * c)
    y = (c2 - c1 * c) / (1 - c * c)
    v = add(mul(w1, x), mul(w2, y))
    n = cross(w1, w2)
    t = math.sqrt((1 - dot(v, v)) / dot(n, n))
    cands = [add(v, mul(n, t)), add(v, mul(n, -t))]
    aC = min(cands, key=lambda q: q[1])
    aC = unit(aC)
    assert abs(dot(aC, aD) - c1) < 1e-12 and abs(dot(aC, aB) - c2) < 1e-12
    # design check: |BC| constant, rocker from the one-angle equation over a crank turn
    Bp, Cp, Dp = mul(aB, R), mul(aC, R), mul(aD, R)
    ell = norm(sub(Cp, Bp))
    prev, worst, phis = 0.0, 0.0, []
    for k in range(3601):
        phi, mg = rocker_solve(rotp(Bp, O, aA, math.radians(k / 10.0)), Cp, O, aD, ell, prev)
        assert phi is not None
        prev, worst = phi, max(worst, mg)
        phis.append(phi)
    assert worst < 0.95 and abs(phis[-1]) < 1e-9
    swing = math.degrees(max(phis) - min(phis))
    P = add(mul(unit(add(aB, aC)), R), mul(unit(cross(aB, aC)), 0.4))
    d = Doc("spherical_fourbar")
    d.body("ground", fixed=True)
    d.pin("A", "revolute", "ground", "crank", mul(aA, R), aA)
    d.pin("B", "revolute", "crank", "coupler", Bp, aB)
    d.pin("C", "revolute", "coupler", "rocker", Cp, aC)
    d.pin("D", "revolute", "ground", "rocker", Dp, aD)
    d.marker("coupler", "P", P)
    d.input("theta", "angle", "A")
    d.sweep = {"input": "theta", "from": 0.0, "to": 360.0, "steps": 361, "trace": ["coupler.P"]}
    d.h("spherical_fourbar: spherical crank-rocker; the four revolute axes meet at O = (0, 0, 0).",
        "Arcs (angles between consecutive axes): ground A-D %g deg, crank A-B %g, coupler B-C %g," % (ag, ac, ak),
        "rocker C-D %g.  Spherical Grashof: s + l = %g + %g <= p + q = %g + %g and the shortest arc is" % (ar, ac, ag, ak, ar),
        "the crank (driven at A), so the crank turns fully: angle(aB, aD) sweeps [45, 95] deg, inside",
        "(|60 - 55|, 60 + 55) = (5, 115).  aA = +z, aD = (sin 70, 0, cos 70); the crank is drawn at 40 deg",
        "about aA from the plane of aA, aD; aC = the cone-cone root with y < 0.",
        "Each revolute's two markers sit on its axis at radius %g from O (distinct points, not the" % R,
        "common centre).  Over a crank turn (3600 samples) the rocker's one-angle equation keeps",
        "|c| / sqrt(a^2 + b^2) <= %.3f; the rocker oscillates over %.1f deg.  coupler.P (off both axes," % (worst, swing),
        "the coupler is fully determined) is traced.",
        "Closed form checked: the rocker angle from |BC| = const (B, C the marker points on the",
        "coupler's axes), a cos phi + b sin phi = c, branch by continuity.",
        "Counts: 3 moving bodies, 4 revolutes = 20 equations, Grubler -2; the spherical loop",
        "only uses rotations about O: 3 redundant rows (the loop's translations), mobility 1.")
    d.expect(3, 4, 20, 1, 3, 0)
    return d


# ---------------------------------------------------------------------------
# 5. Bennett linkage

def mat4mul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def dh(theta, a, alpha):
    c, s = math.cos(theta), math.sin(theta)
    ca, sa = math.cos(alpha), math.sin(alpha)
    # Rz(theta) Tx(a) Rx(alpha)
    return [[c, -s * ca, s * sa, a * c],
            [s, c * ca, -c * sa, a * s],
            [0.0, sa, ca, 0.0],
            [0.0, 0.0, 0.0, 1.0]]


def bennett_thetas(t1, al, be):
    K = math.sin((be + al) / 2) / math.sin((be - al) / 2)
    t2 = 2.0 * math.atan2(K * math.cos(t1 / 2), math.sin(t1 / 2))
    return [t1, t2, -t1, -t2]


def circle_pair_miss(c1, n1, r1, c2, n2, r2, target):
    """Non-coplanar circle-circle intersection: the two candidates on the line of the
    two planes that lie on circle 2; returns (distance of the candidate nearest target,
    miss of the other candidate from circle 1)."""
    t = unit(cross(n1, n2))
    f = tuple(solve_lin([list(n1), list(n2), list(t)], [dot(n1, c1), dot(n2, c2), dot(t, c2)]))
    h = math.sqrt(max(r2 * r2 - dot(sub(f, c2), sub(f, c2)), 0.0))
    cands = [add(f, mul(t, h)), add(f, mul(t, -h))]
    i = 0 if norm(sub(cands[0], target)) < norm(sub(cands[1], target)) else 1
    miss = abs(norm(sub(cands[1 - i], c1)) - r1)
    return norm(sub(cands[i], target)), miss


def bennett():
    a, al_d, be_d = 2.0, 55.0, 145.0
    al, be = math.radians(al_d), math.radians(be_d)
    b = a * math.sin(be) / math.sin(al)
    links = [(a, al), (b, be), (a, al), (b, be)]
    t1_0 = math.radians(50.0)                   # drawn DH angle at joint 1 (A)

    def frames(t1):
        th = bennett_thetas(t1, al, be)
        T = [[1.0 if i == j else 0.0 for j in range(4)] for i in range(4)]
        out = []
        for i in range(4):
            out.append(T)
            T = mat4mul(T, dh(th[i], *links[i]))
        err = max(abs(T[i][j] - (1.0 if i == j else 0.0)) for i in range(4) for j in range(4))
        return out, err
    F, err = frames(t1_0)
    assert err < 1e-12, err
    Op = [(f[0][3], f[1][3], f[2][3]) for f in F]
    Zs = [(f[0][2], f[1][2], f[2][2]) for f in F]
    # design check over a full input turn: closure, and the placement of C as the
    # intersection of its circle about axis B (coupler turning on the placed crank) with its
    # circle about axis D: one candidate is the Bennett pose, the other misses circle 1 by
    # at least `miss` (no ambiguity, no tangency)
    miss, hit = float("inf"), 0.0
    for k in range(3600):
        Fk, e = frames(t1_0 + math.radians(k / 10.0))
        assert e < 1e-11
        Bk = (Fk[1][0][3], Fk[1][1][3], Fk[1][2][3])
        zB = (Fk[1][0][2], Fk[1][1][2], Fk[1][2][2])
        Ck = (Fk[2][0][3], Fk[2][1][3], Fk[2][2][3])

        def circ(P, ax, q):
            ax = unit(ax)
            c = add(P, mul(ax, dot(sub(q, P), ax)))
            return c, ax, norm(sub(q, c))
        h_, m_ = circle_pair_miss(*circ(Bk, zB, Ck), *circ(Op[3], Zs[3], Ck), Ck)
        miss, hit = min(miss, m_), max(hit, h_)
    assert hit < 1e-9 and miss > 0.5, (hit, miss)
    d = Doc("bennett")
    d.body("ground", fixed=True)
    # joint i (A..D) at O_i; link i joins joints i and i+1: crank A-B, coupler B-C, rocker C-D, ground D-A
    for name, i, first, second in (("A", 0, "ground", "crank"), ("B", 1, "crank", "coupler"),
                                   ("C", 2, "coupler", "rocker"), ("D", 3, "ground", "rocker")):
        d.pin(name, "revolute", first, second, Op[i], Zs[i])
    M = add(lerp(Op[1], Op[2], 0.5), mul(unit(cross(sub(Op[2], Op[1]), Zs[1])), 0.5))
    d.marker("coupler", "M", M)
    d.input("theta", "angle", "A")
    d.sweep = {"input": "theta", "from": 0.0, "to": 360.0, "steps": 361, "trace": ["coupler.M"]}
    K = math.sin((be + al) / 2) / math.sin((be - al) / 2)
    d.h("bennett: the Bennett linkage, a movable spatial 4R loop.",
        "Links (Denavit-Hartenberg, zero offsets): crank A-B and rocker C-D: a = %g, twist alpha = %g deg;" % (a, al_d),
        "coupler B-C and ground D-A: b = a sin(beta) / sin(alpha) = %.12g, twist beta = %g deg, so" % (b, be_d),
        "a / sin(alpha) = b / sin(beta) (= %.9g).  Frame i+1 = frame i Rz(theta_i) Tx(a_i) Rx(alpha_i); the" % (a / math.sin(al)),
        "joint angles obey tan(th1/2) tan(th2/2) = sin((beta+alpha)/2) / sin((beta-alpha)/2) = %.9g," % K,
        "th3 = -th1, th4 = -th2 (loop closure checked to 1e-12 for 3600 inputs).  Drawn at th1 = 50 deg.",
        "Each joint's markers are at the point where the two adjacent common normals meet its axis",
        "(zero offsets), with z = the DH axis z_i.  As th1 turns 360 deg, th2 turns 360 deg the other",
        "way (th2 = 2 atan(K cot(th1/2)); dth2/dth1 stays between -K and -1/K): no dead point.",
        "Placing C as circle (about axis B) x circle (about axis D): over 3600 inputs one candidate",
        "is the Bennett pose and the other misses the first circle by >= %.4f (%.3f of a + b)," % (miss, miss / (a + b)),
        "so the choice is never ambiguous.  coupler.M (off the coupler's axes) is traced.",
        "Closed forms checked: the DH chain with th2 from Bennett's relation (positions of B, C, D,",
        "M), and the relation itself on the DH angles measured from the solved poses.",
        "Counts: 3 moving bodies, 4 revolutes = 20 equations, Grubler -2, mobility 1 (the Bennett",
        "conditions), so 3 redundant rows at the drawn pose.")
    d.expect(3, 4, 20, 1, 3, 0)
    return d


# ---------------------------------------------------------------------------
# 6. tilted four-bar

def tilted_fourbar():
    o = (1.0, -2.0, 0.5)
    k = unit((1.0, 1.0, 0.0))
    ang = math.radians(35.0)
    e1, e2 = rot(X, k, ang), rot(Y, k, ang)
    n = cross(e1, e2)

    def P(u, v):
        return add(o, add(mul(e1, u), mul(e2, v)))
    A, D, B, C, Pp = P(0, 0), P(4, 0), P(1, 1), P(4.5, 2.5), P(3, 3.5)
    d = Doc("tilted_fourbar")
    d.body("ground", fixed=True)
    d.marker("ground", "A", A, n)
    d.marker("ground", "D", D, n)
    d.marker("crank", "A", A, n)
    d.marker("crank", "B", B, n)
    d.marker("coupler", "B", B, n)
    d.marker("coupler", "C", C, n)
    d.marker("coupler", "P", Pp)
    d.marker("rocker", "C", C, n)
    d.marker("rocker", "D", D, n)
    d.joint("A", "revolute", "ground.A", "crank.A")
    d.joint("B", "revolute", "crank.B", "coupler.B")
    d.joint("C", "revolute", "coupler.C", "rocker.C")
    d.joint("D", "revolute", "rocker.D", "ground.D")
    d.input("theta", "angle", "A")
    d.sweep = {"input": "theta", "from": 0.0, "to": 360.0, "steps": 361, "trace": ["coupler.P"]}
    d.h("tilted_fourbar: mechanisms/fourbar.toml (ground A = (0,0), D = (4,0); crank B = (1,1);",
        "coupler C = (4.5,2.5), P = (3,3.5); rocker) mapped into a tilted plane by",
        "X(u, v) = o + u e1 + v e2, with the x-y plane turned by 35 deg about (1, 1, 0)/sqrt2:",
        "o = %s" % vec(o),
        "e1 = %s" % vec(e1),
        "e2 = %s" % vec(e2),
        "Every revolute axis is the plane normal n = e1 x e2 = %s (on both markers)," % vec(n),
        "so the angle input theta (right-handed about n) is fourbar's counter-clockwise crank angle.",
        "Same names, joints (D = [rocker.D, ground.D]), input and sweep (theta 0..360, 361 steps,",
        "trace coupler.P) as fourbar.toml, which is a Grashof crank-rocker (s + l = 5.414 <= p + q =",
        "6.357, the crank shortest): it turns fully with transmission angle in ~[42.5, 115.3] deg.",
        "Closed form checked: the planar four-bar of fourbar.toml solved by circle intersection",
        "(drawn side kept) and mapped through o, e1, e2, for crank.B, coupler.C, coupler.P.",
        "Counts: 3 moving bodies, 4 revolutes = 20 equations, Grubler -2; a planar loop in 3D has 3",
        "redundant out-of-plane rows, mobility 1.")
    d.expect(3, 4, 20, 1, 3, 0)
    return d


# ---------------------------------------------------------------------------
# 7. excavator

def tri_angle(P, Q, R, L):
    a, b = norm(sub(Q, P)), norm(sub(R, P))
    return (a * a + b * b - L * L) / (2 * a * b)


def excavator():
    P1 = (0.8, 0.0, 1.6)       # boom pivot (turret)
    P2 = (4.0, 0.0, 3.6)       # stick pivot (boom tip)
    Q1 = (1.2, 0.0, 0.9)       # boom cylinder barrel pin (turret)
    R1 = (2.4, 0.0, 2.3)       # boom cylinder rod pin (boom)
    Q2 = (2.2, 0.0, 3.4)       # stick cylinder barrel pin (boom)
    R2 = (3.7, 0.0, 4.4)       # stick cylinder rod pin (stick tail)
    T = (4.9, 0.0, 1.0)        # stick tip
    F = (4.8, 0.0, 1.3)        # bucket mount (fixed joint)
    Kt = (5.4, 0.0, 0.6)       # bucket tip
    slew, boom, stick = 90.0, 0.4, -0.3
    L1, L2 = norm(sub(R1, Q1)), norm(sub(R2, Q2))
    # design check: both cylinder triangles close with margin over the whole stroke
    cs = []
    for f in (k / 600.0 for k in range(601)):
        cs.append(tri_angle(P1, Q1, R1, L1 + boom * f))
        cs.append(tri_angle(P2, Q2, R2, L2 + stick * f))
    assert max(abs(c) for c in cs) < 0.8
    # transmission: angle between each cylinder and its lever arm (at the rod pin) stays away
    # from 0 / 180: the rod pin's lever (R - P) vs the cylinder (R - Q)
    d = Doc("excavator")
    d.body("ground", fixed=True)
    d.pin("slew_bearing", "revolute", "ground", "turret", O, Z)
    d.pin("boom_pivot", "revolute", "turret", "boom", P1, Y)
    d.pin("stick_pivot", "revolute", "boom", "stick", P2, Y)
    d.marker("stick", "tip", T)
    d.pin("bucket_mount", "fixed", "stick", "bucket", F)
    d.marker("bucket", "tip", Kt)
    for cyl, Q, R, host1, host2 in (("boom", Q1, R1, "turret", "boom"), ("stick", Q2, R2, "boom", "stick")):
        ax = unit(sub(R, Q))
        Lc = norm(sub(R, Q))
        barrel, rod = cyl + "_barrel", cyl + "_rod"
        d.pin(cyl + "_barrel_pin", "revolute", host1, barrel, Q, Y, n1=cyl + "_barrel", n2="pin")
        m1 = d.marker(barrel, "bore", add(Q, mul(ax, 0.3 * Lc)), ax)
        m2 = d.marker(rod, "piston", add(Q, mul(ax, 0.6 * Lc)), ax)
        d.joint(cyl + "_cylinder", "cylindrical", m1, m2)
        d.pin(cyl + "_rod_pin", "revolute", host2, rod, R, Y, n1=cyl + "_rod", n2="pin")
    d.input("slew", "angle", "slew_bearing")
    d.input("boom_cyl", "slide", "boom_cylinder")
    d.input("stick_cyl", "slide", "stick_cylinder")
    d.sweep = {"steps": 61, "inputs": {"slew": (0.0, slew), "boom_cyl": (0.0, boom), "stick_cyl": (0.0, stick)},
               "trace": ["bucket.tip", "stick.tip"]}
    c1a, c1b = tri_angle(P1, Q1, R1, L1), tri_angle(P1, Q1, R1, L1 + boom)
    c2a, c2b = tri_angle(P2, Q2, R2, L2), tri_angle(P2, Q2, R2, L2 + stick)
    d.h("excavator: turret, boom, stick, bucket and two hydraulic cylinders (arm in the plane y = 0 as drawn).",
        "turret: revolute slew_bearing to ground about +z at the origin (angle input slew).",
        "boom: revolute boom_pivot to the turret at P1 = (0.8, 0, 1.6), axis +y (normal to the arm plane).",
        "stick: revolute stick_pivot to the boom at P2 = (4, 0, 3.6), axis +y; tip (4.9, 0, 1).",
        "bucket: fixed to the stick at (4.8, 0, 1.3); bucket.tip = (5.4, 0, 0.6) is traced.",
        "Boom cylinder: boom_barrel pinned to the turret at Q1 = (1.2, 0, 0.9) (revolute, axis +y);",
        "boom_rod in the barrel by the cylindrical joint boom_cylinder, first marker boom_barrel.bore on",
        "the cylinder axis Q1 -> R1 with z along it (slide input boom_cyl = extension), the rod's",
        "marker also on that axis; boom_rod pinned to the boom at R1 = (2.4, 0, 2.3), ON the cylinder axis",
        "(revolute, axis +y).  Stick cylinder likewise: barrel pin on the boom at Q2 = (2.2, 0, 3.4), rod",
        "pin on the stick's tail at R2 = (3.7, 0, 4.4) (slide input stick_cyl).",
        "Sweep: 61 steps, slew 0 -> %g deg, boom_cyl 0 -> %g, stick_cyl 0 -> %g together.  Each cylinder" % (slew, boom, stick),
        "length L sets its pivot's angle by the law of cosines in the triangle (pivot, barrel pin,",
        "rod pin): cos of the angle at P1 goes %.4f -> %.4f, at P2 %.4f -> %.4f, all |cos| <= 0.8" % (c1a, c1b, c2a, c2b),
        "over the sweep (no triangle flattens), so the arm assembles everywhere.",
        "Closed form checked: slew, then boom and stick turns from the two triangles, composed; every",
        "turret/boom/stick/bucket marker and the cylinder pins compared.",
        "Counts: 8 moving bodies; 7 revolutes, 2 cylindrical, 1 fixed = 35 + 8 + 6 = 49 equations,",
        "Grubler 48 - 49 = -1.  Each cylinder loop is planar: 3 bodies with 3 out-of-plane freedoms",
        "each against 3 + 3 + 3 + 2 out-of-plane rows, 2 redundant per loop: 4 redundant, mobility 3",
        "(slew and the two cylinders), no idle freedom (each rod's spin is held by its pin).")
    d.expect(8, 10, 49, 3, 4, 0)
    return d


# ---------------------------------------------------------------------------
# 8. sofa bed

SOFA = {  # (x, z) of the side linkage in its plane
    "A": (0.0, 0.0), "B": (0.3, 0.5), "D": (1.6, 0.0), "C": (1.4, 0.9), "H": (0.8, 1.1),
    "E": (-0.6, 0.3), "F": (-0.7, 0.9), "G": (0.0, 1.6), "K": (1.3, 1.5),
}


def circle2(c1, r1, c2, r2, prev):
    dx, dz = c2[0] - c1[0], c2[1] - c1[1]
    dd = math.hypot(dx, dz)
    a = (dd * dd + r1 * r1 - r2 * r2) / (2 * dd)
    h2 = r1 * r1 - a * a
    if h2 <= 0:
        return None, 0.0
    h = math.sqrt(h2)
    ex, ez = dx / dd, dz / dd
    cands = [(c1[0] + a * ex - s * h * ez, c1[1] + a * ez + s * h * ex) for s in (1, -1)]
    best = min(cands, key=lambda q: math.hypot(q[0] - prev[0], q[1] - prev[1]))
    return best, h / min(r1, r2)


def rot2y(p, c, th):
    # rotation about +y in (x, z): x' = x cos + z sin, z' = -x sin + z cos
    x, z = p[0] - c[0], p[1] - c[1]
    ct, st = math.cos(th), math.sin(th)
    return (c[0] + x * ct + z * st, c[1] - x * st + z * ct)


def sofa_bed():
    S = SOFA
    W = 1.8
    th1, th2 = -40.0, -30.0
    d2 = lambda p, q: math.hypot(p[0] - q[0], p[1] - q[1])
    # design check: both RRR dyads of one side over the sweep (both inputs together)
    prevC, prevG, hmin = S["C"], S["G"], float("inf")
    for k in range(601):
        f = k / 600.0
        B = rot2y(S["B"], S["A"], math.radians(th1 * f))
        F = rot2y(S["F"], S["E"], math.radians(th2 * f))
        C, h1 = circle2(B, d2(S["B"], S["C"]), S["D"], d2(S["D"], S["C"]), prevC)
        assert C is not None
        # H on the coupler
        a0 = math.atan2(S["C"][1] - S["B"][1], S["C"][0] - S["B"][0])
        a1 = math.atan2(C[1] - B[1], C[0] - B[0])
        c, s = math.cos(a1 - a0), math.sin(a1 - a0)
        hx, hz = S["H"][0] - S["B"][0], S["H"][1] - S["B"][1]
        H = (B[0] + c * hx - s * hz, B[1] + s * hx + c * hz)
        G, h2 = circle2(F, d2(S["F"], S["G"]), H, d2(S["H"], S["G"]), prevG)
        assert G is not None
        prevC, prevG = C, G
        hmin = min(hmin, h1, h2)
    assert hmin > 0.5, hmin
    d = Doc("sofa_bed")
    d.body("ground", fixed=True)

    def P(key, y):
        return (S[key][0], y, S[key][1])
    for side, y in (("l", 0.0), ("r", W)):
        def b(name):
            return name + "_" + side
        d.pin("A_" + side, "revolute", "ground", b("crank"), P("A", y), Y, n1="A_" + side, n2="A")
        d.pin("B_" + side, "revolute", b("crank"), b("coupler"), P("B", y), Y, n1="B", n2="B")
        d.pin("C_" + side, "revolute", b("coupler"), b("rocker"), P("C", y), Y, n1="C", n2="C")
        d.pin("D_" + side, "revolute", "ground", b("rocker"), P("D", y), Y, n1="D_" + side, n2="D")
        d.pin("E_" + side, "revolute", "ground", b("lever"), P("E", y), Y, n1="E_" + side, n2="E")
        d.pin("F_" + side, "revolute", b("lever"), b("link"), P("F", y), Y, n1="F", n2="F")
        d.pin("G_" + side, "revolute", b("link"), b("arm"), P("G", y), Y, n1="G", n2="G")
        d.pin("H_" + side, "revolute", b("coupler"), b("arm"), P("H", y), Y, n1="H", n2="H")
        d.marker(b("arm"), "K", P("K", y))
    # torque tubes on the crank and lever pivot lines, each in two halves with a rigid coupling
    for link, piv, tip in (("crank", "A", "B"), ("lever", "E", "F")):
        tl, tr = "%s_tube_l" % link, "%s_tube_r" % link
        Tp = lambda y: (S[piv][0] + 0.25 * (S[tip][0] - S[piv][0]), y, S[piv][1] + 0.25 * (S[tip][1] - S[piv][1]))
        d.pin("%s_tube_l" % link, "fixed", link + "_l", tl, Tp(0.0), n1="T", n2="end")
        d.pin("%s_tube_mid" % link, "fixed", tl, tr, P(piv, 0.5 * W), n1="mid", n2="mid")
        d.pin("%s_tube_r" % link, "fixed", link + "_r", tr, Tp(W), n1="T", n2="end")
    # reorder bodies: ground, left side, right side, tubes (dict keeps insertion order already)
    d.input("theta1", "angle", "A_l")
    d.input("theta2", "angle", "E_l")
    d.sweep = {"steps": 61, "inputs": {"theta1": (0.0, th1), "theta2": (0.0, th2)},
               "trace": ["arm_r.K", "arm_l.K"]}
    xz = lambda k: "(%g, %g)" % S[k]
    d.h("sofa_bed: in the spirit of Kramer's sofa-bed (Figure 7): two identical planar side linkages,",
        "left in the plane y = 0 and right in y = W, W = %g, joined by cross members; heavily" % W,
        "over-constrained yet consistent.  16 moving bodies, 22 joints, 2 angle inputs.",
        "Each side (x forward, z up; every revolute axis +y), 6 bodies and 8 revolutes, planar",
        "mobility 3*6 - 2*8 = 2, solvable by dyads:",
        "  crank  : ground pivot A %s (input theta1 on the left), pin B %s" % (xz("A"), xz("B")),
        "  coupler: B, C %s, H %s;  rocker: ground pivot D %s, C  (four-bar A-B-C-D)" % (xz("C"), xz("H"), xz("D")),
        "  lever  : ground pivot E %s (input theta2 on the left), pin F %s" % (xz("E"), xz("F")),
        "  link   : F, G %s;  arm: G, H (on the coupler), tip K %s  (RRR dyad F-G-H)" % (xz("G"), xz("K")),
        "Cross members: two torque tubes, one joining the cranks and one joining the levers, each",
        "made of two halves: crank_tube_l is fixed to crank_l at T = A + (B - A)/4 in the left plane,",
        "crank_tube_r to crank_r at the same point of the right plane, and the halves are fixed to",
        "each other at y = W/2 on the crank pivot line (a rigid flange coupling); the lever tubes",
        "likewise (T = E + (F - E)/4, coupling on the lever pivot line).  So the right side is the",
        "left side shifted by (0, W, 0), marker for marker.  The inputs turn the LEFT crank and lever;",
        "the tubes drive the right ones, whose own ground revolutes A_r, E_r become redundant, and",
        "the right dyads follow.  Bodies: 2 x 6 side links + 4 tube halves = 16; joints: 2 x 8",
        "revolutes + 6 fixed = 22.",
        "Sweep: 61 steps, theta1 0 -> %g deg and theta2 0 -> %g deg together (right-handed about +y)." % (th1, th2),
        "Over the sweep both dyads of a side keep half-chord h >= %.3f of the shorter link (circle-" % hmin,
        "circle intersection far from tangency), so it assembles everywhere.",
        "Closed form checked: the left four-bar and dyad by circle intersection in the plane, and",
        "every right-side marker = its left twin + (0, W, 0).",
        "Counts: 16 moving bodies, 16 x 5 + 6 x 6 = 116 equations, Grubler 96 - 116 = -20; rank 94:",
        "6 out-of-plane rows per side (2 loops x 3) + 5 per right ground pivot (A_r, E_r) = 22",
        "redundant, mobility 2.  (Kramer: 115 constraints incl. 2 inputs, 19 redundant; here 118 incl.",
        "inputs, 22 redundant; his joint list is not published, so this is not a copy.)")
    d.expect(16, 22, 116, 2, 22, 0)
    return d


# ---------------------------------------------------------------------------
# 9. Stewart platform

def solve_lin(A, b):
    """Gaussian elimination with partial pivoting (dense, small)."""
    n = len(b)
    M = [list(A[i]) + [b[i]] for i in range(n)]
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(M[i][k]))
        if abs(M[p][k]) < 1e-300:
            raise ValueError("singular")
        M[k], M[p] = M[p], M[k]
        for i in range(k + 1, n):
            f = M[i][k] / M[k][k]
            for j in range(k, n + 1):
                M[i][j] -= f * M[k][j]
    x = [0.0] * n
    for k in range(n - 1, -1, -1):
        x[k] = (M[k][n] - sum(M[k][j] * x[j] for j in range(k + 1, n))) / M[k][k]
    return x


def det(A):
    n = len(A)
    M = [list(r) for r in A]
    dsum = 1.0
    for k in range(n):
        p = max(range(k, n), key=lambda i: abs(M[i][k]))
        if M[p][k] == 0:
            return 0.0
        if p != k:
            M[k], M[p] = M[p], M[k]
            dsum = -dsum
        dsum *= M[k][k]
        for i in range(k + 1, n):
            f = M[i][k] / M[k][k]
            for j in range(k, n):
                M[i][j] -= f * M[k][j]
    return dsum


def stewart():
    Rb, Rp, h0 = 1.2, 0.8, 1.0
    bang = [-15, 15, 105, 135, 225, 255]
    pang = [-45, 45, 75, 165, 195, 285]
    base = [(Rb * math.cos(math.radians(t)), Rb * math.sin(math.radians(t)), 0.0) for t in bang]
    plat = [(Rp * math.cos(math.radians(t)), Rp * math.sin(math.radians(t)), h0) for t in pang]
    c0 = (0.0, 0.0, h0)
    axis, ang, shift = X, 10.0, (0.1, 0.0, 0.25)

    def pose(p, axis_, ang_, shift_):
        return add(add(c0, rot(sub(p, c0), axis_, math.radians(ang_))), shift_)
    L0 = [norm(sub(p, b)) for p, b in zip(plat, base)]
    L1 = [norm(sub(pose(p, axis, ang, shift), b)) for p, b in zip(plat, base)]
    # design check: forward kinematics along the linear leg-length path, by Newton on the
    # platform pose (rotation vector about c0 + shift); conditioning and U-joint margins.
    def res(w_, t_, Lk):
        th = norm(w_)
        out = []
        for p, b, l in zip(plat, base, Lk):
            q = add(add(c0, rot(sub(p, c0), w_, th) if th > 0 else sub(p, c0)), t_)
            out.append(norm(sub(q, b)) - l)
        return out

    def jac(w_, t_, Lk):
        r = res(w_, t_, Lk)
        J = [[0.0] * 6 for _ in range(6)]
        hstep = 1e-7
        for c in range(6):
            w2, t2 = list(w_), list(t_)
            (w2 if c < 3 else t2)[c % 3] += hstep
            r2 = res(tuple(w2), tuple(t2), Lk)
            for i in range(6):
                J[i][c] = (r2[i] - r[i]) / hstep
        return r, J
    w, tr = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    jmin, umax, steps = float("inf"), 0.0, 600
    det0 = None
    for k in range(steps + 1):
        f = k / steps
        Lk = [l0 + (l1 - l0) * f for l0, l1 in zip(L0, L1)]
        for it in range(30):
            r, J = jac(w, tr, Lk)
            if max(abs(v) for v in r) < 1e-14:
                break
            dx = solve_lin(J, [-v for v in r])
            w = tuple(w[i] + dx[i] for i in range(3))
            tr = tuple(tr[i] + dx[3 + i] for i in range(3))
        assert max(abs(v) for v in r) < 1e-12
        dj = abs(det(J))
        det0 = det0 or dj
        jmin = min(jmin, dj / det0)
        th = norm(w)
        for i, (p, b) in enumerate(zip(plat, base)):
            q = add(add(c0, rot(sub(p, c0), w, th) if th > 0 else sub(p, c0)), tr)
            z1 = (-math.sin(math.radians(bang[i])), math.cos(math.radians(bang[i])), 0.0)
            umax = max(umax, abs(dot(unit(sub(q, b)), z1)))
    # end pose reached
    end_ok = max(norm(sub(add(add(c0, rot(sub(p, c0), w, norm(w))), tr), pose(p, axis, ang, shift)))
                 for p in plat)
    assert end_ok < 1e-9 and jmin > 0.3 and umax < 0.7, (end_ok, jmin, umax)
    d = Doc("stewart")
    d.body("ground", fixed=True)
    d.body("platform")
    for i in range(6):
        leg = i + 1
        b, p = base[i], plat[i]
        dv = unit(sub(p, b))
        z1 = (-math.sin(math.radians(bang[i])), math.cos(math.radians(bang[i])), 0.0)
        z2 = unit(cross(z1, dv))
        barrel, rod = "barrel%d" % leg, "rod%d" % leg
        d.pin("U%d" % leg, "universal", "ground", barrel, b, z1, z2=z2, n1="U%d" % leg, n2="U")
        m1 = d.marker(barrel, "bore", add(b, mul(dv, 0.35 * L0[i])), dv)
        m2 = d.marker(rod, "piston", add(b, mul(dv, 0.65 * L0[i])), dv)
        d.joint("C%d" % leg, "cylindrical", m1, m2)
        d.pin("S%d" % leg, "spherical", rod, "platform", p, n1="S", n2="S%d" % leg)
        d.input("leg%d" % leg, "slide", "C%d" % leg)
    d.marker("platform", "tool", (0.0, 0.0, h0 + 0.3))
    d.sweep = {"steps": 41, "inputs": {"leg%d" % (i + 1): (0.0, L1[i] - L0[i]) for i in range(6)},
               "trace": ["platform.tool"]}
    d.h("stewart: Stewart platform, 6-UCS.  Base (ground) attachment points b_i on a circle of radius",
        "%g at z = 0, angles %s deg; platform points p_i on a circle of radius %g at" % (Rb, bang, Rp),
        "z = %g, angles %s deg (leg i joins b_i and p_i)." % (h0, pang),
        "Leg i: barrel<i> (universal U<i> to the base: first marker on the base with z = the",
        "horizontal tangent of the base circle at b_i, barrel's z = z1 x leg direction) + rod<i>",
        "(cylindrical C<i> barrel -> rod, first marker barrel<i>.bore on the leg axis with z along",
        "the leg; slide input leg<i>) + spherical S<i> rod -> platform at p_i (rod<i>.S on the leg",
        "axis).  Each rod spins idle about its leg axis.",
        "Motion (heave + tilt): the platform goes from the drawn pose to the end pose",
        "q -> centre + Rot(axis, angle_deg) (q - centre) + shift with",
        "centre = %s, axis = %s, angle_deg = %g, shift = %s." % (vec(c0), vec(axis), ang, vec(shift)),
        "The leg lengths of both end poses are computed exactly; the sweep (41 steps) moves all six",
        "slides linearly together from 0 to L_end - L_drawn.  Forward kinematics solved along the",
        "path (601 samples, Newton on the platform pose) reaches the end pose (error %.1e) with" % end_ok,
        "|det J| of the leg-length Jacobian >= %.3f of its drawn value (no singularity) and every" % jmin,
        "leg at least acos(%.3f) = %.1f deg from its base crosspin (no universal lock)." % (umax, math.degrees(math.acos(umax))),
        "Closed form checked: the last frame = the prescribed end pose.",
        "Counts: 13 moving bodies, 6 x (U 4 + C 4 + S 3) = 66 equations, Grubler 78 - 66 = 12, no",
        "redundancy; mobility 12 = 6 (platform) + 6 rod spins, idle 6 once the legs are driven.")
    d.expect(13, 18, 66, 12, 0, 6)
    return d


# ---------------------------------------------------------------------------
# 10. chains of RSSR loops

STRESS_SEED = 20250301
STRESS_MAX = 100
SPACING = 4.0
SAMPLES = 720


def stress_chain():
    """Design STRESS_MAX loops; each file uses a prefix.

    Loop 1: random rocker (radius 2..3) for the full-turn crank.  Loop i > 1: a spatial
    near-parallelogram driven by rocker_{i-1}: B<i> at radius 1..1.5 about the previous
    rocker's axis (random direction, axial offset +-0.3), C<i> = B<i> + (G_i - G_{i-1}) + a
    random offset of up to 0.25 per coordinate.  A candidate is kept only if its rocker
    assembles over the previous body's whole motion with |c| / rho <= 0.75 and swings
    30..75 deg; of up to 8 such candidates the one with swing nearest 50 deg (and the
    smallest |c| / rho) is taken."""
    rng = random.Random(STRESS_SEED)
    B1 = rot((1.0, 0.0, 0.0), Z, math.radians(30.0))
    drv_pivot, drv_axis, drv_angles = O, Z, [2 * math.pi * k / SAMPLES for k in range(SAMPLES + 1)]
    loops, stats = [], []
    for i in range(1, STRESS_MAX + 1):
        G = (SPACING * i, rng.uniform(-0.4, 0.4), rng.uniform(-0.4, 0.4))
        valid = []
        for attempt in range(4000):
            tilt = math.radians(rng.uniform(10.0, 35.0))
            az = rng.uniform(0.0, 2 * math.pi)
            a = (math.sin(tilt) * math.cos(az), math.sin(tilt) * math.sin(az), math.cos(tilt))
            if i == 1:
                B = B1
                r = rng.uniform(2.0, 3.0)
                psi = rng.uniform(0.0, 2 * math.pi)
                u = unit(cross(a, X))
                w = cross(a, u)
                C = add(G, add(mul(u, r * math.cos(psi)), mul(w, r * math.sin(psi))))
            else:
                u = unit(cross(drv_axis, X))
                w = cross(drv_axis, u)
                psi = rng.uniform(0.0, 2 * math.pi)
                rb = rng.uniform(1.0, 1.5)
                B = add(add(drv_pivot, mul(drv_axis, rng.uniform(-0.3, 0.3))),
                        add(mul(u, rb * math.cos(psi)), mul(w, rb * math.sin(psi))))
                C = add(add(B, sub(G, drv_pivot)), tuple(rng.uniform(-0.25, 0.25) for _ in range(3)))
            foot = add(G, mul(a, dot(sub(C, G), a)))
            if norm(sub(C, foot)) < 0.6:
                continue
            ell = norm(sub(C, B))
            prev, worst, phis, ok = 0.0, 0.0, [], True
            for th in drv_angles:
                Bw = rotp(B, drv_pivot, drv_axis, th)
                phi, m = rocker_solve(Bw, C, G, a, ell, prev)
                if phi is None or m > 0.75:
                    ok = False
                    break
                prev, worst = phi, max(worst, m)
                phis.append(phi)
            if not ok or abs(phis[-1] - phis[0]) > 1e-9:
                continue
            swing = max(phis) - min(phis)
            if not math.radians(30.0) <= swing <= math.radians(75.0):
                continue
            valid.append((abs(math.degrees(swing) - 50.0) / 25.0 + worst, attempt, a, B, C, ell, phis, worst, swing))
            if len(valid) >= 8:
                break
        if not valid:
            raise RuntimeError("stress loop %d: no design found" % i)
        _, _, a, B, C, ell, phis, worst, swing = min(valid)
        loops.append({"G": G, "a": a, "C": C, "B": B, "ell": ell})
        stats.append((worst, math.degrees(swing)))
        drv_pivot, drv_axis, drv_angles = G, a, phis
    return loops, stats


def spatial_stress(N, loops, stats):
    d = Doc("spatial_stress_%d" % N)
    d.body("ground", fixed=True)
    d.pin("O0", "revolute", "ground", "crank", O, Z)
    prev = "crank"
    for i in range(1, N + 1):
        lp = loops[i - 1]
        cpl, rk = "coupler_%d" % i, "rocker_%d" % i
        d.pin("B%d" % i, "spherical", prev, cpl, lp["B"])
        d.pin("C%d" % i, "spherical", cpl, rk, lp["C"])
        d.pin("G%d" % i, "revolute", "ground", rk, lp["G"], lp["a"])
        prev = rk
    last = loops[N - 1]
    d.marker("coupler_%d" % N, "M", lerp(last["B"], last["C"], 0.5))
    d.marker("rocker_%d" % N, "T", add(last["G"], mul(sub(last["C"], last["G"]), 1.25)))
    # reorder markers: the crank's B1 and each rocker's next B come after their pivots already
    d.input("theta", "angle", "O0")
    d.sweep = {"input": "theta", "from": 0.0, "to": 360.0, "steps": 361,
               "trace": ["coupler_%d.M" % N, "rocker_%d.T" % N]}
    worst = max(s[0] for s in stats[:N])
    sw = [s[1] for s in stats[:N]]
    d.h("spatial_stress_%d: a chain of %d R-S-S-R loops (%d moving bodies, %d joints)." % (N, N, 2 * N + 1, 3 * N + 1),
        "Generated with seed %d; every spatial_stress file is a prefix of the %d-loop design." % (STRESS_SEED, STRESS_MAX),
        "crank: revolute O0 to ground about +z at the origin (angle input theta, full turn), B1 at",
        "radius 1, drawn at 30 deg.  Loop i: coupler_i (spherical B<i> on the previous crank/rocker,",
        "spherical C<i> on rocker_i) and rocker_i (revolute G<i> to ground at G_i = (4 i, y, z), y, z in",
        "+-0.4, about an axis tilted 10..35 deg from +z in a random azimuth).  Loop i's rocker is",
        "loop i+1's crank: it carries B<i+1>.",
        "Design: loop 1's rocker arm is 2..3 long (crank-rocker); every later loop is a spatial",
        "near-parallelogram: B<i> at radius 1..1.5 about the previous rocker's axis in a random",
        "direction (axial offset +-0.3), C<i> = B<i> + (G_i - G_{i-1}) + up to +-0.25 per coordinate.",
        "A loop is accepted only if, over the previous body's whole motion (%d samples of the full" % SAMPLES,
        "crank turn), its rocker's one-angle equation a cos phi + b sin phi = c keeps",
        "|c| / sqrt(a^2 + b^2) <= 0.75 (here max %.3f: far from every dead point) and its rocker" % worst,
        "swings 30..75 deg (here %.1f..%.1f deg); of up to 8 such random candidates the one with" % (min(sw), max(sw)),
        "swing nearest 50 deg is kept.  So the whole chain follows theta 0..360 (361 steps).",
        "Traced: coupler_%d.M (midpoint of B-C, independent of the coupler's spin) and rocker_%d.T." % (N, N),
        "Closed form checked: the one-angle equation loop after loop (branch by continuity).",
        "Counts: 2N+1 = %d moving bodies, R + N (S + S + R) = 11N + 5 = %d equations, Grubler N + 1 = %d," % (2 * N + 1, 11 * N + 5, N + 1),
        "no redundancy; mobility N + 1 = the crank + N idle coupler spins about B-C.")
    d.expect(2 * N + 1, 3 * N + 1, 11 * N + 5, N + 1, 0, N)
    return d


# ---------------------------------------------------------------------------

def main(argv):
    global STRESS_MAX
    if argv[:1] == ["--stress"]:
        # One longer chain for scaling measurements (not bundled):
        # tools/generate/spatial.py --stress N OUTDIR.
        n = int(argv[1])
        STRESS_MAX = max(STRESS_MAX, n)
        loops, stats = stress_chain()
        d = spatial_stress(n, loops, stats)
        path = os.path.join(argv[2], d.name + ".toml")
        with open(path, "w") as f:
            f.write(d.text())
        print("wrote %s" % path)
        return 0
    out = argv[0] if argv else os.path.join(REPO, "mechanisms", "spatial")
    os.makedirs(out, exist_ok=True)
    docs = [cardan(), double_cardan(), rssr(), spherical_fourbar(), bennett(), tilted_fourbar(),
            excavator(), sofa_bed(), stewart()]
    loops, stats = stress_chain()
    for N in (10, 20, 30, 50, 100):
        docs.append(spatial_stress(N, loops, stats))
    for d in docs:
        path = os.path.join(out, d.name + ".toml")
        with open(path, "w") as f:
            f.write(d.text())
        print("wrote %s" % os.path.relpath(path, REPO))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
