#!/usr/bin/env python3
"""Independent checker for the bundled mechanisms (mechanisms/*.toml).

Stdlib only (Python >= 3.11 for tomllib).  Usage:

    python3 tools/check/mechanisms.py [-v] [files or directory ...]

(default: every *.toml in <repo>/mechanisms but the numeric-cluster files, which
tools/check/clusters.py checks).  Exit status 0 iff everything passes.

For each file it checks the structure (name = file stem, markers, joint kinds,
revolute markers coinciding to 1e-12 relative, prismatic second marker on the
first marker's line, inputs, sweep, connectivity, Grubler D = 3(L-1) - 2J = 1,
or 0 for the over-constrained files listed in GRUBLER),
then solves the sweep with its own closed-form code.  The solution order is
written out per mechanism family below (it is NOT discovered automatically, so
the check stays independent of the Rust planner):

    crank  : angle input on a revolute joint (body of 2nd marker turns CCW
             relative to the body of the 1st marker by the input value)
    slide  : slide input on a prismatic joint
    rrr    : circle-circle intersection, keeping the side of the drawn pose
             (sign of cross(c2 - c1, X - c1))
    rrp    : circle-line intersection, keeping the drawn side
    rpr    : a pinned block sliding in a slotted link pivoted on a placed body
    pin2   : a body pinned at two points of placed bodies (over-constrained:
             the distance between the two points must already match)

Every frame is then verified against ALL joint constraints of the file, and
the family-specific closed-form property is checked to 1e-9 (straight line,
ellipse, scaled copy, slider formula, break angles, ...).  The sweep is also
solved on a 10x finer sampling to measure the minimal half-chord h (distance
from the tangent / singular configuration) between frames.
"""
import math
import os
import sys
import tomllib

TOL_REL = 1e-12   # marker coincidence / on-line tolerance (relative to scale)
TOL_PROP = 1e-9   # property tolerance
TANGENT_REL = 1e-9  # h^2 >= -TANGENT_REL * r^2 counts as (tangent) assembly
REFINE = 10


class Fail(Exception):
    pass


# Grubler mobility of the files whose count is not 1: the over-constrained ones
# (Brunkhart 1994, figs. 13 and 14b), which still move with mobility 1.
GRUBLER = {"table": 0, "vlink": 0}


# ----------------------------------------------------------------------------
# vectors


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1])


def add(a, b):
    return (a[0] + b[0], a[1] + b[1])


def mul(a, k):
    return (a[0] * k, a[1] * k)


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1]


def cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


def norm(a):
    return math.hypot(a[0], a[1])


def rot(v, phi):
    c, s = math.cos(phi), math.sin(phi)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def wrap(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


def sgn(x):
    return 1.0 if x > 0 else (-1.0 if x < 0 else 0.0)


# ----------------------------------------------------------------------------
# model


class Model:
    def __init__(self, path):
        self.path = path
        self.stem = os.path.splitext(os.path.basename(path))[0]
        with open(path, "rb") as f:
            self.doc = tomllib.load(f)
        self.errors = []
        self.parse()

    def err(self, msg):
        self.errors.append(msg)

    def parse(self):
        d = self.doc
        self.name = d.get("name")
        if self.name != self.stem:
            self.err("name %r != file stem %r" % (self.name, self.stem))
        self.bodies = {}
        self.fixed = []
        for bname, b in d.get("bodies", {}).items():
            mk = {}
            for mname, mv in b.get("markers", {}).items():
                if isinstance(mv, list):
                    p, dr = mv, None
                elif isinstance(mv, dict):
                    p, dr = mv.get("at"), mv.get("dir")
                    extra = set(mv) - {"at", "dir"}
                    if extra:
                        self.err("marker %s.%s: unknown keys %s" % (bname, mname, extra))
                else:
                    self.err("marker %s.%s: bad value" % (bname, mname))
                    continue
                if not (isinstance(p, list) and len(p) == 2 and all(isinstance(x, (int, float)) for x in p)):
                    self.err("marker %s.%s: bad point %r" % (bname, mname, p))
                    continue
                if dr is not None and not (isinstance(dr, list) and len(dr) == 2 and norm(dr) > 0):
                    self.err("marker %s.%s: bad dir %r" % (bname, mname, dr))
                    dr = None
                mk[mname] = (tuple(float(x) for x in p), tuple(float(x) for x in dr) if dr else None)
            extra = set(b) - {"fixed", "markers"}
            if extra:
                self.err("body %s: unknown keys %s" % (bname, extra))
            self.bodies[bname] = mk
            if b.get("fixed", False):
                self.fixed.append(bname)
        if len(self.fixed) != 1:
            self.err("expected exactly one fixed body, got %r" % self.fixed)
        coords = [abs(x) for mk in self.bodies.values() for p, _ in mk.values() for x in p]
        self.scale = max([1.0] + coords)
        self.joints = {}
        for jname, j in d.get("joints", {}).items():
            kind = j.get("kind")
            ms = j.get("markers")
            if kind not in ("revolute", "prismatic"):
                self.err("joint %s: bad kind %r" % (jname, kind))
                continue
            if not (isinstance(ms, list) and len(ms) == 2):
                self.err("joint %s: needs two markers" % jname)
                continue
            refs = []
            for m in ms:
                bn, _, mn = m.partition(".")
                if bn not in self.bodies or mn not in self.bodies[bn]:
                    self.err("joint %s: unknown marker %r" % (jname, m))
                refs.append((bn, mn))
            if refs[0][0] == refs[1][0]:
                self.err("joint %s: both markers on body %s" % (jname, refs[0][0]))
            self.joints[jname] = (kind, refs[0], refs[1])
        self.inputs = {}
        for iname, i in d.get("inputs", {}).items():
            kind, jn = i.get("kind"), i.get("joint")
            if jn not in self.joints:
                self.err("input %s: unknown joint %r" % (iname, jn))
            elif kind == "angle" and self.joints[jn][0] != "revolute":
                self.err("input %s: angle input needs a revolute joint" % iname)
            elif kind == "slide" and self.joints[jn][0] != "prismatic":
                self.err("input %s: slide input needs a prismatic joint" % iname)
            elif kind not in ("angle", "slide"):
                self.err("input %s: bad kind %r" % (iname, kind))
            self.inputs[iname] = (kind, jn)
        s = d.get("sweep")
        if not s:
            self.err("no [sweep]")
            self.sweep = None
        else:
            self.sweep = s
            if s.get("input") not in self.inputs:
                self.err("sweep input %r unknown" % s.get("input"))
            if not (isinstance(s.get("steps"), int) and s["steps"] >= 2):
                self.err("sweep steps must be an integer >= 2")
            for t in s.get("trace", []):
                bn, _, mn = t.partition(".")
                if bn not in self.bodies or mn not in self.bodies[bn]:
                    self.err("trace marker %r unknown" % t)
        self.L = len(self.bodies)
        self.J = len(self.joints)
        self.D = 3 * (self.L - 1) - 2 * self.J

    def m(self, ref):
        if isinstance(ref, str):
            bn, _, mn = ref.partition(".")
            ref = (bn, mn)
        return self.bodies[ref[0]][ref[1]][0]

    def mdir(self, ref):
        d = self.bodies[ref[0]][ref[1]][1]
        n = norm(d)
        return (d[0] / n, d[1] / n)

    def static_checks(self):
        expected = GRUBLER.get(self.name, 1)
        if self.D != expected:
            self.err("Grubler D = 3(%d-1) - 2*%d = %d != %d" % (self.L, self.J, self.D, expected))
        tol = TOL_REL * self.scale
        for jn, (kind, r1, r2) in self.joints.items():
            if r1[0] not in self.bodies or r2[0] not in self.bodies:
                continue
            if r1[1] not in self.bodies[r1[0]] or r2[1] not in self.bodies[r2[0]]:
                continue
            p1, p2 = self.m(r1), self.m(r2)
            if kind == "revolute":
                if norm(sub(p1, p2)) > tol:
                    self.err("revolute %s: markers differ by %.3g" % (jn, norm(sub(p1, p2))))
            else:
                if self.bodies[r1[0]][r1[1]][1] is None:
                    self.err("prismatic %s: first marker has no dir" % jn)
                    continue
                off = abs(cross(self.mdir(r1), sub(p2, p1)))
                if off > tol:
                    self.err("prismatic %s: second marker off the line by %.3g" % (jn, off))
        # connectivity
        adj = {b: set() for b in self.bodies}
        for kind, r1, r2 in self.joints.values():
            if r1[0] in adj and r2[0] in adj:
                adj[r1[0]].add(r2[0])
                adj[r2[0]].add(r1[0])
        if self.fixed:
            seen, todo = set(), [self.fixed[0]]
            while todo:
                b = todo.pop()
                if b in seen:
                    continue
                seen.add(b)
                todo.extend(adj[b] - seen)
            if seen != set(self.bodies):
                self.err("bodies not connected to ground: %s" % sorted(set(self.bodies) - seen))

    def sweep_values(self, refine=1):
        s = self.sweep
        n = (s["steps"] - 1) * refine + 1
        a, b = float(s["from"]), float(s["to"])
        return [a + (b - a) * i / (n - 1) for i in range(n)]


# ----------------------------------------------------------------------------
# closed-form solver


class Broken(Exception):
    pass


class Frame:
    """Poses of the bodies: world(p) = R(phi) p + t, p = drawn coordinates."""

    def __init__(self, model):
        self.M = model
        self.pose = {model.fixed[0]: (0.0, (0.0, 0.0))}
        self.stats = []  # (kind, h, h_rel, sin_mu)

    def placed(self, b):
        return b in self.pose

    def w(self, ref):
        b, mname = ref
        phi, t = self.pose[b]
        return add(rot(self.M.m(ref), phi), t)

    def wdir(self, ref):
        phi, _ = self.pose[ref[0]]
        return rot(self.M.mdir(ref), phi)

    def place2(self, body, ref1, X1, ref2, X2):
        """place body so that marker ref1 -> X1, ref2 -> X2"""
        p1, p2 = self.M.m(ref1), self.M.m(ref2)
        d0, d1 = sub(p2, p1), sub(X2, X1)
        phi = math.atan2(d1[1], d1[0]) - math.atan2(d0[1], d0[0])
        self.pose[body] = (phi, sub(X1, rot(p1, phi)))

    def place_rot(self, body, phi, ref, X):
        self.pose[body] = (phi, sub(X, rot(self.M.m(ref), phi)))

    def split(self, jname):
        """(placed ref, unplaced ref) of a joint"""
        kind, r1, r2 = self.M.joints[jname]
        if self.placed(r1[0]) and not self.placed(r2[0]):
            return r1, r2
        if self.placed(r2[0]) and not self.placed(r1[0]):
            return r2, r1
        raise Fail("joint %s: expected exactly one placed body" % jname)

    # --- steps -------------------------------------------------------------
    def crank(self, jname, deg):
        kind, r1, r2 = self.M.joints[jname]
        th = math.radians(deg)
        if self.placed(r1[0]) and not self.placed(r2[0]):
            phi = self.pose[r1[0]][0] + th
            self.place_rot(r2[0], phi, r2, self.w(r1))
        elif self.placed(r2[0]) and not self.placed(r1[0]):
            phi = self.pose[r2[0]][0] - th
            self.place_rot(r1[0], phi, r1, self.w(r2))
        else:
            raise Fail("crank %s: bad placement state" % jname)

    def slide(self, jname, s):
        kind, r1, r2 = self.M.joints[jname]
        if not (self.placed(r1[0]) and not self.placed(r2[0])):
            raise Fail("slide %s: first marker's body must be placed" % jname)
        phi1, t1 = self.pose[r1[0]]
        self.pose[r2[0]] = (phi1, add(t1, rot(mul(self.M.mdir(r1), s), phi1)))

    def rrr(self, ja, jb, jc):
        """ja: placed P1 -- U1, jb: placed P2 -- U2, jc: U1 -- U2."""
        pa, ua = self.split(ja)
        pb, ub = self.split(jb)
        kind, c1r, c2r = self.M.joints[jc]
        if c1r[0] == ua[0] and c2r[0] == ub[0]:
            xa, xb = c1r, c2r
        elif c2r[0] == ua[0] and c1r[0] == ub[0]:
            xa, xb = c2r, c1r
        else:
            raise Fail("rrr: joint %s does not join %s and %s" % (jc, ua[0], ub[0]))
        M = self.M
        r1 = norm(sub(M.m(xa), M.m(ua)))
        r2 = norm(sub(M.m(xb), M.m(ub)))
        # branch of the drawn pose
        c1d, c2d, Xd = M.m(ua), M.m(ub), M.m(xa)
        sign = sgn(cross(sub(c2d, c1d), sub(Xd, c1d)))
        if sign == 0:
            raise Fail("rrr at %s: drawn pose is tangent" % jc)
        c1, c2 = self.w(pa), self.w(pb)
        d = sub(c2, c1)
        dd = norm(d)
        if dd == 0:
            raise Broken("rrr %s: coincident centres" % jc)
        a = (dd * dd + r1 * r1 - r2 * r2) / (2 * dd)
        h2 = r1 * r1 - a * a
        rmin = min(r1, r2)
        if h2 < -TANGENT_REL * rmin * rmin:
            self.stats.append(("rrr", -math.sqrt(-h2), -math.sqrt(-h2) / rmin, 0.0))
            raise Broken("rrr %s: circles do not meet" % jc)
        h = math.sqrt(max(h2, 0.0))
        e = (d[0] / dd, d[1] / dd)
        X = (c1[0] + a * e[0] - sign * h * e[1], c1[1] + a * e[1] + sign * h * e[0])
        self.place2(ua[0], ua, c1, xa, X)
        self.place2(ub[0], ub, c2, xb, X)
        u, v = sub(c1, X), sub(c2, X)
        smu = abs(cross(u, v)) / (norm(u) * norm(v)) if h > 0 else 0.0
        self.stats.append(("rrr", h, h / rmin, smu))

    def rrp(self, ja, jp, jc):
        """ja: placed P1 -- U1 (revolute), jp: prismatic, 1st marker on placed P2,
        2nd on U2 (slider); jc: U1 -- U2 revolute at X."""
        M = self.M
        pa, ua = self.split(ja)
        kind, lr, sr = M.joints[jp]
        if not (kind == "prismatic" and self.placed(lr[0]) and not self.placed(sr[0])):
            raise Fail("rrp: bad prismatic %s" % jp)
        kind, c1r, c2r = M.joints[jc]
        if c1r[0] == ua[0] and c2r[0] == sr[0]:
            xa, xs = c1r, c2r
        elif c2r[0] == ua[0] and c1r[0] == sr[0]:
            xa, xs = c2r, c1r
        else:
            raise Fail("rrp: joint %s does not join %s and %s" % (jc, ua[0], sr[0]))
        r1 = norm(sub(M.m(xa), M.m(ua)))
        # slider pose for slide s: (phi_l, t_l + R_l s dir); its marker xs:
        phil, tl = self.pose[lr[0]]
        dw = self.wdir(lr)
        W0 = add(rot(M.m(xs), phil), tl)
        c1 = self.w(pa)
        b = dot(dw, sub(W0, c1))
        q = dot(sub(W0, c1), sub(W0, c1)) - r1 * r1
        h2 = b * b - q
        # drawn branch: s = 0 = -b_d + sign * h_d
        bd = dot(M.mdir(lr), sub(M.m(xs), M.m(ua)))
        sign = sgn(bd)
        if sign == 0:
            raise Fail("rrp at %s: drawn pose is tangent" % jc)
        if h2 < -TANGENT_REL * r1 * r1:
            self.stats.append(("rrp", -math.sqrt(-h2), -math.sqrt(-h2) / r1, 0.0))
            raise Broken("rrp %s: circle misses line" % jc)
        h = math.sqrt(max(h2, 0.0))
        s = -b + sign * h
        self.pose[sr[0]] = (phil, add(tl, mul(dw, s)))
        X = add(W0, mul(dw, s))
        self.place2(ua[0], ua, c1, xa, X)
        # transmission: the singular pose is link (c1 -> X) perpendicular to the
        # track, so the quality is |cos(link, track)| = h / r1
        smu = abs(dot(dw, sub(X, c1))) / r1
        self.stats.append(("rrp", h, h / r1, smu))

    def rpr(self, ja, jb, jp):
        """ja: placed P1 -- U1 (block) revolute, jb: placed P2 -- U2 (slotted link)
        revolute, jp: prismatic between U1 and U2 (either order)."""
        M = self.M
        pa, ua = self.split(ja)
        pb, ub = self.split(jb)
        kind, lr, sr = M.joints[jp]
        if kind != "prismatic" or {lr[0], sr[0]} != {ua[0], ub[0]}:
            raise Fail("rpr: bad prismatic %s" % jp)
        # line body L (with dir), point body S; pivot of each on the placed side
        piv = {ua[0]: ua, ub[0]: ub}
        Bw = {ua[0]: self.w(pa), ub[0]: self.w(pb)}
        lp, sp = piv[lr[0]], piv[sr[0]]
        # both bodies rotate by the same phi (relative to drawn).
        # world_L(p) = R(p - lp_d) + Bw_L ; world_S(p) = R(p - sp_d) + Bw_S
        dh = M.mdir(lr)
        w = sub(Bw[sr[0]], Bw[lr[0]])
        kappa = sub(sub(M.m(sr), M.m(sp)), sub(M.m(lr), M.m(lp)))
        e = -cross(dh, kappa)
        rho = norm(w)
        wd = sub(M.m(sp), M.m(lp))
        sign = sgn(dot(dh, wd))  # side of the pivot along the slot, drawn pose
        if sign == 0:
            raise Fail("rpr at %s: degenerate drawn pose" % jp)
        if rho < abs(e) * (1 - TANGENT_REL) or rho == 0:
            self.stats.append(("rpr", rho - abs(e), (rho - abs(e)) / max(rho, 1e-300), 0.0))
            raise Broken("rpr %s: slot cannot reach pin" % jp)
        alpha = math.atan2(w[1], w[0])
        delta = math.atan2(dh[1], dh[0])
        beta = math.asin(max(-1.0, min(1.0, e / rho)))
        if sign < 0:
            beta = math.pi - beta
        phi = alpha - delta - beta
        for body, pref in ((lr[0], lp), (sr[0], sp)):
            self.place_rot(body, phi, pref, Bw[body])
        h = math.sqrt(max(rho * rho - e * e, 0.0))
        self.stats.append(("rpr", h, h / max(rho, 1e-300), math.sqrt(max(0.0, 1 - (e / rho) ** 2))))

    def pin2(self, ja, jb):
        """ja, jb: revolutes from placed bodies to one unplaced body U.  U is
        placed by the two points; the distance between them must already be
        U's own (the joints are redundant, not in conflict)."""
        pa, ua = self.split(ja)
        pb, ub = self.split(jb)
        if ua[0] != ub[0]:
            raise Fail("pin2: joints %s and %s do not pin one body" % (ja, jb))
        Xa, Xb = self.w(pa), self.w(pb)
        gap = abs(norm(sub(Xb, Xa)) - norm(sub(self.M.m(ub), self.M.m(ua))))
        if gap > TOL_PROP * self.M.scale:
            raise Broken("pin2 %s, %s: the two pins are %.3g too far apart" % (ja, jb, gap))
        self.place2(ua[0], ua, Xa, ub, Xb)

    # --- verification -------------------------------------------------------
    def residual(self):
        M = self.M
        worst = 0.0
        for b in M.bodies:
            if b not in self.pose:
                raise Fail("body %s not placed by the recipe" % b)
        for jn, (kind, r1, r2) in M.joints.items():
            p1, p2 = self.w(r1), self.w(r2)
            if kind == "revolute":
                worst = max(worst, norm(sub(p1, p2)))
            else:
                worst = max(worst, abs(cross(self.wdir(r1), sub(p2, p1))))
                dphi = abs(wrap(self.pose[r1[0]][0] - self.pose[r2[0]][0]))
                worst = max(worst, dphi * M.scale)
        return worst


# ----------------------------------------------------------------------------
# recipes (solution orders), per mechanism family


def recipe_stress(M):
    k = (M.L - 2) // 2
    steps = [("crank", "O0")]
    for j in range(1, k + 1):
        steps.append(("rrr", "C%d" % j, "G%d" % j, "R%d" % j))
    return steps


RECIPES = {
    "fourbar": lambda M: [("crank", "A"), ("rrr", "B", "D", "C")],
    "rocker_rocker": lambda M: [("crank", "A"), ("rrr", "B", "D", "C")],
    "parallelogram": lambda M: [("crank", "A"), ("rrr", "B", "D", "C")],
    "slider_crank": lambda M: [("crank", "O"), ("rrp", "B", "S", "C")],
    "inverted_slider_crank": lambda M: [("crank", "O2"), ("rpr", "B", "O4", "S")],
    "sixbar_a": lambda M: [("crank", "A"), ("rrr", "B", "D", "C"), ("rrr", "E", "F", "G")],
    "peaucellier": lambda M: [("crank", "O2"), ("rrr", "OA", "QA", "A"), ("rrr", "OB", "QB", "B"),
                              ("rrr", "A2", "B2", "P")],
    "trammel": lambda M: [("slide", "TX"), ("rrp", "X", "TY", "Y")],
    "pantograph": lambda M: [("crank", "C0"), ("rrr", "O", "T1", "A"), ("rrr", "E", "T2", "D")],
    "table": lambda M: [("crank", "A"), ("rrr", "B", "D", "C"), ("pin2", "E", "F")],
    "vlink": lambda M: [("crank", "A"), ("rrr", "B", "D", "C"), ("pin2", "U", "W")],
    "jansen": lambda M: [("crank", "O"), ("rrr", "A_j", "B", "C"), ("rrr", "A_k", "B_c", "E"),
                         ("rrr", "D", "E_foot", "F")],
}


# The bundled files that need a numeric cluster: no solution order here fits them
# (tools/check/clusters.py checks them), so the default run leaves them out.
CLUSTERS = {"sixbar_b", "eightbar", "tenbar", "duplex", "chain_4", "chain_6", "chain_8", "chain_10",
            "chain_15"}


def recipe_for(M):
    if M.name in RECIPES:
        return RECIPES[M.name](M)
    if M.name and M.name.startswith("stress_"):
        return recipe_stress(M)
    raise Fail("no recipe for %r" % M.name)


def solve_frame(M, recipe, value):
    F = Frame(M)
    for step in recipe:
        op = step[0]
        if op == "crank":
            F.crank(step[1], value)
        elif op == "slide":
            F.slide(step[1], value)
        else:
            getattr(F, op)(*step[1:])
    return F


def run_sweep(M, recipe, refine=1):
    out = []
    for v in M.sweep_values(refine):
        try:
            F = solve_frame(M, recipe, v)
            out.append((v, F, None))
        except Broken as ex:
            out.append((v, None, str(ex)))
    return out


# ----------------------------------------------------------------------------
# family property checks; each returns (ok, text) and may add notes


def prop_fourbar(M, frames, res):
    A, D, B, C = M.m("ground.A"), M.m("ground.D"), M.m("crank.B"), M.m("coupler.C")
    g, a, b, c = norm(sub(D, A)), norm(sub(B, A)), norm(sub(C, B)), norm(sub(D, C))
    ls = sorted([g, a, b, c])
    grashof = ls[0] + ls[3] <= ls[1] + ls[2]
    crank_rocker = grashof and a == ls[0]
    res["notes"].append("links g=%.6f a=%.6f b=%.6f c=%.6f; s+l=%.6f p+q=%.6f -> %s"
                        % (g, a, b, c, ls[0] + ls[3], ls[1] + ls[2],
                           "Grashof crank-rocker" if crank_rocker else ("Grashof" if grashof else "non-Grashof")))
    mus = []
    for v, F, e in frames:
        if F:
            X = F.w(("coupler", "C"))
            u, w = sub(F.w(("coupler", "B")), X), sub(F.w(("rocker", "D")), X)
            mus.append(math.degrees(math.acos(dot(u, w) / (norm(u) * norm(w)))))
    if mus:
        res["notes"].append("transmission angle mu in [%.2f, %.2f] deg" % (min(mus), max(mus)))
    return crank_rocker, "crank-rocker" if crank_rocker else "NOT a crank-rocker"


def prop_rocker_rocker(M, frames, res):
    A, D = M.m("ground.A"), M.m("ground.D")
    B, C = M.m("input.B"), M.m("coupler.C")
    a, b, c, d = norm(sub(B, A)), norm(sub(C, B)), norm(sub(D, C)), norm(sub(D, A))
    ls = sorted([a, b, c, d])
    nong = ls[0] + ls[3] > ls[1] + ls[2]
    phi0 = math.degrees(math.atan2(B[1] - A[1], B[0] - A[0]) - math.atan2(D[1] - A[1], D[0] - A[0]))
    cosb = (a * a + d * d - (b + c) ** 2) / (2 * a * d)
    phib = math.degrees(math.acos(cosb))
    lo, hi = -phib - phi0, phib - phi0
    # folded break reachable?
    fold = abs(b - c) > d - a
    res["notes"].append("non-Grashof: %s (s+l=%.4f > p+q=%.4f)" % (nong, ls[0] + ls[3], ls[1] + ls[2]))
    res["notes"].append("closed form: cos(phi*) = (a^2+d^2-(b+c)^2)/(2ad) = %.15g, phi* = +/-%.10f deg,"
                        " phi0 = %.10f deg" % (cosb, phib, phi0))
    res["notes"].append("break angles (input theta): theta_lo = %.10f deg, theta_hi = %.10f deg" % (lo, hi))
    # numerical break points by bisection on the solver's assembly
    def assembles(t):
        # strict: no tangency tolerance while locating the break points
        global TANGENT_REL
        saved, TANGENT_REL = TANGENT_REL, 0.0
        try:
            solve_frame(M, recipe_for(M), t)
            return True
        except Broken:
            return False
        finally:
            TANGENT_REL = saved

    def bisect(inside, outside):
        for _ in range(200):
            mid = (inside + outside) / 2
            if assembles(mid):
                inside = mid
            else:
                outside = mid
        return inside

    nlo, nhi = bisect(0.0, -180.0), bisect(0.0, 180.0)
    res["notes"].append("bisection on the closed-form solver: %.10f, %.10f (diff %.2g, %.2g)"
                        % (nlo, nhi, nlo - lo, nhi - hi))
    ok = nong and not fold and abs(nlo - lo) < TOL_PROP and abs(nhi - hi) < TOL_PROP
    # assembled frames must be exactly those inside [lo, hi]
    bad = [v for v, F, e in frames if (F is not None) != (lo - 1e-9 <= v <= hi + 1e-9)]
    if bad:
        ok = False
        res["notes"].append("frames inconsistent with break angles: %s" % bad[:5])
    nin = sum(1 for v, F, e in frames if F)
    res["expect_all"] = False
    return ok, "breaks %.4f / %.4f, %d/%d frames assemble as predicted" % (lo, hi, nin, len(frames))


def prop_parallelogram(M, frames, res):
    A, D, B, C = M.m("ground.A"), M.m("ground.D"), M.m("crank.B"), M.m("coupler.C")
    g = norm(sub(D, A))
    is_par = abs(norm(sub(B, A)) - norm(sub(C, D))) < 1e-12 and abs(norm(sub(C, B)) - g) < 1e-12 \
        and norm(sub(sub(C, B), sub(D, A))) < 1e-12
    phi0 = math.degrees(math.atan2(B[1], B[0]))
    tangent = [v for v, F, e in frames if F and F.stats[0][2] < 1e-6]
    modes = []
    for v, F, e in frames:
        if F is None:
            modes.append((v, "broken"))
            continue
        crot = abs(wrap(F.pose["coupler"][0]))
        modes.append((v, "para" if crot < 1e-6 or F.stats[0][2] < 1e-6 else "anti"))
    runs = []
    for v, mo in modes:
        if runs and runs[-1][2] == mo:
            runs[-1][1] = v
        else:
            runs.append([v, v, mo])
    res["notes"].append("drawn crank angle %.4f deg; change points (tangent, h = 0) at theta = %s"
                        % (phi0, ", ".join("%g" % t for t in tangent)))
    res["notes"].append("with the drawn branch sign kept: " +
                        "; ".join("%g..%g %s" % tuple(r) for r in runs))
    # the parallelogram branch exists at every frame: check C = B + (D - A) closes the loop
    worst = 0.0
    for v, F, e in frames:
        Bw = rot(B, math.radians(v))
        Cw = add(Bw, sub(D, A))
        worst = max(worst, abs(norm(sub(Cw, D)) - norm(sub(C, D))))
    ok = is_par and worst < TOL_PROP and len(tangent) >= 1
    res["min_h_required"] = False
    return ok, "parallelogram; change points at theta=%s" % ",".join("%g" % t for t in tangent)


def prop_slider_crank(M, frames, res):
    O, B, C = M.m("ground.O"), M.m("crank.B"), M.m("slider.C")
    S = M.m("ground.S")
    r, l, e = norm(sub(B, O)), norm(sub(C, B)), S[1] - O[1]
    phi0 = math.atan2(B[1] - O[1], B[0] - O[0])
    worst = 0.0
    for v, F, _ in frames:
        phi = phi0 + math.radians(v)
        x = O[0] + r * math.cos(phi) + math.sqrt(l * l - (r * math.sin(phi) - e) ** 2)
        Cw = F.w(("slider", "C"))
        worst = max(worst, abs(Cw[0] - x), abs(Cw[1] - S[1]))
    res["notes"].append("r=%.6g l=%.6g e=%.6g phi0=%.6g deg; x_C = r cos(phi) + sqrt(l^2 - (r sin(phi) - e)^2)"
                        % (r, l, e, math.degrees(phi0)))
    return worst < TOL_PROP, "x_C(theta) formula max err %.2g" % worst


def prop_inverted(M, frames, res):
    O2, O4, B = M.m("ground.O2"), M.m("ground.O4"), M.m("crank.B")
    r, d = norm(sub(B, O2)), norm(sub(O4, O2))
    phi0 = math.atan2(B[1], B[0])
    psi0 = math.atan2(B[1] - O4[1], B[0] - O4[0])
    worst = 0.0
    for v, F, _ in frames:
        phi = phi0 + math.radians(v)
        psi = math.atan2(r * math.sin(phi), r * math.cos(phi) - d)
        s = math.sqrt(r * r + d * d - 2 * r * d * math.cos(phi))
        worst = max(worst, abs(wrap(F.pose["rocker"][0] - (psi - psi0))))
        Bw = F.w(("block", "S"))
        worst = max(worst, abs(norm(sub(Bw, O4)) - s))
    res["notes"].append("r=%.6g d=%.6g; psi = atan2(r sin phi, r cos phi - d), s = sqrt(r^2+d^2-2rd cos phi)" % (r, d))
    return worst < TOL_PROP, "rocker angle / slot position formula max err %.2g" % worst


def prop_peaucellier(M, frames, res):
    O, O2 = M.m("ground.O"), M.m("ground.O2")
    Q, A = M.m("crank.Q"), M.m("armA.A")
    r = norm(sub(Q, O2))
    l = norm(sub(A, O))
    s = norm(sub(Q, A))
    if abs(norm(sub(O2, O)) - r) > 1e-12 * M.scale:
        return False, "crank length != distance to fixed pivot"
    ax = mul(sub(O2, O), 1 / norm(sub(O2, O)))
    xline = (l * l - s * s) / (2 * r)
    worst = 0.0
    ys = []
    for v, F, _ in frames:
        P = F.w(("linkPA", "P"))
        Qw = F.w(("crank", "Q"))
        worst = max(worst, abs(dot(sub(P, O), ax) - xline))
        # inversion: O, Q, P collinear and |OQ||OP| = l^2 - s^2
        worst = max(worst, abs(cross(sub(Qw, O), sub(P, O))) / norm(sub(P, O)))
        worst = max(worst, abs(norm(sub(Qw, O)) * norm(sub(P, O)) - (l * l - s * s)))
        ys.append(cross(ax, sub(P, O)))
    res["notes"].append("line x = (l^2 - s^2)/(2r) = (%.6g^2 - %.6g^2)/(2*%.6g) = %.15g; P.y in [%.4f, %.4f]"
                        % (l, s, r, xline, min(ys), max(ys)))
    return worst < TOL_PROP, "P on x=%.6g, max err %.2g" % (xline, worst)


def prop_trammel(M, frames, res):
    X, Y = M.m("bar.X"), M.m("bar.Y")
    L = norm(sub(Y, X))
    worst = 0.0
    txt = []
    for mk in ("M", "N"):
        P = M.m(("bar", mk))
        lam = dot(sub(P, X), sub(Y, X)) / (L * L)
        if abs(cross(sub(P, X), sub(Y, X))) > 1e-12 * M.scale:
            return False, "bar.%s not on the bar line" % mk
        a, b = abs(1 - lam) * L, abs(lam) * L
        for v, F, _ in frames:
            Pw = F.w(("bar", mk))
            worst = max(worst, abs(Pw[0] ** 2 / a ** 2 + Pw[1] ** 2 / b ** 2 - 1))
        txt.append("bar.%s: a=%.6g b=%.6g" % (mk, a, b))
        res["notes"].append("bar.%s: lambda=%.6g, ellipse x^2/%.6g^2 + y^2/%.6g^2 = 1" % (mk, lam, a, b))
    return worst < TOL_PROP, "%s; max err %.2g" % (", ".join(txt), worst)


def prop_pantograph(M, frames, res):
    O = M.m("ground.O")
    T, P = M.m("crank.T"), M.m("barEP.P")
    k = norm(sub(P, O)) / norm(sub(T, O))
    worst = 0.0
    for v, F, _ in frames:
        Tw, Pw = F.w(("crank", "T")), F.w(("barEP", "P"))
        worst = max(worst, norm(sub(Pw, add(O, mul(sub(Tw, O), k)))))
    res["notes"].append("pen barEP.P = O + k (crank.T - O), O = (%.6g, %.6g), k = %.15g" % (O[0], O[1], k))
    return worst < TOL_PROP, "pen = O + %.6g (T - O), max err %.2g" % (k, worst)


def prop_sixbar(M, frames, res):
    # chain type: the two ternary links (3 distinct joint points) adjacent -> Watt, else Stephenson
    pts = {}
    for kind, r1, r2 in M.joints.values():
        for r in (r1, r2):
            pts.setdefault(r[0], set()).add(M.m(r))
    tern = sorted(b for b, ps in pts.items() if len(ps) == 3)
    adj = any({r1[0], r2[0]} == set(tern) for kind, r1, r2 in M.joints.values())
    kind = "Watt" if adj else "Stephenson"
    res["notes"].append("ternary links %s, %s -> %s chain" % (tern, "adjacent" if adj else "not adjacent", kind))
    return len(tern) == 2, "%s six-bar (ternary: %s)" % (kind, ", ".join(tern))


def prop_table(M, frames, res):
    # Fig. 14b: the extra link stays parallel and equal to the crank (ABFE is a
    # parallelogram) and the top translates.
    worst = 0.0
    for v, F, _ in frames:
        crank = sub(F.w(("crank", "B")), F.w(("crank", "A")))
        extra = sub(F.w(("extra", "F")), F.w(("extra", "E")))
        worst = max(worst, norm(sub(crank, extra)), abs(wrap(F.pose["coupler"][0])) * M.scale)
    return worst < TOL_PROP, "extra link = crank, top translates, max err %.2g" % worst


def prop_vlink(M, frames, res):
    # Fig. 13: the V moves with the coupler as one rigid body.
    worst = 0.0
    for v, F, _ in frames:
        (pv, tv), (pc, tc) = F.pose["vee"], F.pose["coupler"]
        worst = max(worst, abs(wrap(pv - pc)) * M.scale, norm(sub(tv, tc)))
    return worst < TOL_PROP, "V rigid with the coupler, max err %.2g" % worst


def prop_none(M, frames, res):
    return True, "-"


PROPS = {
    "fourbar": prop_fourbar,
    "rocker_rocker": prop_rocker_rocker,
    "parallelogram": prop_parallelogram,
    "slider_crank": prop_slider_crank,
    "inverted_slider_crank": prop_inverted,
    "peaucellier": prop_peaucellier,
    "trammel": prop_trammel,
    "pantograph": prop_pantograph,
    "sixbar_a": prop_sixbar,
    "table": prop_table,
    "vlink": prop_vlink,
}

# expected headline constants (the values stated in the file headers)
EXPECT = {
    "peaucellier": "P on x=3.2",
    "trammel": "bar.M: a=1 b=3, bar.N: a=1.5 b=0.5",
    "pantograph": "pen = O + 2.5 (T - O)",
    "rocker_rocker": "breaks -105.5225 / 45.5225",
}


# ----------------------------------------------------------------------------


def check(path, verbose):
    res = dict(file=os.path.basename(path), notes=[], ok=True, expect_all=True, min_h_required=True)
    try:
        M = Model(path)
    except Exception as ex:  # parse error
        res.update(ok=False, status="parse error: %s" % ex)
        return res
    res.update(name=M.name, L=M.L, J=M.J, D=M.D)
    M.static_checks()
    if M.errors:
        res.update(ok=False, status="; ".join(M.errors))
        return res
    try:
        recipe = recipe_for(M)
        frames = run_sweep(M, recipe)
        fine = run_sweep(M, recipe, REFINE)
        # drawn pose sanity: solving at input 0 reproduces the drawn coordinates
        F0 = solve_frame(M, recipe, 0.0)
        drift = max(norm(sub(F0.w((b, m)), p)) for b, mk in M.bodies.items() for m, (p, _) in mk.items())
        if drift > 1e-9 * M.scale:
            raise Fail("input 0 does not reproduce the drawn pose (drift %.3g)" % drift)
        resid = max([F.residual() for v, F, e in frames if F] + [0.0])
        nok = sum(1 for v, F, e in frames if F)
        stats = [s for v, F, e in fine if F for s in F.stats]
        res.update(frames=len(frames), assembled=nok, resid=resid)
        res["min_h"] = min(s[1] for s in stats)
        res["min_hrel"] = min(s[2] for s in stats)
        res["min_smu"] = min(s[3] for s in stats)
        fn = PROPS.get(M.name, prop_none)
        pok, ptxt = fn(M, frames if M.name == "rocker_rocker" else [f for f in frames if f[1]], res)
        res["prop"] = ptxt
        if M.name in EXPECT and EXPECT[M.name] not in ptxt:
            pok = False
            res["notes"].append("expected %r in property text" % EXPECT[M.name])
        probs = []
        if not pok:
            probs.append("property failed")
        if resid > 1e-9 * M.scale:
            probs.append("joint residual %.3g" % resid)
        if res["expect_all"] and nok != len(frames):
            probs.append("%d frames do not assemble" % (len(frames) - nok))
        if res["expect_all"] and any(F is None for v, F, e in fine):
            probs.append("breaks between frames")
        if res["min_h_required"] and res["expect_all"] and res["min_hrel"] < 0.05:
            probs.append("near-tangent intersection (h_rel %.3g)" % res["min_hrel"])
        res["ok"] = not probs
        res["status"] = "PASS" if not probs else "FAIL: " + "; ".join(probs)
    except Fail as ex:
        res.update(ok=False, status="FAIL: %s" % ex)
    return res


def main(argv):
    verbose = "-v" in argv
    args = [a for a in argv if a != "-v"]
    here = os.path.dirname(os.path.abspath(__file__))
    files = []
    if not args:
        d = os.path.join(here, "..", "..", "mechanisms")
        files = sorted(os.path.join(d, f) for f in os.listdir(d)
                       if f.endswith(".toml") and f[:-5] not in CLUSTERS)
    for a in args:
        if os.path.isdir(a):
            files += sorted(os.path.join(a, f) for f in os.listdir(a) if f.endswith(".toml"))
        else:
            files.append(a)

    def key(p):
        n = os.path.basename(p)
        if n.startswith("stress_"):
            return (1, int(n[7:-5]) if n[7:-5].isdigit() else 0, n)
        return (0, 0, n)

    files.sort(key=key)
    results = [check(f, verbose) for f in files]
    hdr = "%-26s %3s %3s %2s %9s %9s %8s %7s  %s" % ("file", "L", "J", "D", "frames", "min h", "min h/r", "min|sin", "status / property")
    print(hdr)
    print("-" * len(hdr))
    for r in results:
        if "frames" in r:
            print("%-26s %3d %3d %2d %4d/%-4d %9.4f %8.4f %7.4f  %s | %s" % (
                r["file"], r["L"], r["J"], r["D"], r["assembled"], r["frames"], r["min_h"], r["min_hrel"],
                r["min_smu"], r["status"], r.get("prop", "")))
        else:
            print("%-26s %3s %3s %2s %9s %9s %8s %7s  %s" % (r["file"], r.get("L", "?"), r.get("J", "?"),
                                                             r.get("D", "?"), "-", "-", "-", "-", r["status"]))
    print()
    for r in results:
        if r["notes"] and (verbose or r["file"] in ("fourbar.toml", "rocker_rocker.toml", "parallelogram.toml")
                           or not r["ok"]):
            print("%s:" % r["file"])
            for n in r["notes"]:
                print("    " + n)
    if verbose:
        for r in results:
            if r.get("resid") is not None:
                print("%s: max joint residual over frames %.3g" % (r["file"], r["resid"]))
    nfail = sum(1 for r in results if not r["ok"])
    print()
    print("%d mechanism(s) checked, %d failed" % (len(results), nfail))
    return 1 if nfail else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
