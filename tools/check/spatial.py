#!/usr/bin/env python3
"""Independent checker for the bundled 3D mechanisms (mechanisms/spatial/*.toml).

Stdlib only (Python >= 3.11 for tomllib); it shares no code with the Rust
crates nor with tools/generate/spatial.py.  Usage:

    python3 tools/check/spatial.py [-v] [--quick | --stride K] [files or directories ...]

(default: every *.toml in <repo>/mechanisms/spatial).  Exit status 0 iff every
file passes.

Model.  Every moving body has a pose (R, t); a marker given at world point p of
the drawn pose is at R p + t (the drawn pose is the identity).  The joints are
written as the raw primitive equations of the 3D format (first marker m1 owns
the axis / line / plane, m2 is constrained):

    coincident          p2 - p1 = 0                                   3 rows
    point-on-line       (p2 - p1).x1 = (p2 - p1).y1 = 0                 2 rows
    point-in-plane      (p2 - p1).z1 = 0                                1 row
    parallel-z          z2.x1 = z2.y1 = 0  (z2: m1's z carried by body 2)  2 rows
    perpendicular-z     z2.z1 = 0                                       1 row
    no relative rot.    ez2.ex1 = ez2.ey1 = ex2.ey1 = 0 (world axes carried) 3 rows
    helical             x2.(cos psi y1 - sin psi x1) = 0,
                        psi = 2 pi ((p2 - p1).z1 - drawn) / pitch        1 row

    revolute = coincident + parallel-z (5), prismatic = point-on-line + no rot. (5),
    cylindrical = point-on-line + parallel-z (4), spherical = coincident (3),
    universal = coincident + perpendicular-z (4), planar = point-in-plane +
    parallel-z (3), fixed = coincident + no rot. (6), helical = point-on-line +
    parallel-z + helical (5).

Inputs add one row each: angle = x2.(cos th y1 - sin th x1) = 0 (body 2 turned
by th relative to body 1, right-handed about z1; x1 any vector normal to z1
carried by both bodies), slide = (p2 - p1).z1 - drawn - s = 0.

Unknowns: a body's pose is (R, c), c the world position of the centroid of its
markers, so a marker is at R (p - centroid) + c; a step rotates each body about
its own centroid (q -> exp(omega) (q - c) + c + dc), which keeps the columns of
far-away bodies well conditioned.  Direction rows are multiplied by a
characteristic length l (the mean distance of the markers from their body's
centroid, over the moving bodies) and the rotation unknowns are scaled by l
(u = omega l), so every row is a length and the Jacobian is dimensionally
uniform.  L = diagonal of the bounding box of all markers (the mechanism size);
residuals are reported as position rows / L and direction rows in radians.

Per file:
 (a) every marker is well formed (z, x non-zero, x normal to z), the axes each
     joint needs are there (the second z parallel to the first, the universal
     crosspins perpendicular), and every joint row holds at the drawn pose to
     1e-9 L;
 (b) counts: n moving bodies, joints, sum of joint equations, Grubler 6n - sum,
     the rank r of the joint Jacobian at the drawn pose (sparse Gaussian
     elimination with FULL pivoting, pivots below 1e-9 of the largest entry
     count as zero; the gap between the smallest kept and the largest rejected
     pivot is printed with -v), mobility 6n - r, redundant = sum - r, and the
     idle freedoms 6n - rank(joint rows + input rows).  They must equal the
     "Expected counts" line of the file's header;
 (c) every sweep frame is solved by damped Gauss-Newton (Levenberg-Marquardt
     on the normal equations, sparse Gaussian elimination with partial
     pivoting, bodies ordered by reverse Cuthill-McKee), warm-started from the
     previous frame with a linear predictor, iterated to 1e-14; a frame is ok
     when every row is below 1e-10 (positions / L, directions in radians).
     The max residual of the joint rows is reported the same way.  Every frame
     is solved by default (about a minute for all files); --quick solves only
     every 10th frame (and the last) of spatial_stress_N for N >= 50, --stride K
     every Kth frame of every file (the table marks subsampled files with *);
 (d) closed forms, computed here from the file's own markers: Cardan
     tan th2 = tan th1 / cos beta; double Cardan output = input; tilted four-bar
     = planar four-bar of mechanisms/fourbar.toml (circle intersection) mapped
     through the header's o, e1, e2; RSSR / spherical four-bar / stress
     chains: each loop's rocker angle from the one-angle equation
     |C(phi) - B| = |BC| (a cos phi + b sin phi = c), branch by continuity from
     the drawn pose; Bennett: the DH chain (link lengths and twists read from
     the markers) with th2 from tan(th1/2) tan(th2/2) = sin((b+a)/2) /
     sin((b-a)/2), th3 = -th1, th4 = -th2, and that relation on the DH angles
     measured from the solved poses; excavator: boom and stick angles from
     the cylinder triangles (law of cosines), tip by composing rotations; sofa
     bed: planar four-bar + RRR dyad of the left side by circle intersection,
     right side = left side shifted by W; Stewart: last frame = the header's
     prescribed end pose.  The error is the largest position error relative
     to L (angles for Bennett's relation).
"""
import math
import os
import re
import sys
import time
import tomllib

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DRAWN_TOL = 1e-9     # joints as drawn, relative to L
RANK_TOL = 1e-9      # pivot threshold, relative to the largest Jacobian entry
SOLVE_TOL = 1e-10    # a frame converged: every row below SOLVE_TOL * L
FINE_TOL = 1e-14     # iterate until every row is below FINE_TOL * L (or no progress)
CLOSED_TOL = 1e-9    # closed-form agreement, relative to L
AXIS_KINDS = ("revolute", "prismatic", "cylindrical", "planar", "helical")
JOINT_EQS = {"revolute": 5, "prismatic": 5, "cylindrical": 4, "spherical": 3,
             "universal": 4, "planar": 3, "fixed": 6, "helical": 5}
INPUT_KINDS = {"angle": ("revolute", "cylindrical"),
               "slide": ("prismatic", "cylindrical", "helical")}


class Fail(Exception):
    pass


# ---------------------------------------------------------------------------
# small vector / rotation algebra (tuples)

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


def mv(R, p):
    return (R[0] * p[0] + R[1] * p[1] + R[2] * p[2],
            R[3] * p[0] + R[4] * p[1] + R[5] * p[2],
            R[6] * p[0] + R[7] * p[1] + R[8] * p[2])


def mtv(R, p):
    return (R[0] * p[0] + R[3] * p[1] + R[6] * p[2],
            R[1] * p[0] + R[4] * p[1] + R[7] * p[2],
            R[2] * p[0] + R[5] * p[1] + R[8] * p[2])


def mm(A, B):
    return tuple(sum(A[3 * i + k] * B[3 * k + j] for k in range(3))
                 for i in range(3) for j in range(3))


def mt(A):
    return (A[0], A[3], A[6], A[1], A[4], A[7], A[2], A[5], A[8])


IDENT = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)


def rodrigues(w):
    """Rotation matrix of the rotation vector w."""
    th = norm(w)
    if th < 1e-300:
        return IDENT
    k = mul(w, 1.0 / th)
    c, s = math.cos(th), math.sin(th)
    v = 1.0 - c
    x, y, z = k
    return (c + x * x * v, x * y * v - z * s, x * z * v + y * s,
            y * x * v + z * s, c + y * y * v, y * z * v - x * s,
            z * x * v - y * s, z * y * v + x * s, c + z * z * v)


def rot_axis(a, ang):
    return rodrigues(mul(unit(a), ang))


def perp(z):
    """A unit vector normal to z: the world axis least aligned with z, made normal."""
    z = unit(z)
    best = min(range(3), key=lambda i: (abs(z[i]), i))
    e = [0.0, 0.0, 0.0]
    e[best] = 1.0
    e = tuple(e)
    return unit(sub(e, mul(z, dot(e, z))))


def rot_angle_about(R, a):
    """Angle of rotation R about the unit axis a (R assumed to fix a)."""
    v = perp(a)
    w = mv(R, v)
    return math.atan2(dot(a, cross(v, w)), dot(v, w))


def wrap(x):
    return (x + math.pi) % (2.0 * math.pi) - math.pi


# ---------------------------------------------------------------------------
# model

class Marker:
    def __init__(self, body, name, at, z=None, x=None):
        self.body, self.name, self.p, self.z, self.x = body, name, at, z, x


class Joint:
    def __init__(self, name, kind, m1, m2, pitch=None):
        self.name, self.kind, self.m1, self.m2, self.pitch = name, kind, m1, m2, pitch


def vec3(v, what):
    if not isinstance(v, list) or len(v) != 3 or not all(
            isinstance(c, (int, float)) and not isinstance(c, bool) for c in v):
        raise Fail("%s must be 3 numbers" % what)
    return (float(v[0]), float(v[1]), float(v[2]))


class Mech:
    def __init__(self, path):
        self.path = path
        self.stem = os.path.splitext(os.path.basename(path))[0]
        with open(path, "rb") as f:
            self.doc = tomllib.load(f)
        with open(path) as f:
            self.text = f.read()
        self.header = [ln for ln in self.text.splitlines() if ln.startswith("#")]
        self.parse()

    def parse(self):
        d = self.doc
        self.name = d.get("name")
        if self.name != self.stem:
            raise Fail("name %r is not the file stem %r" % (self.name, self.stem))
        if d.get("dimension") != 3:
            raise Fail("dimension must be 3")
        self.fixed = []
        self.moving = []
        self.markers = {}
        for bname, b in d["bodies"].items():
            (self.fixed if b.get("fixed", False) else self.moving).append(bname)
            for mname, m in b.get("markers", {}).items():
                what = "bodies.%s.markers.%s" % (bname, mname)
                if isinstance(m, list):
                    mk = Marker(bname, mname, vec3(m, what))
                else:
                    z = vec3(m["z"], what + ".z") if "z" in m else None
                    x = vec3(m["x"], what + ".x") if "x" in m else None
                    if z is not None and norm(z) == 0:
                        raise Fail(what + ".z is zero")
                    if x is not None:
                        if z is None:
                            raise Fail(what + " has x without z")
                        if norm(x) == 0 or abs(dot(unit(x), unit(z))) > 1e-9:
                            raise Fail(what + ".x is not normal to z")
                    mk = Marker(bname, mname, vec3(m["at"], what + ".at"), z, x)
                self.markers[bname + "." + mname] = mk
        if not self.fixed:
            raise Fail("no fixed body")
        self.index = {b: i for i, b in enumerate(self.moving)}
        pts = [m.p for m in self.markers.values()]
        lo = [min(p[k] for p in pts) for k in range(3)]
        hi = [max(p[k] for p in pts) for k in range(3)]
        self.size = math.sqrt(sum((hi[k] - lo[k]) ** 2 for k in range(3)))
        self.centroid = {}
        spread = []
        for b in self.moving:
            ps = [m.p for m in self.markers.values() if m.body == b]
            if not ps:
                raise Fail("body %s has no markers" % b)
            cb = mul(tuple(sum(p[k] for p in ps) for k in range(3)), 1.0 / len(ps))
            self.centroid[b] = cb
            spread += [norm(sub(p, cb)) for p in ps]
        self.ell = max(sum(spread) / len(spread), 1e-3 * self.size)
        self.joints = []
        for jname, j in d["joints"].items():
            kind = j["kind"]
            if kind not in JOINT_EQS:
                raise Fail("joint %s: unknown kind %r" % (jname, kind))
            ms = j["markers"]
            if len(ms) != 2 or any(m not in self.markers for m in ms):
                raise Fail("joint %s: bad markers %r" % (jname, ms))
            m1, m2 = self.markers[ms[0]], self.markers[ms[1]]
            if m1.body == m2.body:
                raise Fail("joint %s joins a body to itself" % jname)
            if kind in AXIS_KINDS:
                if m1.z is None:
                    raise Fail("joint %s (%s): first marker has no z" % (jname, kind))
                if m2.z is not None and norm(cross(unit(m1.z), unit(m2.z))) > 1e-9:
                    raise Fail("joint %s: the second z is not parallel to the first" % jname)
            if kind == "universal" and (m1.z is None or m2.z is None):
                raise Fail("joint %s: universal needs z on both markers" % jname)
            pitch = j.get("pitch")
            if kind == "helical" and not pitch:
                raise Fail("joint %s: helical needs pitch" % jname)
            self.joints.append(Joint(jname, kind, m1, m2, pitch))
        self.jmap = {j.name: j for j in self.joints}
        # modelling rule of the bundled files: different joints sit at distinct points
        seen = {}
        for j in self.joints:
            key = tuple(round(c / self.size, 9) for c in j.m1.p)
            if key in seen:
                raise Fail("joints %s and %s are at the same point" % (seen[key], j.name))
            seen[key] = j.name
        self.inputs = {}
        for iname, inp in d.get("inputs", {}).items():
            j = self.jmap.get(inp["joint"])
            if j is None or j.kind not in INPUT_KINDS.get(inp["kind"], ()):
                raise Fail("input %s: kind %s does not fit joint %s" % (iname, inp["kind"], inp["joint"]))
            self.inputs[iname] = (inp["kind"], j)
        sw = d["sweep"]
        steps = sw["steps"]
        if "inputs" in sw:
            if "input" in sw:
                raise Fail("sweep has both input and inputs")
            ranges = {k: (float(v[0]), float(v[1])) for k, v in sw["inputs"].items()}
        else:
            ranges = {sw["input"]: (float(sw["from"]), float(sw["to"]))}
        for k in ranges:
            if k not in self.inputs:
                raise Fail("sweep names unknown input %s" % k)
        self.frames = []
        for s in range(steps):
            f = s / (steps - 1) if steps > 1 else 0.0
            self.frames.append({k: (ranges[k][0] + (ranges[k][1] - ranges[k][0]) * f
                                    if k in ranges else 0.0) for k in self.inputs})
        self.trace = sw.get("trace", [])
        for t in self.trace:
            if t not in self.markers:
                raise Fail("trace names unknown marker %s" % t)
        self.build_rows()

    # -- rows -------------------------------------------------------------
    def bidx(self, body):
        return self.index.get(body, -1)

    def loc(self, m):
        """A marker's point relative to its body's centroid (world point for fixed bodies)."""
        return sub(m.p, self.centroid[m.body]) if m.body in self.index else m.p

    def drawn(self):
        return [(IDENT, self.centroid[b]) for b in self.moving]

    def relres(self, rows, vals):
        """Residual, dimensionless: position rows / L, direction rows (scaled by l) / l."""
        return max((abs(v) / (self.size if r[0] == "P" else self.ell) for r, v in zip(rows, vals)), default=0.0)

    def frame_of(self, m):
        z = unit(m.z)
        x = unit(m.x) if m.x is not None else perp(z)
        return z, x, cross(z, x)

    def build_rows(self):
        rows = []
        for j in self.joints:
            m1, m2 = j.m1, j.m2
            b1, b2 = self.bidx(m1.body), self.bidx(m2.body)
            tag = j.name

            def P(v, bv, const=0.0, t=tag):
                rows.append(("P", b2, self.loc(m2), b1, self.loc(m1), bv, v, const, t))

            def D(a, ba, b, bb, t=tag):
                rows.append(("D", ba, a, bb, b, t))
            k = j.kind
            if k in ("revolute", "spherical", "universal", "fixed"):      # coincident
                for e in ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)):
                    P(e, -2)
            if k in ("prismatic", "cylindrical", "helical", "planar"):
                z1, x1, y1 = self.frame_of(m1)
                if k == "planar":
                    P(z1, b1)
                else:
                    P(x1, b1)
                    P(y1, b1)
            if k in ("revolute", "cylindrical", "planar", "helical"):    # parallel-z
                z1, x1, y1 = self.frame_of(m1)
                D(z1, b2, x1, b1)
                D(z1, b2, y1, b1)
            if k in ("prismatic", "fixed"):                               # no rotation
                ex, ey, ez = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
                D(ez, b2, ex, b1)
                D(ez, b2, ey, b1)
                D(ex, b2, ey, b1)
            if k == "universal":
                D(unit(m2.z), b2, unit(m1.z), b1)
            if k == "helical":
                z1, x1, y1 = self.frame_of(m1)
                d0 = dot(sub(m2.p, m1.p), z1)
                rows.append(("H", b2, self.loc(m2), b1, self.loc(m1), z1, x1, y1, d0, j.pitch, tag))
            if sum(1 for r in rows if r[-1] == tag) != JOINT_EQS[k]:
                raise Fail("internal: row count of %s" % tag)
        self.rows = rows

    def input_rows(self, values):
        rows = []
        for iname, (kind, j) in self.inputs.items():
            m1, m2 = j.m1, j.m2
            b1, b2 = self.bidx(m1.body), self.bidx(m2.body)
            z1, x1, y1 = self.frame_of(m1)
            v = values[iname]
            if kind == "angle":
                th = math.radians(v)
                b = add(mul(y1, math.cos(th)), mul(x1, -math.sin(th)))
                rows.append(("D", b2, x1, b1, b, "input " + iname))
            else:
                d0 = dot(sub(m2.p, m1.p), z1)
                rows.append(("P", b2, self.loc(m2), b1, self.loc(m1), b1, z1, d0 + v, "input " + iname))
        return rows


# ---------------------------------------------------------------------------
# evaluation: values and sparse gradients of the rows

def evaluate(rows, poses, L, grad):
    """rows -> values (lengths; direction rows times L) and, if grad, one dict
    {column: d/d(c, omega L)} per row (L: the characteristic length l)."""
    vals = []
    jac = [] if grad else None
    invL = 1.0 / L
    for r in rows:
        typ = r[0]
        if typ == "P":
            _, b2, p2, b1, p1, bv, v, const, _t = r
            if b2 >= 0:
                R2, t2 = poses[b2]
                r2 = mv(R2, p2)
                q2 = add(r2, t2)
            else:
                r2 = q2 = p2
            if b1 >= 0:
                R1, t1 = poses[b1]
                r1 = mv(R1, p1)
                q1 = add(r1, t1)
            else:
                r1 = q1 = p1
            if bv >= 0:
                vw = mv(poses[bv][0], v)
            else:
                vw = v
            dq = sub(q2, q1)
            vals.append(dot(dq, vw) - const)
            if grad:
                g = {}
                if b2 >= 0:
                    w = cross(r2, vw)
                    _acc(g, 6 * b2, vw, mul(w, invL))
                if b1 >= 0:
                    w = cross(r1, vw)
                    _acc(g, 6 * b1, mul(vw, -1.0), mul(w, -invL))
                if bv >= 0:
                    w = cross(vw, dq)
                    _acc(g, 6 * bv, None, mul(w, invL))
                jac.append(g)
        elif typ == "D":
            _, ba, a, bb, b, _t = r
            aw = mv(poses[ba][0], a) if ba >= 0 else a
            bw = mv(poses[bb][0], b) if bb >= 0 else b
            vals.append(L * dot(aw, bw))
            if grad:
                g = {}
                if ba >= 0:
                    _acc(g, 6 * ba, None, cross(aw, bw))
                if bb >= 0:
                    _acc(g, 6 * bb, None, cross(bw, aw))
                jac.append(g)
        else:  # helical
            _, b2, p2, b1, p1, z1, x1, y1, d0, pitch, _t = r
            R1, t1 = poses[b1] if b1 >= 0 else (IDENT, (0.0, 0.0, 0.0))
            R2, t2 = poses[b2] if b2 >= 0 else (IDENT, (0.0, 0.0, 0.0))     # ground: world points
            r2, r1 = mv(R2, p2), mv(R1, p1)
            dq = sub(add(r2, t2), add(r1, t1))
            zw, xw, yw = mv(R1, z1), mv(R1, x1), mv(R1, y1)
            x2 = mv(R2, x1)
            k = 2.0 * math.pi / pitch
            psi = k * (dot(dq, zw) - d0)
            c, s = math.cos(psi), math.sin(psi)
            bw = add(mul(yw, c), mul(xw, -s))
            vals.append(L * dot(x2, bw))
            if grad:
                g = {}
                dpsi = L * dot(x2, add(mul(yw, -s), mul(xw, -c))) * k   # d f / d (axial)
                if b2 >= 0:
                    _acc(g, 6 * b2, mul(zw, dpsi), add(cross(x2, bw), mul(cross(r2, zw), dpsi * invL)))
                if b1 >= 0:
                    _acc(g, 6 * b1, mul(zw, -dpsi),
                         add(cross(bw, x2), mul(add(cross(r1, zw), mul(cross(zw, dq), -1.0)), -dpsi * invL)))
                jac.append(g)
    return vals, jac


def _acc(g, c0, dt, dw):
    if dt is not None:
        for k in range(3):
            g[c0 + k] = g.get(c0 + k, 0.0) + dt[k]
    for k in range(3):
        g[c0 + 3 + k] = g.get(c0 + 3 + k, 0.0) + dw[k]


# ---------------------------------------------------------------------------
# sparse linear algebra

def sparse_rank(rows, rel=RANK_TOL):
    """Rank of a sparse matrix (list of {col: val}) by Gaussian elimination with
    full pivoting.  Returns (rank, smallest kept pivot, largest rejected), both
    relative to the largest entry."""
    rows = [dict(r) for r in rows]
    big = max((abs(v) for r in rows for v in r.values()), default=0.0)
    if big == 0.0:
        return 0, 0.0, 0.0
    colrows = {}
    for i, r in enumerate(rows):
        for c in r:
            colrows.setdefault(c, set()).add(i)
    alive = set(range(len(rows)))
    rmax = [max((abs(v) for v in r.values()), default=0.0) for r in rows]
    rank, kept = 0, float("inf")
    while alive:
        i = max(alive, key=lambda k: (rmax[k], -k))
        if rmax[i] <= rel * big:
            break
        r = rows[i]
        c, pv = max(r.items(), key=lambda kv: (abs(kv[1]), -kv[0]))
        kept = min(kept, abs(pv))
        alive.discard(i)
        rank += 1
        for j in colrows.get(c, ()):
            if j not in alive:
                continue
            rj = rows[j]
            a = rj.get(c)
            if a is None:
                continue
            f = a / pv
            for cc, vv in r.items():
                if cc == c:
                    continue
                nv = rj.get(cc, 0.0) - f * vv
                rj[cc] = nv
                colrows.setdefault(cc, set()).add(j)
            del rj[c]
            rmax[j] = max((abs(v) for v in rj.values()), default=0.0)
    rej = max((rmax[k] for k in alive), default=0.0)
    return rank, kept / big, rej / big


def sparse_solve(A, rhs, n):
    """Solve A x = rhs, A a list of n row dicts, by Gaussian elimination with
    partial pivoting (column by column; the candidate rows are the remaining
    rows holding that column).  A and rhs are consumed."""
    colrows = [set() for _ in range(n)]
    for i, r in enumerate(A):
        for c in r:
            colrows[c].add(i)
    used = [False] * n
    piv = [0] * n
    for k in range(n):
        best, bi = -1.0, -1
        for i in colrows[k]:
            if not used[i]:
                v = A[i].get(k)
                if v is not None and abs(v) > best:
                    best, bi = abs(v), i
        if bi < 0 or best == 0.0:
            raise Fail("singular system in the solver")
        used[bi] = True
        piv[k] = bi
        pr = A[bi]
        pv = pr[k]
        items = [(c, v) for c, v in pr.items() if c != k]
        for i in colrows[k]:
            if used[i]:
                continue
            ri = A[i]
            a = ri.pop(k, None)
            if a is None:
                continue
            f = a / pv
            for c, v in items:
                ri[c] = ri.get(c, 0.0) - f * v
                colrows[c].add(i)
            rhs[i] -= f * rhs[bi]
    x = [0.0] * n
    for k in range(n - 1, -1, -1):
        pr = A[piv[k]]
        s = rhs[piv[k]]
        for c, v in pr.items():
            if c != k:
                s -= v * x[c]
        x[k] = s / pr[k]
    return x


def rcm_order(mech):
    """Reverse Cuthill-McKee order of the moving bodies (graph of joints
    between moving bodies), ties broken by file order."""
    n = len(mech.moving)
    adj = [set() for _ in range(n)]
    for j in mech.joints:
        a, b = mech.bidx(j.m1.body), mech.bidx(j.m2.body)
        if a >= 0 and b >= 0:
            adj[a].add(b)
            adj[b].add(a)
    seen = [False] * n
    order = []
    while len(order) < n:
        start = min((i for i in range(n) if not seen[i]), key=lambda i: (len(adj[i]), i))
        # walk to a pseudo-peripheral node
        for _ in range(3):
            lv = {start: 0}
            q = [start]
            for u in q:
                for w in sorted(adj[u]):
                    if w not in lv and not seen[w]:
                        lv[w] = lv[u] + 1
                        q.append(w)
            far = max(lv.values())
            cand = min((i for i in lv if lv[i] == far), key=lambda i: (len(adj[i]), i))
            if cand == start:
                break
            start = cand
        seen[start] = True
        q = [start]
        for u in q:
            for w in sorted(adj[u], key=lambda i: (len(adj[i]), i)):
                if not seen[w]:
                    seen[w] = True
                    q.append(w)
        order.extend(q)
    order.reverse()
    return order


# ---------------------------------------------------------------------------
# solving a frame

class Solver:
    def __init__(self, mech):
        self.mech = mech
        self.n = len(mech.moving)
        order = rcm_order(mech)
        # column permutation: body order[k] -> block k
        self.perm = [0] * (6 * self.n)
        for k, b in enumerate(order):
            for i in range(6):
                self.perm[6 * b + i] = 6 * k + i
        self.iters = 0

    def apply(self, poses, delta):
        L = self.mech.ell
        out = []
        for b, (R, t) in enumerate(poses):
            c = [self.perm[6 * b + i] for i in range(6)]
            dt = (delta[c[0]], delta[c[1]], delta[c[2]])
            w = (delta[c[3]] / L, delta[c[4]] / L, delta[c[5]] / L)
            out.append((orthonormal(mm(rodrigues(w), R)), add(t, dt)))
        return out

    def solve(self, poses, values, maxit=60):
        mech, L, n = self.mech, self.mech.ell, 6 * self.n
        rows = mech.rows + mech.input_rows(values)
        perm = self.perm
        f, J = evaluate(rows, poses, L, True)
        cost = sum(v * v for v in f)
        lam = 1e-9
        for it in range(maxit):
            if mech.relres(rows, f) <= FINE_TOL:
                return poses, True, it
            N = [dict() for _ in range(n)]
            g = [0.0] * n
            for fi, gi in zip(f, J):
                items = [(perm[c], v) for c, v in gi.items()]
                for ci, vi in items:
                    Ni = N[ci]
                    g[ci] += vi * fi
                    for cj, vj in items:
                        Ni[cj] = Ni.get(cj, 0.0) + vi * vj
            dmax = max(max(N[i].get(i, 0.0) for i in range(n)), 1e-300)
            while True:
                A = [dict(r) for r in N]
                for i in range(n):
                    A[i][i] = A[i].get(i, 0.0) + lam * dmax
                delta = sparse_solve(A, [-v for v in g], n)
                self.iters += 1
                cand = self.apply(poses, delta)
                f2, _ = evaluate(rows, cand, L, False)
                cost2 = sum(v * v for v in f2)
                if cost2 < cost or cost2 == 0.0:
                    poses = cand
                    f, J = evaluate(rows, poses, L, True)
                    cost = cost2
                    lam = max(lam * 0.1, 1e-12)
                    break
                lam *= 10.0
                if lam > 1e6 or (lam > 1e-3 and mech.relres(rows, f) <= SOLVE_TOL):
                    return poses, mech.relres(rows, f) <= SOLVE_TOL, it
        return poses, mech.relres(rows, f) <= SOLVE_TOL, maxit


def orthonormal(R):
    """The rotation nearest R by Gram-Schmidt on its rows (keeps roundoff from growing)."""
    r0 = unit(R[0:3])
    r1 = R[3:6]
    r1 = unit(sub(r1, mul(r0, dot(r0, r1))))
    r2 = cross(r0, r1)
    return r0 + r1 + r2


def predict(p_prev, p_cur):
    """Linear predictor: repeat the last step's motion of every body."""
    out = []
    for (R0, t0), (R1, t1) in zip(p_prev, p_cur):
        D = mm(R1, mt(R0))
        out.append((orthonormal(mm(D, R1)), sub(mul(t1, 2.0), t0)))
    return out


def world(mech, poses, key):
    m = mech.markers[key]
    b = mech.bidx(m.body)
    if b < 0:
        return m.p
    R, c = poses[b]
    return add(mv(R, sub(m.p, mech.centroid[m.body])), c)


def world_dir(mech, poses, key):
    m = mech.markers[key]
    b = mech.bidx(m.body)
    z = unit(m.z)
    return z if b < 0 else mv(poses[b][0], z)


def body_rot(mech, poses, body):
    b = mech.bidx(body)
    return IDENT if b < 0 else poses[b][0]


# ---------------------------------------------------------------------------
# closed forms

def header_vec(mech, key):
    pat = re.compile(r"\b%s\s*=\s*\[([^\]]*)\]" % re.escape(key))
    for ln in mech.header:
        m = pat.search(ln)
        if m:
            return tuple(float(s) for s in m.group(1).split(","))
    raise Fail("header has no %s = [...]" % key)


def header_num(mech, key):
    pat = re.compile(r"\b%s\s*=\s*([-+0-9.eE]+)" % re.escape(key))
    for ln in mech.header:
        m = pat.search(ln)
        if m:
            return float(m.group(1))
    raise Fail("header has no %s = number" % key)


def other_body(j, body):
    return j.m2.body if j.m1.body == body else j.m1.body


def marker_of(j, body):
    return j.m1 if j.m1.body == body else j.m2


def cf_cardan(mech, sol):
    """tan th2 = tan th1 / cos beta, th1 = input, th2 = output shaft angle."""
    (iname, (_, jin)), = mech.inputs.items()
    ground = mech.fixed[0]
    jout = [j for j in mech.joints if j.kind == "revolute" and j is not jin
            and ground in (j.m1.body, j.m2.body)][0]
    a1 = unit(jin.m1.z)
    a2 = unit(marker_of(jout, ground).z)
    shaft2 = other_body(jout, ground)
    cb = dot(a1, a2)
    if cb <= 0:
        a2 = mul(a2, -1.0)
        cb = -cb
    # convention: the input yoke lies in the plane of the shafts as drawn
    ju = [j for j in mech.joints if j.kind == "universal"][0]
    yoke1 = unit(marker_of(ju, jin.m2.body).z)
    if abs(dot(yoke1, unit(cross(a1, a2)))) > 1e-9:
        raise Fail("cardan: the input yoke is not in the plane of the shafts")
    err = 0.0
    for vals, poses in sol:
        th1 = math.radians(vals[iname])
        th2 = math.atan2(math.sin(th1), math.cos(th1) * cb)
        meas = rot_angle_about(body_rot(mech, poses, shaft2), a2)
        err = max(err, abs(wrap(meas - th2)))
    return err, "angle error %.2e rad (beta = %.4f deg)" % (err, math.degrees(math.acos(cb)))


def cf_double_cardan(mech, sol):
    (iname, (_, jin)), = mech.inputs.items()
    ground = mech.fixed[0]
    jout = [j for j in mech.joints if j.kind == "revolute" and j is not jin
            and ground in (j.m1.body, j.m2.body)][0]
    a1 = unit(jin.m1.z)
    a2 = unit(marker_of(jout, ground).z)
    if norm(cross(a1, a2)) > 1e-12 or dot(a1, a2) < 0:
        raise Fail("double_cardan: output axis not parallel to the input axis")
    out = other_body(jout, ground)
    err = 0.0
    for vals, poses in sol:
        meas = rot_angle_about(body_rot(mech, poses, out), a2)
        err = max(err, abs(wrap(meas - math.radians(vals[iname]))))
    return err, "output - input angle %.2e rad" % err


def cf_tilted_fourbar(mech, sol):
    o, e1, e2 = header_vec(mech, "o"), header_vec(mech, "e1"), header_vec(mech, "e2")
    if abs(norm(e1) - 1) > 1e-12 or abs(norm(e2) - 1) > 1e-12 or abs(dot(e1, e2)) > 1e-12:
        raise Fail("tilted_fourbar: e1, e2 not orthonormal")
    n = cross(e1, e2)
    with open(os.path.join(REPO, "mechanisms", "fourbar.toml"), "rb") as f:
        planar = tomllib.load(f)

    def X(u):
        return add(o, add(mul(e1, u[0]), mul(e2, u[1])))
    pm = {}
    for bname, b in planar["bodies"].items():
        for mname, uv in b["markers"].items():
            pm[bname + "." + mname] = (float(uv[0]), float(uv[1]))
            key = bname + "." + mname
            if key not in mech.markers or norm(sub(mech.markers[key].p, X(uv))) > 1e-12 * mech.size:
                raise Fail("tilted_fourbar: marker %s is not fourbar.toml's mapped through o, e1, e2" % key)
    for j in mech.joints:
        if j.kind != "revolute" or norm(cross(unit(j.m1.z), n)) > 1e-12:
            raise Fail("tilted_fourbar: joint %s axis is not the plane normal" % j.name)
    A, B0, C0, D, P0 = pm["ground.A"], pm["crank.B"], pm["coupler.C"], pm["ground.D"], pm["coupler.P"]

    def d2(a, b):
        return math.hypot(a[0] - b[0], a[1] - b[1])

    def crs(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
    rBC, rDC = d2(B0, C0), d2(D, C0)
    side = math.copysign(1.0, crs(B0, D, C0))
    th0 = math.atan2(B0[1] - A[1], B0[0] - A[0])
    rAB = d2(A, B0)
    err = 0.0
    (iname, _), = mech.inputs.items()
    for vals, poses in sol:
        th = th0 + math.radians(vals[iname])
        B = (A[0] + rAB * math.cos(th), A[1] + rAB * math.sin(th))
        d = d2(B, D)
        a = (d * d + rBC * rBC - rDC * rDC) / (2 * d)
        h = math.sqrt(max(rBC * rBC - a * a, 0.0))
        ex = ((D[0] - B[0]) / d, (D[1] - B[1]) / d)
        nx = (-ex[1], ex[0])
        C = (B[0] + a * ex[0] + side * h * nx[0], B[1] + a * ex[1] + side * h * nx[1])
        # coupler point P from the rigid coupler frame (B, C)
        u0 = ((C0[0] - B0[0]) / rBC, (C0[1] - B0[1]) / rBC)
        v0 = (-u0[1], u0[0])
        lp = ((P0[0] - B0[0]) * u0[0] + (P0[1] - B0[1]) * u0[1],
              (P0[0] - B0[0]) * v0[0] + (P0[1] - B0[1]) * v0[1])
        u = ((C[0] - B[0]) / rBC, (C[1] - B[1]) / rBC)
        v = (-u[1], u[0])
        P = (B[0] + lp[0] * u[0] + lp[1] * v[0], B[1] + lp[0] * u[1] + lp[1] * v[1])
        for key, q in (("crank.B", B), ("coupler.C", C), ("coupler.P", P), ("rocker.C", C)):
            err = max(err, norm(sub(world(mech, poses, key), X(q))) / mech.size)
    return err, "position error %.2e L" % err


def rocker_angle(Bw, Cd, Dp, a, rBC, prev):
    """Angle phi (about the unit axis a through Dp) of the rocker point whose
    drawn position is Cd, such that |C(phi) - Bw| = rBC; the root closest to
    prev.  Returns (phi, margin |c| / sqrt(a^2 + b^2))."""
    cpar = dot(sub(Cd, Dp), a)
    foot = add(Dp, mul(a, cpar))
    rv = sub(Cd, foot)
    r = norm(rv)
    u = mul(rv, 1.0 / r)
    w = cross(a, u)
    E = sub(foot, Bw)
    A_, B_ = dot(E, u), dot(E, w)
    c = (rBC * rBC - dot(E, E) - r * r) / (2.0 * r)
    rho = math.hypot(A_, B_)
    m = c / rho
    if abs(m) > 1.0:
        raise Fail("closed form: rocker does not assemble (|c|/rho = %.4f)" % m)
    base, dlt = math.atan2(B_, A_), math.acos(m)
    roots = [base + dlt, base - dlt]
    best = min(roots, key=lambda x: abs(wrap(x - prev)))
    return prev + wrap(best - prev), abs(m)


def fourbar_loops(mech, sol, loops):
    """loops: list of (crank_body, crank_joint, jB, jC, rocker_body, rocker_joint);
    the first crank is driven by the (only) input; later cranks are earlier rockers."""
    (iname, _), = mech.inputs.items()
    ground = mech.fixed[0]
    err, worst_m = 0.0, 0.0
    phis = [0.0] * len(loops)
    for vals, poses in sol:
        ang = {}
        for k, (crank, jcr, jB, jC, rocker, jro) in enumerate(loops):
            a_cr = unit(marker_of(jcr, ground).z)
            if k == 0:
                th = math.radians(vals[iname])
                if jcr.m1.body != ground:
                    th = -th
            else:
                th = ang[crank]
            Bd = marker_of(jB, crank).p
            Pc = marker_of(jcr, ground).p
            Bw = add(Pc, mv(rot_axis(a_cr, th), sub(Bd, Pc)))
            cpl = other_body(jB, crank)
            Cd = marker_of(jC, cpl).p
            rBC = norm(sub(Cd, Bd))
            a_ro = unit(marker_of(jro, ground).z)
            Dp = marker_of(jro, ground).p
            phi, m = rocker_angle(Bw, Cd, Dp, a_ro, rBC, phis[k])
            phis[k] = phi
            ang[rocker] = phi
            worst_m = max(worst_m, m)
            Cw = add(Dp, mv(rot_axis(a_ro, phi), sub(Cd, Dp)))
            err = max(err, norm(sub(world(mech, poses, rocker + "." + marker_of(jC, rocker).name), Cw)) / mech.size,
                      norm(sub(world(mech, poses, crank + "." + marker_of(jB, crank).name), Bw)) / mech.size)
    return err, worst_m


def loops_by_names(mech, spec):
    out = []
    for crank, jcr, jB, jC, rocker, jro in spec:
        out.append((crank, mech.jmap[jcr], mech.jmap[jB], mech.jmap[jC], rocker, mech.jmap[jro]))
    return out


def cf_fourbar(mech, sol):
    loops = loops_by_names(mech, [("crank", "A", "B", "C", "rocker", "D")])
    err, m = fourbar_loops(mech, sol, loops)
    return err, "position error %.2e L (one-angle equation, max |c|/rho %.3f)" % (err, m)


def cf_stress(mech, sol):
    nloops = sum(1 for b in mech.moving if b.startswith("coupler_"))
    spec = []
    for i in range(1, nloops + 1):
        crank = "crank" if i == 1 else "rocker_%d" % (i - 1)
        spec.append((crank, "O0" if i == 1 else "G%d" % (i - 1), "B%d" % i, "C%d" % i,
                     "rocker_%d" % i, "G%d" % i))
    err, m = fourbar_loops(mech, sol, loops_by_names(mech, spec))
    return err, "position error %.2e L (one-angle equation per loop, max |c|/rho %.3f)" % (err, m)


def dh_frames(F0, thetas, links):
    """Frames (origin, x, z) along the DH chain from F0, F_{i+1} = F_i Rz(th_i) Tx(a_i) Rx(al_i)."""
    out = [F0]
    o, x, z = F0
    for th, (a, al) in zip(thetas, links):
        x = rot_vec(x, z, th)
        o = add(o, mul(x, a))
        z = rot_vec(z, x, al)
        out.append((o, x, z))
    return out


def rot_vec(v, a, th):
    return mv(rot_axis(a, th), v)


def cf_bennett(mech, sol):
    """DH chain with Bennett's relation; the relation on the solved DH angles."""
    (iname, _), = mech.inputs.items()
    names = ["A", "B", "C", "D"]
    J = [mech.jmap[n] for n in names]
    O = [j.m1.p for j in J]
    Z = [unit(j.m1.z) for j in J]
    a = [norm(sub(O[(i + 1) % 4], O[i])) for i in range(4)]
    xs = [unit(sub(O[(i + 1) % 4], O[i])) for i in range(4)]
    for i in range(4):   # zero offsets: O_{i+1} - O_i is the common normal of axes i, i+1
        if abs(dot(xs[i], Z[i])) > 1e-12 or abs(dot(xs[i], Z[(i + 1) % 4])) > 1e-12:
            raise Fail("bennett: link %d is not the common normal of its axes" % i)
    alpha = [math.atan2(dot(cross(Z[i], Z[(i + 1) % 4]), xs[i]), dot(Z[i], Z[(i + 1) % 4])) for i in range(4)]
    if abs(a[0] - a[2]) > 1e-12 * mech.size or abs(a[1] - a[3]) > 1e-12 * mech.size \
            or abs(alpha[0] - alpha[2]) > 1e-12 or abs(alpha[1] - alpha[3]) > 1e-12:
        raise Fail("bennett: opposite links are not equal")
    if abs(a[0] / math.sin(alpha[0]) - a[1] / math.sin(alpha[1])) > 1e-9 * mech.size:
        raise Fail("bennett: a/sin(alpha) != b/sin(beta)")
    al, be = alpha[0], alpha[1]
    sp, sm = math.sin((be + al) / 2), math.sin((be - al) / 2)

    def dh_angles(Ow, Zw):
        th = []
        for i in range(4):
            xp, xn = unit(sub(Ow[i], Ow[i - 1])), unit(sub(Ow[(i + 1) % 4], Ow[i]))
            th.append(math.atan2(dot(Zw[i], cross(xp, xn)), dot(xp, xn)))
        return th
    th0 = dh_angles(O, Z)
    links = list(zip(a, alpha))
    err, rel = 0.0, 0.0
    keys = [("crank", "A"), ("crank", "B"), ("coupler", "C"), ("rocker", "D")]
    Mloc = None
    for vals, poses in sol:
        t1 = th0[0] + math.radians(vals[iname])
        t2 = 2.0 * math.atan2(sp * math.cos(t1 / 2), sm * math.sin(t1 / 2))
        fr = dh_frames((O[0], xs[3], Z[0]), [t1, t2, -t1, -t2], links)
        for i, (b, n) in enumerate(keys):
            err = max(err, norm(sub(world(mech, poses, "%s.%s" % (b, n)), fr[i][0])) / mech.size)
        # the coupler point M, carried by the coupler's frame (origin O_B, x towards C, z = z_B)
        if Mloc is None:
            o, x, z = O[1], xs[1], Z[1]
            mp = mech.markers["coupler.M"].p
            d = sub(mp, o)
            Mloc = (dot(d, x), dot(d, cross(z, x)), dot(d, z))
        o, x, z = fr[1][0], fr[2][0], fr[1][2]
        x = unit(sub(x, o))
        pred = add(o, add(mul(x, Mloc[0]), add(mul(cross(z, x), Mloc[1]), mul(z, Mloc[2]))))
        err = max(err, norm(sub(world(mech, poses, "coupler.M"), pred)) / mech.size)
        Ow = [world(mech, poses, "%s.%s" % k) for k in keys]
        Zw = [world_dir(mech, poses, "%s.%s" % k) for k in keys]
        th = dh_angles(Ow, Zw)
        # tan(t1/2) tan(t2/2) = sp/sm  <=>  sm sin(t1/2) sin(t2/2) - sp cos(t1/2) cos(t2/2) = 0
        r = sm * math.sin(th[0] / 2) * math.sin(th[1] / 2) - sp * math.cos(th[0] / 2) * math.cos(th[1] / 2)
        rel = max(rel, abs(r) / math.hypot(sm, sp), abs(wrap(th[0] + th[2])), abs(wrap(th[1] + th[3])))
    return max(err, rel), ("position error %.2e L (DH chain); Bennett relation %.2e "
                           "(a = %.4f, alpha = %.2f deg, b = %.4f, beta = %.2f deg)"
                           % (err, rel, a[0], math.degrees(al), a[1], math.degrees(be)))


def cf_excavator(mech, sol):
    """Boom and stick angles from the cylinder triangles; tip by composing rotations."""
    js = mech.jmap

    def pin(jname, body):
        return marker_of(js[jname], body).p

    def tri(P, Q, R, axis, L):
        """Signed rotation (about axis, through P) of R's arm so that |Q R'| = L."""
        a, b = norm(sub(Q, P)), norm(sub(R, P))
        ua, ub = sub(Q, P), sub(R, P)
        s0 = math.atan2(dot(axis, cross(ua, ub)), dot(ua, ub))
        c = (a * a + b * b - L * L) / (2 * a * b)
        if abs(c) >= 1:
            raise Fail("excavator: cylinder triangle does not close")
        s = math.copysign(math.acos(c), s0)
        return s - s0
    slew_axis = unit(js["slew_bearing"].m1.z)
    P1, P2 = pin("boom_pivot", "boom"), pin("stick_pivot", "stick")
    y1, y2 = unit(js["boom_pivot"].m1.z), unit(js["stick_pivot"].m1.z)
    Q1, R1 = pin("boom_barrel_pin", "boom_barrel"), pin("boom_rod_pin", "boom_rod")
    Q2, R2 = pin("stick_barrel_pin", "stick_barrel"), pin("stick_rod_pin", "stick_rod")
    Ob = js["slew_bearing"].m1.p
    err = 0.0
    for vals, poses in sol:
        Rs = rot_axis(slew_axis, math.radians(vals["slew"]))
        d1 = tri(P1, Q1, R1, y1, norm(sub(R1, Q1)) + vals["boom_cyl"])
        d2 = tri(P2, Q2, R2, y2, norm(sub(R2, Q2)) + vals["stick_cyl"])
        Rb = rot_axis(y1, d1)
        Rst = rot_axis(y2, d2)

        def pred(body, p):
            q = p
            if body in ("stick", "bucket"):
                q = add(P2, mv(Rst, sub(q, P2)))        # stick turns about P2 (boom frame)
            if body in ("boom", "stick", "bucket"):
                q = add(P1, mv(Rb, sub(q, P1)))         # boom turns about P1 (turret frame)
            return add(Ob, mv(Rs, sub(q, Ob)))          # turret slews
        # points whose position the closed form gives: every marker of turret, boom, stick,
        # bucket, and the pins of the cylinders (rod ends on the pin axes)
        for key, m in mech.markers.items():
            if m.body in ("turret", "boom", "stick", "bucket"):
                err = max(err, norm(sub(world(mech, poses, key), pred(m.body, m.p))) / mech.size)
        for jn, body in (("boom_rod_pin", "boom_rod"), ("stick_rod_pin", "stick_rod"),
                         ("boom_barrel_pin", "boom_barrel"), ("stick_barrel_pin", "stick_barrel")):
            m = marker_of(js[jn], body)
            host = other_body(js[jn], body)
            err = max(err, norm(sub(world(mech, poses, body + "." + m.name), pred(host, m.p))) / mech.size)
    return err, "position error %.2e L (cylinder triangles)" % err


def cf_stewart(mech, sol):
    c0 = header_vec(mech, "centre")
    ax = header_vec(mech, "axis")
    ang = math.radians(header_num(mech, "angle_deg"))
    sh = header_vec(mech, "shift")
    R = rot_axis(ax, ang)
    vals, poses = sol[-1]
    if len(sol) < 2 or vals != mech.frames[-1]:
        raise Fail("stewart: the last frame was not solved")
    err = 0.0
    for key, m in mech.markers.items():
        if m.body == "platform":
            pred = add(add(c0, mv(R, sub(m.p, c0))), sh)
            err = max(err, norm(sub(world(mech, poses, key), pred)) / mech.size)
    return err, "end pose error %.2e L" % err


def cf_sofa(mech, sol):
    W = header_num(mech, "W")
    side = ["crank", "coupler", "rocker", "lever", "link", "arm"]

    def P(key):
        return mech.markers[key].p

    def rot_y(p, c, th):
        return add(c, mv(rot_axis((0.0, 1.0, 0.0), th), sub(p, c)))

    def cc(c1, r1, c2, r2, prev):
        # circles in the plane y = const, axis y
        d = norm(sub(c2, c1))
        e = mul(sub(c2, c1), 1.0 / d)
        a = (d * d + r1 * r1 - r2 * r2) / (2 * d)
        h2 = r1 * r1 - a * a
        if h2 <= 0:
            raise Fail("sofa_bed: dyad does not assemble")
        h = math.sqrt(h2)
        nrm = cross((0.0, 1.0, 0.0), e)
        cands = [add(add(c1, mul(e, a)), mul(nrm, s * h)) for s in (1.0, -1.0)]
        return min(cands, key=lambda q: norm(sub(q, prev))), h / min(r1, r2)

    def frame2(b0, c0, b, c, q0):
        # planar rigid map taking (b0, c0) to (b, c), applied to q0 (axis y)
        u0, u = unit(sub(c0, b0)), unit(sub(c, b))
        ang = math.atan2(dot((0.0, 1.0, 0.0), cross(u0, u)), dot(u0, u))
        return add(b, mv(rot_axis((0.0, 1.0, 0.0), ang), sub(q0, b0)))
    for key, m in mech.markers.items():
        if m.body.endswith("_r") and m.body[:-2] in side:
            twin = m.body[:-2] + "_l." + m.name
            if norm(sub(m.p, add(P(twin), (0.0, W, 0.0)))) > 1e-12 * mech.size:
                raise Fail("sofa_bed: %s is not %s shifted by W" % (key, twin))
    inp = {k: j for k, (_, j) in mech.inputs.items()}
    err, hmin = 0.0, float("inf")
    prevC, prevG = P("coupler_l.C"), P("link_l.G")
    for vals, poses in sol:
        pred = {}
        for iname, j in inp.items():
            body = j.m2.body
            th = math.radians(vals[iname])
            piv = j.m1.p
            for key, m in mech.markers.items():
                if m.body == body:
                    pred[key] = rot_y(m.p, piv, th)
        B, F = pred["crank_l.B"], pred["lever_l.F"]
        D = P("ground.D_l")
        C, h1 = cc(B, norm(sub(P("coupler_l.C"), P("coupler_l.B"))), D, norm(sub(P("rocker_l.C"), D)), prevC)
        prevC = C
        for key, m in mech.markers.items():
            if m.body == "coupler_l":
                pred[key] = frame2(P("coupler_l.B"), P("coupler_l.C"), B, C, m.p)
            if m.body == "rocker_l":
                pred[key] = frame2(D, P("rocker_l.C"), D, C, m.p)
        H = pred["coupler_l.H"]
        G, h2 = cc(F, norm(sub(P("link_l.G"), P("link_l.F"))), H, norm(sub(P("arm_l.G"), P("arm_l.H"))), prevG)
        prevG = G
        hmin = min(hmin, h1, h2)
        for key, m in mech.markers.items():
            if m.body == "link_l":
                pred[key] = frame2(P("link_l.F"), P("link_l.G"), F, G, m.p)
            if m.body == "arm_l":
                pred[key] = frame2(P("arm_l.H"), P("arm_l.G"), H, G, m.p)
        for key, q in list(pred.items()):
            err = max(err, norm(sub(world(mech, poses, key), q)) / mech.size)
            rk = key.replace("_l.", "_r.")
            if rk in mech.markers:
                err = max(err, norm(sub(world(mech, poses, rk), add(q, (0.0, W, 0.0)))) / mech.size)
    return err, "position error %.2e L (planar dyads, right = left + W; min h/r %.3f)" % (err, hmin)


CLOSED = {"cardan": cf_cardan, "double_cardan": cf_double_cardan,
          "tilted_fourbar": cf_tilted_fourbar, "rssr": cf_fourbar,
          "spherical_fourbar": cf_fourbar, "bennett": cf_bennett,
          "excavator": cf_excavator, "stewart": cf_stewart, "sofa_bed": cf_sofa}


# ---------------------------------------------------------------------------
# per-file check

EXPECT_RE = re.compile(
    r"Expected counts: moving bodies (\d+), joints (\d+), joint equations (\d+), "
    r"Grubler (-?\d+), mobility (\d+), redundant (\d+), idle (\d+)")


def check_file(path, verbose=False, stride=None, quick=False):
    t0 = time.time()
    mech = Mech(path)
    L, ell = mech.size, mech.ell
    n = len(mech.moving)
    ident = mech.drawn()
    # (a) drawn pose
    vals, J = evaluate(mech.rows, ident, ell, True)
    worst = mech.relres(mech.rows, vals)
    if worst > DRAWN_TOL:
        bad = [r[-1] for r, v in zip(mech.rows, vals) if mech.relres([r], [v]) > DRAWN_TOL]
        raise Fail("joints open in the drawn pose: %s (%.2e)" % (sorted(set(bad)), worst))
    # (b) counts
    eqs = len(mech.rows)
    grub = 6 * n - eqs
    r, kept, rej = sparse_rank(J)
    _, Ji = evaluate(mech.rows + mech.input_rows({k: 0.0 for k in mech.inputs}), ident, ell, True)
    ri, kepti, reji = sparse_rank(Ji)
    mob, red, idle = 6 * n - r, eqs - r, 6 * n - ri
    counts = (n, len(mech.joints), eqs, grub, mob, red, idle)
    exp = None
    for ln in mech.header:
        m = EXPECT_RE.search(ln)
        if m:
            exp = tuple(int(x) for x in m.groups())
    if exp is None:
        raise Fail("header has no 'Expected counts:' line")
    if exp != counts:
        raise Fail("counts %s differ from the header's %s" % (counts, exp))
    if verbose:
        print("  %s: L = %.4f, l = %.4f, drawn residual %.1e; rank %d (smallest pivot %.2e, largest rejected %.2e), "
              "with inputs %d (%.2e, %.2e)" % (mech.name, L, ell, worst, r, kept, rej, ri, kepti, reji))
    # (c) sweep
    if stride is None:
        stride = 10 if quick and mech.name.startswith("spatial_stress_") and n >= 101 else 1
    idxs = list(range(0, len(mech.frames), stride))
    if idxs[-1] != len(mech.frames) - 1:
        idxs.append(len(mech.frames) - 1)
    solver = Solver(mech)
    poses, prev = ident, None
    sol, ok, maxres = [], 0, 0.0
    for k in idxs:
        values = mech.frames[k]
        start = predict(prev, poses) if prev is not None else poses
        new, conv, _ = solver.solve(start, values)
        if not conv:
            # retry from the previous solution without prediction
            new, conv, _ = solver.solve(poses, values)
        f, _ = evaluate(mech.rows, new, ell, False)
        res = mech.relres(mech.rows, f)
        maxres = max(maxres, res)
        if conv:
            ok += 1
        elif verbose:
            print("  frame %d did not converge (residual %.2e)" % (k, res))
        prev, poses = poses, new
        sol.append((values, new))
    # (d) closed forms
    cf = None
    fn = CLOSED.get(mech.name)
    if fn is None and mech.name.startswith("spatial_stress_"):
        fn = cf_stress
    if fn is not None:
        cerr, note = fn(mech, sol)
        cf = (cerr, note)
    return mech, counts, (ok, len(idxs), len(mech.frames), stride), maxres, cf, solver.iters, time.time() - t0


def main(argv):
    verbose = "-v" in argv
    quick = "--quick" in argv
    argv = [a for a in argv if a not in ("-v", "--quick")]
    stride = None
    if "--stride" in argv:
        i = argv.index("--stride")
        stride = int(argv[i + 1])
        del argv[i:i + 2]
    paths = []
    for a in argv or [os.path.join(REPO, "mechanisms", "spatial")]:
        if os.path.isdir(a):
            paths += sorted(os.path.join(a, f) for f in os.listdir(a) if f.endswith(".toml"))
        else:
            paths.append(a)

    def key(p):
        s = os.path.basename(p)
        m = re.search(r"_(\d+)\.toml$", s)
        return (re.sub(r"_\d+\.toml$", "", s), int(m.group(1)) if m else 0)
    paths.sort(key=key)
    hdr = ("%-20s %5s %6s %5s %5s %4s %4s %4s %11s %9s %9s %7s"
           % ("file", "bodies", "joints", "eqs", "grub", "mob", "red", "idle", "frames ok", "max res", "closed", "time"))
    print(hdr)
    print("-" * len(hdr))
    failed = 0
    notes = []
    for p in paths:
        name = os.path.splitext(os.path.basename(p))[0]
        try:
            mech, c, fr, res, cf, iters, dt = check_file(p, verbose, stride, quick)
            ok, solved, total, st = fr
            frames = "%d/%d" % (ok, solved) + ("" if st == 1 else "*")
            cerr = "%.1e" % cf[0] if cf else "-"
            print("%-20s %5d %6d %5d %5d %4d %4d %4d %11s %9.1e %9s %6.1fs"
                  % ((name,) + c + (frames, res, cerr, dt)))
            bad = []
            if ok != solved:
                bad.append("%d frames did not converge" % (solved - ok))
            if res > SOLVE_TOL:
                bad.append("residual %.2e" % res)
            if cf and not cf[0] <= CLOSED_TOL:
                bad.append("closed form off by %.2e" % cf[0])
            if cf:
                notes.append("%s: %s" % (name, cf[1]))
            if st != 1:
                notes.append("%s: every %dth of %d frames solved (and the last)" % (name, st, total))
            if bad:
                failed += 1
                print("  FAIL %s: %s" % (name, "; ".join(bad)))
        except Fail as e:
            failed += 1
            print("%-20s FAIL: %s" % (name, e))
    print()
    for n in notes:
        print("  " + n)
    print("\n%d file(s), %d failed" % (len(paths), failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
