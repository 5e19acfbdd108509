#!/usr/bin/env python3
"""Generate the hand-designed bundled mechanisms (everything except stress_N).

Deterministic, stdlib only.  Usage:  python3 tools/generate/mechanisms.py [outdir]
(default outdir: <repo>/mechanisms).  The stress chains come from
tools/generate/stress.py; the checker is tools/check/mechanisms.py.

Coordinates that are computed are written with repr() (shortest round-trip
form of the double), and both markers of a revolute joint are written from the
same float, so they coincide exactly.
"""
import math
import os
import sys

# ----------------------------------------------------------------------------
# small geometry helpers


def fmt(v):
    if isinstance(v, int):
        return str(v)
    if abs(v) < 1e-13:
        v = 0.0
    return repr(float(v))


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1])


def mul(a, k):
    return (a[0] * k, a[1] * k)


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1]


def norm(a):
    return math.hypot(a[0], a[1])


def polar(r, deg, c=(0.0, 0.0)):
    t = math.radians(deg)
    return (c[0] + r * math.cos(t), c[1] + r * math.sin(t))


def cc(c1, r1, c2, r2, sign):
    """Intersection of circle(c1, r1) and circle(c2, r2); sign=+1 picks the
    point left of c1->c2 (cross(c2-c1, X-c1) > 0).  Returns (X, h)."""
    d = sub(c2, c1)
    dd = norm(d)
    a = (dd * dd + r1 * r1 - r2 * r2) / (2 * dd)
    h2 = r1 * r1 - a * a
    if h2 < 0:
        return None, h2
    h = math.sqrt(h2)
    e = (d[0] / dd, d[1] / dd)
    return (c1[0] + a * e[0] - sign * h * e[1], c1[1] + a * e[1] + sign * h * e[0]), h


def sin_mu(x, c1, c2):
    u, v = sub(c1, x), sub(c2, x)
    return abs(cross(u, v)) / (norm(u) * norm(v))


# ----------------------------------------------------------------------------
# TOML writer


class Mech:
    def __init__(self, name, header):
        self.name = name
        self.header = header
        self.bodies = []  # (name, fixed, [(mname, pt, dir|None)])
        self.joints = []  # (name, kind, m1, m2)
        self.inputs = []  # (name, kind, joint)
        self.sweep = None

    def body(self, name, markers, fixed=False):
        self.bodies.append((name, fixed, markers))

    def joint(self, name, kind, m1, m2):
        self.joints.append((name, kind, m1, m2))

    def text(self):
        out = []
        w = out.append
        for line in self.header.strip("\n").split("\n"):
            w(("# " + line).rstrip())
        w('name = "%s"' % self.name)
        for bname, fixed, markers in self.bodies:
            w("")
            w("[bodies.%s]" % bname)
            if fixed:
                w("fixed = true")
            items = []
            for m in markers:
                mname, p = m[0], m[1]
                d = m[2] if len(m) > 2 else None
                ps = "[%s, %s]" % (fmt(p[0]), fmt(p[1]))
                if d is None:
                    items.append("%s = %s" % (mname, ps))
                else:
                    items.append("%s = { at = %s, dir = [%s, %s] }" % (mname, ps, fmt(d[0]), fmt(d[1])))
            w("markers = { %s }" % ", ".join(items))
        w("")
        for jname, kind, m1, m2 in self.joints:
            w("[joints.%s]" % jname)
            w('kind = "%s"' % kind)
            w('markers = ["%s", "%s"]' % (m1, m2))
        for iname, kind, joint in self.inputs:
            w("")
            w("[inputs.%s]" % iname)
            w('kind = "%s"' % kind)
            w('joint = "%s"' % joint)
        s = self.sweep
        w("")
        w("[sweep]")
        w('input = "%s"' % s["input"])
        w("from = %s" % fmt(float(s["from"])))
        w("to = %s" % fmt(float(s["to"])))
        w("steps = %d" % s["steps"])
        w("trace = [%s]" % ", ".join('"%s"' % t for t in s["trace"]))
        return "\n".join(out) + "\n"

    def grubler(self):
        L = len(self.bodies)
        J = len(self.joints)
        return L, J, 3 * (L - 1) - 2 * J


# ----------------------------------------------------------------------------
# 1. fourbar (numbers fixed by the spec; written verbatim)

FOURBAR = '''\
# fourbar: crank-rocker four-bar A-B-C-D (the reference example of the format).
# Links: ground |AD| = 4, crank |AB| = sqrt(2) = 1.41421, coupler |BC| = sqrt(14.5) = 3.80789,
# rocker |CD| = sqrt(6.5) = 2.54951.  Coupler point P = (3, 3.5) is traced.
# Grashof: s + l = 1.41421 + 4 = 5.41421 <= p + q = 3.80789 + 2.54951 = 6.35740, and the
# shortest link is the crank (driven from ground joint A), so it is a crank-rocker: the
# circle(B,|BC|) / circle(D,|CD|) intersection exists for every crank angle, |BD| ranging over
# [4 - sqrt2, 4 + sqrt2] = [2.5858, 5.4142] inside (|BC|-|CD|, |BC|+|CD|) = (1.2584, 6.3574).
# Transmission angle mu (at C) stays within ~[42.5, 115.3] deg.
# Grubler: L = 4, J = 4, D = 3*3 - 2*4 = 1.
name = "fourbar"

[bodies.ground]
fixed = true
markers = { A = [0, 0], D = [4, 0] }

[bodies.crank]
markers = { A = [0, 0], B = [1, 1] }

[bodies.coupler]
markers = { B = [1, 1], C = [4.5, 2.5], P = [3, 3.5] }

[bodies.rocker]
markers = { C = [4.5, 2.5], D = [4, 0] }

[joints.A]
kind = "revolute"
markers = ["ground.A", "crank.A"]
[joints.B]
kind = "revolute"
markers = ["crank.B", "coupler.B"]
[joints.C]
kind = "revolute"
markers = ["coupler.C", "rocker.C"]
[joints.D]
kind = "revolute"
markers = ["rocker.D", "ground.D"]

[inputs.theta]
kind = "angle"
joint = "A"

[sweep]
input = "theta"
from = 0.0
to = 360.0
steps = 361
trace = ["coupler.P"]
'''


# ----------------------------------------------------------------------------
# 2. rocker_rocker (non-Grashof triple rocker)

def rocker_rocker():
    a, b, c, d = 2.5, 2.0, 3.0, 5.0  # input, coupler, output, ground
    phi0 = 30.0
    A, D = (0.0, 0.0), (d, 0.0)
    B = polar(a, phi0)
    C, _ = cc(B, b, D, c, +1.0)
    cosb = (a * a + d * d - (b + c) ** 2) / (2 * a * d)
    phib = math.degrees(math.acos(cosb))
    lo, hi = -phib - phi0, phib - phi0
    hdr = """\
rocker_rocker: non-Grashof four-bar (triple rocker); the input link cannot turn fully.
Links: input |AB| = a = %(a)g (driven from ground joint A), coupler |BC| = b = %(b)g,
output rocker |CD| = c = %(c)g, ground |AD| = d = %(d)g.  Non-Grashof: s + l = %(sl)g > p + q = %(pq)g.
Drawn pose: input at phi0 = %(phi0)g deg from the ground line A->D, C on the upper branch
(C left of B->D).  Input theta = phi - phi0 (phi = absolute input angle).
Break points (coupler and output rocker collinear, B-C-D stretched: |BD| = b + c, the
circle(B,b)/circle(D,c) intersection becomes tangent), by the law of cosines in triangle ABD:
    cos(phi*) = (a^2 + d^2 - (b + c)^2) / (2 a d) = %(cosb)s
    phi* = +/- acos(%(cosb)s) = +/- %(phib).10f deg
    theta* = +/-phi* - phi0:  theta_lo = %(lo).10f deg,  theta_hi = %(hi).10f deg
(the folded break |BD| = |b - c| = %(fold)g is unreachable since |BD| >= d - a = %(dma)g).
The linkage assembles exactly for theta in [theta_lo, theta_hi]; the sweep -180..180 crosses
both break points (frames -105..45 assemble, the others must be reported as not assembling).
Grubler: L = 4, J = 4, D = 1.""" % dict(a=a, b=b, c=c, d=d, sl=min(a, b, c, d) + max(a, b, c, d),
                                        pq=a + b + c + d - min(a, b, c, d) - max(a, b, c, d),
                                        phi0=phi0, cosb=repr(cosb), phib=phib, lo=lo, hi=hi,
                                        fold=abs(b - c), dma=d - a)
    m = Mech("rocker_rocker", hdr)
    n = mul((-(C[1] - B[1]), C[0] - B[0]), 1.0 / norm(sub(C, B)))  # unit left normal of B->C
    P = add(mul(add(B, C), 0.5), n)
    m.body("ground", [("A", A), ("D", D)], fixed=True)
    m.body("input", [("A", A), ("B", B)])
    m.body("coupler", [("B", B), ("C", C), ("P", P)])
    m.body("output", [("C", C), ("D", D)])
    m.joint("A", "revolute", "ground.A", "input.A")
    m.joint("B", "revolute", "input.B", "coupler.B")
    m.joint("C", "revolute", "coupler.C", "output.C")
    m.joint("D", "revolute", "ground.D", "output.D")
    m.inputs.append(("theta", "angle", "A"))
    m.sweep = dict(input="theta", **{"from": -180.0, "to": 180.0}, steps=361, trace=["coupler.P"])
    return m


# ----------------------------------------------------------------------------
# 3. slider_crank (offset)

def slider_crank():
    r, l, e, phi0 = 1.0, 3.5, 0.25, 30.0
    O = (0.0, 0.0)
    B = polar(r, phi0)
    xC = B[0] + math.sqrt(l * l - (B[1] - e) ** 2)
    C = (xC, e)
    hdr = """\
slider_crank: offset slider-crank.  Crank O->B (r = %(r)g) pivoted on ground at O = (0,0),
connecting rod B->C (l = %(l)g), slider pinned to the rod at C, sliding on a ground track
y = e = %(e)g along +x (prismatic joint S: ground.S first, dir (1,0); slider.S second).
Drawn pose: crank at phi0 = %(phi0)g deg, slider on the right of the crank (x_C > x_B).
l > r + |e| so the crank turns fully and the rod never becomes perpendicular to the track;
circle(B,l) meets the track with half-chord sqrt(l^2 - (y_B - e)^2) >= sqrt(l^2 - (r+|e|)^2).
Closed form (theta = crank input in deg, phi = phi0 + theta):
    x_C(theta) = r cos(phi) + sqrt(l^2 - (r sin(phi) - e)^2),   y_C = e
slider displacement along the track from the drawn pose: x_C(theta) - x_C(0), x_C(0) = %(x0)s.
Grubler: L = 4 (ground, crank, rod, slider), J = 4 (O, B, C revolute; S prismatic), D = 1.""" % dict(
        r=r, l=l, e=e, phi0=phi0, x0=repr(xC))
    m = Mech("slider_crank", hdr)
    m.body("ground", [("O", O), ("S", (0.0, e), (1.0, 0.0))], fixed=True)
    m.body("crank", [("O", O), ("B", B)])
    m.body("rod", [("B", B), ("C", C)])
    m.body("slider", [("C", C), ("S", C)])
    m.joint("O", "revolute", "ground.O", "crank.O")
    m.joint("B", "revolute", "crank.B", "rod.B")
    m.joint("C", "revolute", "rod.C", "slider.C")
    m.joint("S", "prismatic", "ground.S", "slider.S")
    m.inputs.append(("theta", "angle", "O"))
    m.sweep = dict(input="theta", **{"from": 0.0, "to": 360.0}, steps=361, trace=["slider.C", "crank.B"])
    return m


# ----------------------------------------------------------------------------
# 4. inverted_slider_crank

def inverted_slider_crank():
    r, d, phi0 = 1.0, 2.0, 60.0
    O2, O4 = (0.0, 0.0), (d, 0.0)
    B = polar(r, phi0)
    v = sub(B, O4)
    dirv = mul(v, 1.0 / norm(v))
    T = add(O4, mul(dirv, 3.5))
    hdr = """\
inverted_slider_crank: crank O2->B (r = %(r)g) on ground pivot O2 = (0,0); slotted rocker
pivoted on ground at O4 = (%(d)g, 0); a block pinned to the crank at B slides in the rocker's
slot, a line through O4 (prismatic joint S: rocker.S first, at O4 with dir O4->B of the drawn
pose; block.S second).  Drawn pose: crank at phi0 = %(phi0)g deg.
r < d, so the crank turns fully while the rocker oscillates and |O4B| >= d - r = %(dmr)g > 0:
the RPR dyad (block, rocker) never degenerates.  Closed form (phi = phi0 + theta):
    rocker direction  psi(theta) = atan2(r sin(phi), r cos(phi) - d)
    block position along the slot  s(theta) = |O4B| = sqrt(r^2 + d^2 - 2 r d cos(phi))
    (slide relative to the drawn pose: s(theta) - sqrt(3)); rocker rotation psi - psi(0).
Rocker tip T (3.5 from O4 along the slot) is traced.
Grubler: L = 4 (ground, crank, block, rocker), J = 4 (O2, B, O4 revolute; S prismatic), D = 1.""" % dict(
        r=r, d=d, phi0=phi0, dmr=d - r)
    m = Mech("inverted_slider_crank", hdr)
    m.body("ground", [("O2", O2), ("O4", O4)], fixed=True)
    m.body("crank", [("O2", O2), ("B", B)])
    m.body("block", [("B", B), ("S", B)])
    m.body("rocker", [("O4", O4), ("S", O4, dirv), ("T", T)])
    m.joint("O2", "revolute", "ground.O2", "crank.O2")
    m.joint("B", "revolute", "crank.B", "block.B")
    m.joint("S", "prismatic", "rocker.S", "block.S")
    m.joint("O4", "revolute", "ground.O4", "rocker.O4")
    m.inputs.append(("theta", "angle", "O2"))
    m.sweep = dict(input="theta", **{"from": 0.0, "to": 360.0}, steps=361, trace=["rocker.T"])
    return m


# ----------------------------------------------------------------------------
# 5. parallelogram

def parallelogram():
    a, g, phi0 = 2.0, 4.0, 60.0
    A, D = (0.0, 0.0), (g, 0.0)
    B = polar(a, phi0)
    C = add(B, (g, 0.0))
    P = ((B[0] + C[0]) / 2, B[1] + 1.0)
    hdr = """\
parallelogram: parallelogram four-bar.  Ground A=(0,0) -> D=(%(g)g,0), crank A->B and rocker
D->C both of length %(a)g, coupler B->C of length %(g)g (= ground).  Drawn pose: crank at
phi0 = %(phi0)g deg, C = B + (%(g)g, 0): a true parallelogram, coupler translating.
Change points: at absolute crank angle 0 deg and 180 deg (input theta = -60 / 300 and 120 deg)
all four links are collinear.  There |BD| = g - a = %(gma)g (phi = 0) or g + a = %(gpa)g (phi = 180),
i.e. exactly |BC| -/+ |CD|: the circle(B,%(g)g) / circle(D,%(a)g) intersection is tangent, a
double root, half-chord h = 0.  Geometrically both assembly modes meet there: the parallelogram
(C = B + (g,0)) and the antiparallelogram (crossed) branch.  For the parallelogram the side of C
relative to the centre line B->D (sign of cross(D-B, C-B) = g*y_B) changes sign at each change
point, so a solver that keeps the sign of the drawn-pose branch switches to the
antiparallelogram after theta = 120 and back to the parallelogram after theta = 300 (the
sweep 0..360 step 1 hits both change points exactly: theta = 120 and 300).
Grubler: L = 4, J = 4, D = 1.""" % dict(a=a, g=g, phi0=phi0, gma=g - a, gpa=g + a)
    m = Mech("parallelogram", hdr)
    m.body("ground", [("A", A), ("D", D)], fixed=True)
    m.body("crank", [("A", A), ("B", B)])
    m.body("coupler", [("B", B), ("C", C), ("P", P)])
    m.body("rocker", [("C", C), ("D", D)])
    m.joint("A", "revolute", "ground.A", "crank.A")
    m.joint("B", "revolute", "crank.B", "coupler.B")
    m.joint("C", "revolute", "coupler.C", "rocker.C")
    m.joint("D", "revolute", "ground.D", "rocker.D")
    m.inputs.append(("theta", "angle", "A"))
    m.sweep = dict(input="theta", **{"from": 0.0, "to": 360.0}, steps=361, trace=["coupler.P"])
    return m


# ----------------------------------------------------------------------------
# 6. sixbar_a : Stephenson III six-bar

SIX = dict(g=3.5, a=1.0, b=3.5, c=3.0, phi0=45.0, e_along=0.5, e_off=1.2)


def sixbar_design():
    """Grid search for the ground pivot F and the dyad lengths maximising the
    worst transmission of both circle-circle intersections over a crank turn."""
    p = SIX
    A, D = (0.0, 0.0), (p["g"], 0.0)
    N = 720
    Bs, Cs, Es = [], [], []
    B0 = polar(p["a"], p["phi0"])
    C0, _ = cc(B0, p["b"], D, p["c"], +1.0)
    for i in range(N):
        B = polar(p["a"], p["phi0"] + 360.0 * i / N)
        C, h = cc(B, p["b"], D, p["c"], +1.0)
        u = sub(C, B)
        L = norm(u)
        ex = mul(u, 1 / L)
        E = add(B, add(mul(ex, p["e_along"] * L), mul((-ex[1], ex[0]), p["e_off"])))
        Bs.append(B), Cs.append(C), Es.append(E)
    best = None
    # compact design: F within [-3, 7] x [-3, 6], link lengths 2 .. 4
    for gx in range(-12, 29):
        for gy in range(-12, 25):
            F = (gx * 0.25, gy * 0.25)
            ds = [norm(sub(E, F)) for E in Es]
            dmin, dmax = min(ds), max(ds)
            if dmin < 0.5:
                continue
            for l4i in range(8, 17):
                for l5i in range(8, 17):
                    l4, l5 = l4i * 0.25, l5i * 0.25
                    if dmax >= l4 + l5 or dmin <= abs(l4 - l5):
                        continue
                    # transmission angle at G depends only on |EF|:
                    # cos mu = (l4^2 + l5^2 - |EF|^2) / (2 l4 l5); worst at an end
                    worst = 1.0
                    for dd in (dmin, dmax):
                        cm = (l4 * l4 + l5 * l5 - dd * dd) / (2 * l4 * l5)
                        worst = min(worst, math.sqrt(max(0.0, 1 - cm * cm)))
                    if best is None or worst > best[0] + 1e-12:
                        best = (worst, F, l4, l5)
    return best


def sixbar_a():
    p = SIX
    worst, F, l4, l5 = sixbar_design()
    A, D = (0.0, 0.0), (p["g"], 0.0)
    B = polar(p["a"], p["phi0"])
    C, _ = cc(B, p["b"], D, p["c"], +1.0)
    u = sub(C, B)
    L = norm(u)
    ex = mul(u, 1 / L)
    E = add(B, add(mul(ex, p["e_along"] * L), mul((-ex[1], ex[0]), p["e_off"])))
    G, _ = cc(E, l4, F, l5, +1.0)
    # traced point on link IV: beyond G along E->G by 1.0
    w = sub(G, E)
    Pt = add(G, mul(w, 1.0 / norm(w)))
    hdr = """\
sixbar_a: Stephenson III six-bar (6 links incl. ground, 7 revolute joints), Brunkhart-style
decomposition: crank I (A->B) driven from ground joint A; links II (ternary coupler B, C, E)
and III (rocker C->D) close a Grashof crank-rocker four-bar with the ground (|AD| = %(g)g,
|AB| = %(a)g, |BC| = %(b)g, |CD| = %(c)g; s + l = 4.5 <= p + q = 6.5); then the dyad IV (E->G, %(l4)g)
and V (F->G, %(l5)g, ground pivot F = (%(fx)g, %(fy)g)) joins coupler point E to the ground.
E sits on the coupler %(ea)g of the way from B to C, offset %(eo)g to the left.  The ground
(A, D, F) and the coupler (B, C, E) are the two ternary links, not adjacent: Stephenson chain.
Designed by a grid search (tools/generate/mechanisms.py) of F, |EG|, |FG| maximising the worst
transmission of the E-G-F dyad over a full crank turn: worst |sin mu| = %(worst).3f.
Solution order: crank (input) -> RRR dyad (II, III) at C -> RRR dyad (IV, V) at G.
Drawn pose: crank at %(phi0)g deg; C and G both on the 'left' branch (cross(c2 - c1, X - c1) > 0).
Link IV carries the traced point P (1 beyond G on line E->G).
Grubler: L = 6, J = 7, D = 3*5 - 2*7 = 1.""" % dict(g=p["g"], a=p["a"], b=p["b"], c=p["c"], l4=l4, l5=l5,
                                                  fx=F[0], fy=F[1], ea=p["e_along"], eo=p["e_off"],
                                                  worst=worst, phi0=p["phi0"])
    m = Mech("sixbar_a", hdr)
    m.body("ground", [("A", A), ("D", D), ("F", F)], fixed=True)
    m.body("crank", [("A", A), ("B", B)])
    m.body("coupler", [("B", B), ("C", C), ("E", E)])
    m.body("rocker", [("C", C), ("D", D)])
    m.body("link4", [("E", E), ("G", G), ("P", Pt)])
    m.body("link5", [("G", G), ("F", F)])
    m.joint("A", "revolute", "ground.A", "crank.A")
    m.joint("B", "revolute", "crank.B", "coupler.B")
    m.joint("C", "revolute", "coupler.C", "rocker.C")
    m.joint("D", "revolute", "ground.D", "rocker.D")
    m.joint("E", "revolute", "coupler.E", "link4.E")
    m.joint("G", "revolute", "link4.G", "link5.G")
    m.joint("F", "revolute", "ground.F", "link5.F")
    m.inputs.append(("theta", "angle", "A"))
    m.sweep = dict(input="theta", **{"from": 0.0, "to": 360.0}, steps=361, trace=["link4.P"])
    return m


# ----------------------------------------------------------------------------
# 8a. Peaucellier-Lipkin

def peaucellier():
    l, s, r, phi0 = 3.0, 1.0, 1.25, 20.0
    O, O2 = (0.0, 0.0), (r, 0.0)
    Q = polar(r, phi0, O2)
    A, _ = cc(O, l, Q, s, +1.0)
    B, _ = cc(O, l, Q, s, -1.0)
    # P: the intersection of circle(A,s), circle(B,s) other than Q (the far one)
    sq = 1.0 if cross(sub(B, A), sub(Q, A)) > 0 else -1.0
    P, _ = cc(A, s, B, s, -sq)
    xline = (l * l - s * s) / (2 * r)
    # crank range: |OQ| = 2 r cos(phi/2) must exceed l - s  (and stay < sqrt(l^2 - s^2))
    phimax = 2 * math.degrees(math.acos((l - s) / (2 * r)))
    hdr = """\
peaucellier: Peaucellier-Lipkin straight-line inversor.  Fixed pivot O = (0,0); two long
arms O->A, O->B (l = %(l)g); rhombus A-Q-B-P of side s = %(s)g (links QA, QB, PA, PB).
Inversion: O, Q, P collinear with |OQ| * |OP| = l^2 - s^2 = %(k)g.
Q is driven by a crank pivoted at O2 = (%(r)g, 0) with |O2 Q| = |O2 O| = r = %(r)g, so Q moves on a
circle through O and P traces an exact straight line perpendicular to the ground line O->O2:
    x_P = (l^2 - s^2) / (2 r) = %(x)s   (relative to O, axis along O->O2),  y_P free.
Drawn pose: crank angle phi0 = %(phi0)g deg (absolute, measured at O2 from +x), A above and B
below the line O->Q, P beyond Q.  Input theta = phi - phi0.
Assembly: |OQ| = 2 r cos(phi/2) must stay in (l - s, sqrt(l^2 - s^2)) = (2, 2.828): the arm/link
dyads O-A-Q, O-B-Q become tangent at |OQ| = l - s, i.e. |phi| = 2 acos((l-s)/(2r)) = %(pm).4f deg;
|OQ| <= 2r = 2.5 < sqrt(8) keeps the rhombus from flattening (P = Q).  The singular poses
are avoided by sweeping phi over [-60, 60] deg: theta from %(f)g to %(t)g.
Solution order: crank (input) -> RRR (armA, linkQA) at A -> RRR (armB, linkQB) at B ->
RRR (linkPA, linkPB) at P.  Compound joints: O (ground-armA, ground-armB),
Q (crank-linkQA, crank-linkQB), A (armA-linkQA, armA-linkPA), B (armB-linkQB, armB-linkPB).
Grubler: L = 8, J = 10, D = 3*7 - 2*10 = 1.""" % dict(l=l, s=s, r=r, k=l * l - s * s, x=repr(xline), phi0=phi0,
                                                    pm=phimax, f=-60 - phi0, t=60 - phi0)
    m = Mech("peaucellier", hdr)
    m.body("ground", [("O", O), ("O2", O2)], fixed=True)
    m.body("crank", [("O2", O2), ("Q", Q)])
    m.body("armA", [("O", O), ("A", A)])
    m.body("armB", [("O", O), ("B", B)])
    m.body("linkQA", [("Q", Q), ("A", A)])
    m.body("linkQB", [("Q", Q), ("B", B)])
    m.body("linkPA", [("A", A), ("P", P)])
    m.body("linkPB", [("B", B), ("P", P)])
    m.joint("O2", "revolute", "ground.O2", "crank.O2")
    m.joint("OA", "revolute", "ground.O", "armA.O")
    m.joint("OB", "revolute", "ground.O", "armB.O")
    m.joint("QA", "revolute", "crank.Q", "linkQA.Q")
    m.joint("QB", "revolute", "crank.Q", "linkQB.Q")
    m.joint("A", "revolute", "armA.A", "linkQA.A")
    m.joint("A2", "revolute", "armA.A", "linkPA.A")
    m.joint("B", "revolute", "armB.B", "linkQB.B")
    m.joint("B2", "revolute", "armB.B", "linkPB.B")
    m.joint("P", "revolute", "linkPA.P", "linkPB.P")
    m.inputs.append(("theta", "angle", "O2"))
    m.sweep = dict(input="theta", **{"from": -60.0 - phi0, "to": 60.0 - phi0}, steps=121, trace=["linkPA.P"])
    return m


# ----------------------------------------------------------------------------
# 8b. trammel of Archimedes

def trammel():
    L, x0 = 2.0, 1.0
    y0 = math.sqrt(L * L - x0 * x0)
    X, Y = (x0, 0.0), (0.0, y0)
    lm, ln = 1.5, 0.25
    M = add(X, mul(sub(Y, X), lm))
    N = add(X, mul(sub(Y, X), ln))
    hdr = """\
trammel: trammel of Archimedes (elliptic trammel).  Slider sx on the ground x axis (prismatic
TX: ground.TX at (0,0) dir (1,0) first), slider sy on the ground y axis (prismatic TY:
ground.TY at (0,0) dir (0,1) first); bar X->Y of length L = %(L)g pinned to both sliders.
Driven by the slide input s on TX: x_X = %(x0)g + s.  Dyad (bar, sy) is RRP: circle(X, L) meets
the y axis at y_Y = +sqrt(L^2 - x_X^2) (branch y > 0 of the drawn pose, x0 = %(x0)g, y0 = sqrt(3)).
It is singular when the bar lies along the x track (|x_X| = L); the sweep keeps |x_X| <= 1.8 = 0.9 L
(s from -2.8 to 0.8), half-chord y_Y >= sqrt(4 - 3.24) = 0.8718.
A bar point X + lambda (Y - X) = ((1 - lambda) x_X, lambda y_Y) traces the ellipse
    x^2 / a^2 + y^2 / b^2 = 1,  a = |1 - lambda| L,  b = |lambda| L  (centre (0,0), axes along the tracks):
    bar.M (lambda = %(lm)g, beyond pin Y):  a = %(am)g, b = %(bm)g
    bar.N (lambda = %(ln)g, between pins):  a = %(an)g, b = %(bn)g
(the sweep covers the upper halves, y > 0).
Grubler: L = 4 (ground, sx, sy, bar), J = 4 (TX, TY prismatic; X, Y revolute), D = 1.""" % dict(
        L=L, x0=x0, lm=lm, ln=ln, am=abs(1 - lm) * L, bm=abs(lm) * L, an=abs(1 - ln) * L, bn=abs(ln) * L)
    m = Mech("trammel", hdr)
    m.body("ground", [("TX", (0.0, 0.0), (1.0, 0.0)), ("TY", (0.0, 0.0), (0.0, 1.0))], fixed=True)
    m.body("sx", [("TX", X), ("X", X)])
    m.body("sy", [("TY", Y), ("Y", Y)])
    m.body("bar", [("X", X), ("Y", Y), ("M", M), ("N", N)])
    m.joint("TX", "prismatic", "ground.TX", "sx.TX")
    m.joint("TY", "prismatic", "ground.TY", "sy.TY")
    m.joint("X", "revolute", "sx.X", "bar.X")
    m.joint("Y", "revolute", "bar.Y", "sy.Y")
    m.inputs.append(("s", "slide", "TX"))
    m.sweep = dict(input="s", **{"from": -2.8, "to": 0.8}, steps=181, trace=["bar.M", "bar.N"])
    return m


# ----------------------------------------------------------------------------
# 8c. pantograph

def pantograph():
    l1, l2, k = 2.0, 2.5, 2.5
    O = (0.0, 0.0)
    C0, rc = (2.0, 1.0), 0.8
    T = add(C0, (rc, 0.0))
    A, _ = cc(O, l1, T, l2, +1.0)
    u = sub(A, O)
    v = sub(T, A)
    E = add(O, mul(u, k))
    Dp = add(E, v)
    Pen = add(E, mul(v, k))
    dmin, dmax = norm(C0) - rc, norm(C0) + rc
    hdr = """\
pantograph: scaling pantograph.  Fixed pivot O = (0,0).  Bar OE (pivot O, pin A at |OA| = %(l1)g,
end E at |OE| = k |OA|), bar AT (|AT| = %(l2)g), bar TD (parallel to OA, |TD| = (k-1)|OA|), bar EP
(pin E, pin D at |ED| = |AT|, pen P at |EP| = k |AT|).  A-E-D-T is a parallelogram, so O, T, P
stay collinear and
    pen = O + k (tracer - O),   O = (0, 0),  k = %(k)g
with tracer = crank.T (= barAT.T = barTD.T) and pen = barEP.P.
The tracer T is driven around a circle by a crank pivoted at C0 = (%(c0x)g, %(c0y)g), radius %(rc)g
(full turn); the pen draws the circle of centre k*C0 = (%(pcx)g, %(pcy)g), radius k*%(rc)g = %(prc)g.
|OT| stays in [%(dmin).4f, %(dmax).4f], inside (|l1 - l2|, l1 + l2) = (0.5, 4.5): the parallelogram never
folds.  Solution order: crank (input, places T) -> RRR (barOE, barAT) at A (circle(O, %(l1)g) and
circle(T, %(l2)g)) -> RRR (barEP, barTD) at D (circle(E, %(l2)g) and circle(T, %(tdl)g)).
Compound joint T: crank-barAT and crank-barTD.
Grubler: L = 6 (ground, crank, barOE, barAT, barTD, barEP), J = 7, D = 3*5 - 2*7 = 1.""" % dict(
        l1=l1, l2=l2, k=k, c0x=C0[0], c0y=C0[1], rc=rc, pcx=k * C0[0], pcy=k * C0[1], prc=k * rc,
        dmin=dmin, dmax=dmax, tdl=(k - 1) * l1)
    m = Mech("pantograph", hdr)
    m.body("ground", [("O", O), ("C0", C0)], fixed=True)
    m.body("crank", [("C0", C0), ("T", T)])
    m.body("barOE", [("O", O), ("A", A), ("E", E)])
    m.body("barAT", [("A", A), ("T", T)])
    m.body("barTD", [("T", T), ("D", Dp)])
    m.body("barEP", [("E", E), ("D", Dp), ("P", Pen)])
    m.joint("C0", "revolute", "ground.C0", "crank.C0")
    m.joint("O", "revolute", "ground.O", "barOE.O")
    m.joint("A", "revolute", "barOE.A", "barAT.A")
    m.joint("T1", "revolute", "crank.T", "barAT.T")
    m.joint("T2", "revolute", "crank.T", "barTD.T")
    m.joint("E", "revolute", "barOE.E", "barEP.E")
    m.joint("D", "revolute", "barTD.D", "barEP.D")
    m.inputs.append(("theta", "angle", "C0"))
    m.sweep = dict(input="theta", **{"from": 0.0, "to": 360.0}, steps=361, trace=["crank.T", "barEP.P"])
    return m


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    outdir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "..", "mechanisms")
    os.makedirs(outdir, exist_ok=True)
    with open(os.path.join(outdir, "fourbar.toml"), "w") as f:
        f.write(FOURBAR)
    print("wrote fourbar.toml")
    for fn in (rocker_rocker, slider_crank, inverted_slider_crank, parallelogram, sixbar_a,
               peaucellier, trammel, pantograph):
        m = fn()
        L, J, D = m.grubler()
        assert D == 1, (m.name, L, J, D)
        with open(os.path.join(outdir, m.name + ".toml"), "w") as f:
            f.write(m.text())
        print("wrote %s.toml  (L=%d, J=%d, D=%d)" % (m.name, L, J, D))


if __name__ == "__main__":
    main()
