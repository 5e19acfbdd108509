#!/usr/bin/env python3
"""Independent checker for the mechanisms that need a numeric cluster
(the mechanisms written by tools/generate/clusters.py).

Stdlib only (Python >= 3.11 for tomllib).  Usage:

    python3 tools/check/clusters.py [-v] [files or directories ...]

(default: the files tools/generate/clusters.py writes in <repo>/mechanisms).  Exit status 0 iff all pass.

For each file:

1. Structure: name = file stem, one fixed body (the ground), revolute joints only, every
   joint's markers coincide in the drawn pose to 1e-12 of the mechanism's size, bodies
   connected, one angle input on a revolute joint between the ground and a link, a sweep.
2. Counts: Grubler mobility D = 3(L - 1) - 2J (1 for the closed linkages, n - 2 for
   chain_n), mobility by the rank of the Jacobian at the drawn pose, Figure 30's counts
   (mobile links = L - 2, active joints = J - 1, Newton 3*mobile / 2*active): a mismatch
   is a failure; a mismatch of the mixed count only (see 3.) is a warning.
3. Closed form: a small simulation of the propagation + dyad rule.  Starting from the ground,
   repeatedly place
     - the body driven by the angle input, once the other body of its joint is placed;
     - a body with revolutes at two distinct points to placed bodies (rigid placement);
     - an RRR dyad: two unplaced bodies U1, U2 joined to each other by a revolute, each
       joined by a revolute to a placed body.
   The bodies left over when this stalls must be non-empty (else the file does not need a
   numeric cluster).  Then the smallest subset S of the left-over bodies that is not
   under-constrained (2 j(S) >= 3 |S|, j(S) = joints from S to S or to placed bodies) is
   the numeric cluster: it is placed, and the closed form runs again (a dyad hanging off the
   cluster's output is placed then).  If no such subset exists (chains) all left-over
   bodies form one under-constrained cluster.  Mixed count of a cluster (Brunkhart): a body
   pinned to an already placed body has 1 unknown (its angle), any other 3; each joint of
   the cluster that is not such a pin gives 2 equations.  These are compared with Figure 30.
4. Numeric sweep, own code: body poses world(p) = t + R(phi) p (p = drawn coordinates, the
   runtime's convention), the driven body placed from the input, every other joint two
   equations.  Frames are solved in order starting from the drawn pose, each warm-started
   from the previous frame: Newton (Householder QR) for the 1-DOF linkages, minimum-norm
   Gauss-Newton steps (QR of J^T) for the chains.  Every frame must hold every joint and
   the input to 1e-10 (absolute).  Conditioning: the smallest singular value of the
   Jacobian (Jacobi eigenvalues of J^T J or J J^T, with each body's angle taken about its
   marker centroid so the number does not depend on where the origin is) over all frames.
   1-DOF linkages are also solved backwards from the last frame, and the first frame by
   small steps from the drawn pose: both must give the same poses (no branch jump).
   RRR dyads after the cluster report their transmission |sin mu|.
5. sixbar_b: bodies, markers and joints identical to mechanisms/sixbar_a.toml, and every
   frame agrees with sixbar_a's closed form (circle intersections, drawn branches) at the
   crank rotation found numerically.
"""
import math
import os
import sys
import tomllib

TOL_DRAWN = 1e-12   # relative to the size
TOL_FRAME = 1e-10   # absolute joint / input residual of a frame
MIN_SIGMA = 0.05    # smallest singular value of the Jacobian must stay above this
TOL_SAME = 1e-8     # forward / backward / sub-stepped poses agree to this

# Figure 30 rows: mobile links, active joints, Newton unk/eqs, mixed unk/eqs
REFERENCE = {
    "sixbar_b": ("6-bar (b)", 4, 6, 12, 12, 6, 6),
    "eightbar": ("8-bar", 6, 9, 18, 18, 12, 12),
    "tenbar": ("10-bar", 8, 12, 24, 24, 14, 14),
    "duplex": ("Duplex", 10, 15, 30, 30, 20, 20),
    "chain_4": ("Chain-4", 3, 4, 9, 8, 5, 4),
    "chain_6": ("Chain-6", 5, 6, 15, 12, 11, 8),
    "chain_8": ("Chain-8", 7, 8, 21, 16, 17, 12),
    "chain_10": ("Chain-10", 9, 10, 27, 20, 23, 16),
    "chain_15": ("Chain-15", 15, 14, 42, 30, 38, 26),
}
# the reference's Chain-15 row swaps its mobile-link and joint counts (its Newton column
# 42/30 = 3*14 / 2*15 agrees with 14 mobile links and 15 active joints)
KNOWN_SWAP = {"chain_15"}


class Fail(Exception):
    pass


# ----------------------------------------------------------------------------
# linear algebra


def householder_qr(A):
    """A (m x n, m >= n) = Q R; returns (list of Householder vectors, R as rows, n)"""
    m, n = len(A), len(A[0])
    R = [row[:] for row in A]
    vs = []
    for k in range(n):
        x = [R[i][k] for i in range(k, m)]
        nx = math.sqrt(sum(v * v for v in x))
        if nx == 0.0:
            raise Fail("rank-deficient Jacobian")
        alpha = -nx if x[0] >= 0 else nx
        v = x[:]
        v[0] -= alpha
        nv = math.sqrt(sum(t * t for t in v))
        v = [t / nv for t in v]
        vs.append(v)
        for j in range(k, n):
            s = 2 * sum(v[i - k] * R[i][j] for i in range(k, m))
            for i in range(k, m):
                R[i][j] -= s * v[i - k]
    return vs, R


def apply_qt(vs, b):
    b = b[:]
    for k, v in enumerate(vs):
        s = 2 * sum(v[i] * b[k + i] for i in range(len(v)))
        for i in range(len(v)):
            b[k + i] -= s * v[i]
    return b


def apply_q(vs, b):
    b = b[:]
    for k in range(len(vs) - 1, -1, -1):
        v = vs[k]
        s = 2 * sum(v[i] * b[k + i] for i in range(len(v)))
        for i in range(len(v)):
            b[k + i] -= s * v[i]
    return b


def solve_square(J, b):
    n = len(J)
    vs, R = householder_qr(J)
    y = apply_qt(vs, b)
    x = [0.0] * n
    for i in range(n - 1, -1, -1):
        x[i] = (y[i] - sum(R[i][k] * x[k] for k in range(i + 1, n))) / R[i][i]
    return x


def solve_min_norm(J, b):
    """minimum-norm solution of the wide system J x = b (J full row rank): J^T = Q R,
    x = Q [R^-T b; 0]"""
    m, n = len(J), len(J[0])
    Jt = [[J[i][j] for i in range(m)] for j in range(n)]
    vs, R = householder_qr(Jt)
    z = [0.0] * n
    for i in range(m):
        z[i] = (b[i] - sum(R[k][i] * z[k] for k in range(i))) / R[i][i]
    return apply_q(vs, z)


def jacobi_eigenvalues(S):
    n = len(S)
    A = [r[:] for r in S]
    for _ in range(100):
        off = sum(A[i][j] ** 2 for i in range(n) for j in range(n) if i != j)
        if off <= 1e-30 * sum(A[i][i] ** 2 for i in range(n)):
            break
        for p in range(n - 1):
            for r in range(p + 1, n):
                if A[p][r] == 0.0:
                    continue
                th = (A[r][r] - A[p][p]) / (2 * A[p][r])
                t = (1.0 if th >= 0 else -1.0) / (abs(th) + math.sqrt(th * th + 1))
                c = 1 / math.sqrt(t * t + 1)
                s = t * c
                for k in range(n):
                    akp, akr = A[k][p], A[k][r]
                    A[k][p], A[k][r] = c * akp - s * akr, s * akp + c * akr
                for k in range(n):
                    apk, ark = A[p][k], A[r][k]
                    A[p][k], A[r][k] = c * apk - s * ark, s * apk + c * ark
    return sorted(A[i][i] for i in range(n))


def singular_values(J):
    m, n = len(J), len(J[0])
    if m <= n:
        S = [[sum(a * b for a, b in zip(J[i], J[j])) for j in range(m)] for i in range(m)]
    else:
        S = [[sum(J[k][i] * J[k][j] for k in range(m)) for j in range(n)] for i in range(n)]
    return [math.sqrt(max(0.0, e)) for e in jacobi_eigenvalues(S)]


def rank(J, rel=1e-9):
    s = singular_values(J)
    return sum(1 for v in s if v > rel * s[-1])


# ----------------------------------------------------------------------------
# model


def dist(a, b):
    return math.hypot(a[0] - b[0], a[1] - b[1])


class Model:
    def __init__(self, path):
        self.path = path
        self.stem = os.path.splitext(os.path.basename(path))[0]
        with open(path, "rb") as f:
            d = tomllib.load(f)
        self.doc = d
        errs = []
        self.name = d.get("name")
        if self.name != self.stem:
            errs.append("name %r != file stem %r" % (self.name, self.stem))
        if d.get("dimension", 2) != 2:
            errs.append("dimension must be 2")
        self.bodies, self.fixed = {}, []
        for b, v in d.get("bodies", {}).items():
            mk = {}
            for k, p in v.get("markers", {}).items():
                if isinstance(p, dict):
                    p = p.get("at")
                if not (isinstance(p, list) and len(p) == 2):
                    errs.append("marker %s.%s: bad point" % (b, k))
                    continue
                mk[k] = (float(p[0]), float(p[1]))
            self.bodies[b] = mk
            if v.get("fixed", False):
                self.fixed.append(b)
        if len(self.fixed) != 1:
            errs.append("expected one fixed body, got %r" % self.fixed)
        self.ground = self.fixed[0] if self.fixed else None
        self.joints = {}
        for j, v in d.get("joints", {}).items():
            if v.get("kind") != "revolute":
                errs.append("joint %s: only revolute joints are expected here" % j)
                continue
            refs = []
            for s in v.get("markers", []):
                b, _, k = s.partition(".")
                if b not in self.bodies or k not in self.bodies[b]:
                    errs.append("joint %s: unknown marker %s" % (j, s))
                refs.append((b, k))
            if len(refs) != 2 or refs[0][0] == refs[1][0]:
                errs.append("joint %s: needs two markers on two bodies" % j)
                continue
            self.joints[j] = tuple(refs)
        inputs = d.get("inputs", {})
        if len(inputs) != 1:
            errs.append("expected exactly one input")
        self.input_name, iv = next(iter(inputs.items())) if inputs else (None, {})
        self.input_joint = iv.get("joint")
        if iv.get("kind") != "angle" or self.input_joint not in self.joints:
            errs.append("the input must be an angle on a revolute joint")
        else:
            (b1, k1), (b2, k2) = self.joints[self.input_joint]
            if self.ground not in (b1, b2):
                errs.append("input joint %s is not a ground joint" % self.input_joint)
            if b1 != self.ground:
                errs.append("input joint %s: the ground must be the first marker (the second "
                            "marker's body is the one that turns)" % self.input_joint)
            self.driver = b2 if b1 == self.ground else b1
            self.driver_sign = 1.0 if b1 == self.ground else -1.0
            self.pivot = self.bodies[self.ground][k1 if b1 == self.ground else k2]
        s = d.get("sweep")
        if not s or s.get("input") != self.input_name or not isinstance(s.get("steps"), int) \
                or s["steps"] < 2:
            errs.append("bad or missing [sweep]")
        self.sweep = s
        for t in (s or {}).get("trace", []):
            b, _, k = t.partition(".")
            if b not in self.bodies or k not in self.bodies[b]:
                errs.append("trace marker %s unknown" % t)
        if errs:
            raise Fail("; ".join(errs))
        self.L, self.J = len(self.bodies), len(self.joints)
        self.D = 3 * (self.L - 1) - 2 * self.J
        self.scale = max([1.0] + [abs(c) for mk in self.bodies.values() for p in mk.values() for c in p])
        self.mobile = [b for b in self.bodies if b not in (self.ground, self.driver)]
        self.idx = {b: i for i, b in enumerate(self.mobile)}
        self.eq_joints = [j for j in self.joints if j != self.input_joint]
        self.centroid = {b: (sum(p[0] for p in mk.values()) / len(mk), sum(p[1] for p in mk.values()) / len(mk))
                         for b, mk in self.bodies.items()}

    def values(self):
        s = self.sweep
        n = s["steps"]
        return [float(s["from"]) + (float(s["to"]) - float(s["from"])) * i / (n - 1) for i in range(n)]

    # --- poses: dict body -> (phi, (tx, ty)), world(p) = t + R(phi) p ---------------
    def poses(self, q, th):
        P = {self.ground: (0.0, (0.0, 0.0))}
        phi = self.driver_sign * th
        c, s = math.cos(phi), math.sin(phi)
        pv = self.pivot
        P[self.driver] = (phi, (pv[0] - (c * pv[0] - s * pv[1]), pv[1] - (s * pv[0] + c * pv[1])))
        for b, i in self.idx.items():
            P[b] = (q[3 * i + 2], (q[3 * i], q[3 * i + 1]))
        return P

    @staticmethod
    def w(P, b, p):
        phi, t = P[b]
        c, s = math.cos(phi), math.sin(phi)
        return (t[0] + c * p[0] - s * p[1], t[1] + s * p[0] + c * p[1])

    def wm(self, P, b, k):
        return self.w(P, b, self.bodies[b][k])

    def resid(self, q, th):
        P = self.poses(q, th)
        r = []
        for j in self.eq_joints:
            (b1, k1), (b2, k2) = self.joints[j]
            a, b = self.wm(P, b1, k1), self.wm(P, b2, k2)
            r += [a[0] - b[0], a[1] - b[1]]
        return r

    def jac(self, q, th, about_centroid=False):
        """d resid / d(tx, ty, phi); about_centroid: the angle column turns the body about
        its marker centroid instead of the origin (a change of unknowns that leaves the
        singular values independent of where the origin is)"""
        P = self.poses(q, th)
        n = 3 * len(self.mobile)
        J = []
        for j in self.eq_joints:
            (b1, k1), (b2, k2) = self.joints[j]
            rx, ry = [0.0] * n, [0.0] * n
            for b, k, sg in ((b1, k1, 1.0), (b2, k2, -1.0)):
                if b not in self.idx:
                    continue
                i = 3 * self.idx[b]
                x = self.wm(P, b, k)
                o = self.w(P, b, self.centroid[b]) if about_centroid else P[b][1]
                rx[i] += sg
                ry[i + 1] += sg
                rx[i + 2] += -sg * (x[1] - o[1])
                ry[i + 2] += sg * (x[0] - o[0])
            J += [rx, ry]
        return J

    def dresid_dtheta(self, q, th):
        P = self.poses(q, th)
        out = []
        for j in self.eq_joints:
            d = [0.0, 0.0]
            for (b, k), sg in zip(self.joints[j], (1.0, -1.0)):
                if b == self.driver:
                    x = self.wm(P, b, k)
                    d[0] += -sg * self.driver_sign * (x[1] - self.pivot[1])
                    d[1] += sg * self.driver_sign * (x[0] - self.pivot[0])
            out += d
        return out

    def frame_residual(self, q, th):
        """every joint (including the input's pin) and the input angle, from the poses"""
        P = self.poses(q, th)
        worst = 0.0
        for j, ((b1, k1), (b2, k2)) in self.joints.items():
            worst = max(worst, dist(self.wm(P, b1, k1), self.wm(P, b2, k2)))
        (b1, _), (b2, _) = self.joints[self.input_joint]
        rel = P[b2][0] - P[b1][0]
        worst = max(worst, abs(math.remainder(rel - th, 2 * math.pi)) * self.scale)
        return worst


# ----------------------------------------------------------------------------
# solving


def newton(M, q, th, wide, its=50):
    for _ in range(its):
        r = M.resid(q, th)
        if max(abs(v) for v in r) < 1e-13:
            break
        J = M.jac(q, th)
        dq = solve_min_norm(J, [-v for v in r]) if wide else solve_square(J, [-v for v in r])
        q = [a + b for a, b in zip(q, dq)]
    return q


def run(M, values, q0, wide):
    q, out = q0, []
    for v in values:
        q = newton(M, q, math.radians(v), wide)
        out.append((v, q))
    return out


def max_pose_diff(M, qa, qb, th):
    Pa, Pb = M.poses(qa, th), M.poses(qb, th)
    return max(dist(M.wm(Pa, b, k), M.wm(Pb, b, k)) for b in M.mobile for k in M.bodies[b])


# ----------------------------------------------------------------------------
# closed-form simulation and clusters


def closed_form(M, placed, log):
    """place what propagation + dyads can; returns the set of placed bodies"""
    placed = set(placed)
    rev = [(j, r1[0], r2[0], r1, r2) for j, (r1, r2) in M.joints.items()]
    while True:
        progress = False
        (g1, _), (g2, _) = M.joints[M.input_joint]
        for a, b in ((g1, g2), (g2, g1)):
            if a in placed and b not in placed:
                placed.add(b)
                log.append(("input", b, M.input_joint))
                progress = True
        # rigid placement: two pins at distinct points to placed bodies
        for b in M.bodies:
            if b in placed:
                continue
            pts = set()
            for j, b1, b2, r1, r2 in rev:
                if b1 == b and b2 in placed:
                    pts.add(M.bodies[b][r1[1]])
                elif b2 == b and b1 in placed:
                    pts.add(M.bodies[b][r2[1]])
            if len(pts) >= 2:
                placed.add(b)
                log.append(("rigid", b))
                progress = True
        # RRR dyads
        for j, u1, u2, r1, r2 in rev:
            if u1 in placed or u2 in placed:
                continue
            p1 = [jj for jj, a, b, _, _ in rev if jj != j and ((a == u1 and b in placed) or (b == u1 and a in placed))]
            p2 = [jj for jj, a, b, _, _ in rev if jj != j and ((a == u2 and b in placed) or (b == u2 and a in placed))]
            if p1 and p2:
                placed |= {u1, u2}
                log.append(("dyad", u1, u2, j, p1[0], p2[0]))
                progress = True
        if not progress:
            return placed


def describe(step):
    kind = step[0]
    if kind == "input":
        return "input at %s places %s" % (step[2], step[1])
    if kind == "rigid":
        return "%s pinned at two placed points" % step[1]
    if kind == "dyad":
        return "RRR dyad (%s, %s) at %s (pins %s, %s)" % step[1:]
    return "numeric cluster {%s} (%s): %d unknowns / %d equations" % (
        ", ".join(step[1]), "under-constrained" if step[2] else "well-constrained", step[3], step[4])


def joints_touching(M, S, placed):
    """joints with an end in S and the other end in S or placed"""
    out = []
    for j, ((b1, _), (b2, _)) in M.joints.items():
        if (b1 in S and (b2 in S or b2 in placed)) or (b2 in S and (b1 in S or b1 in placed)):
            out.append(j)
    return out


def plan(M):
    """closed form, clusters, closed form ...; returns (first left-over, steps, mixed)"""
    log = []
    placed = closed_form(M, {M.ground}, log)
    first_left = sorted(set(M.bodies) - placed, key=list(M.bodies).index)
    clusters = []
    mixed_u = mixed_e = 0
    while len(placed) < len(M.bodies):
        rest = [b for b in M.bodies if b not in placed]
        found = None
        for size in range(1, len(rest) + 1):
            for mask in range(1, 1 << len(rest)):
                if bin(mask).count("1") != size:
                    continue
                S = {rest[i] for i in range(len(rest)) if mask >> i & 1}
                if 2 * len(joints_touching(M, S, placed)) >= 3 * len(S):
                    found = S
                    break
            if found:
                break
        S = found or set(rest)
        js = joints_touching(M, S, placed)
        pinned = set()
        for j in js:
            (b1, _), (b2, _) = M.joints[j]
            if b1 in S and b2 in placed:
                pinned.add(b1)
            if b2 in S and b1 in placed:
                pinned.add(b2)
        unk = 3 * len(S) - 2 * len(pinned)
        eqs = 2 * len(js) - 2 * len(pinned)
        mixed_u += unk
        mixed_e += eqs
        names = sorted(S, key=list(M.bodies).index)
        clusters.append((names, sorted(pinned, key=list(M.bodies).index), unk, eqs, found is None))
        log.append(("cluster", names, found is None, unk, eqs))
        placed |= S
        placed = closed_form(M, placed, log)
    return first_left, log, clusters, (mixed_u, mixed_e)


# ----------------------------------------------------------------------------
# sixbar_b against sixbar_a


def circle_circle(c1, r1, c2, r2, side):
    dx, dy = c2[0] - c1[0], c2[1] - c1[1]
    d = math.hypot(dx, dy)
    a = (d * d + r1 * r1 - r2 * r2) / (2 * d)
    h = math.sqrt(max(0.0, r1 * r1 - a * a))
    ex, ey = dx / d, dy / d
    return (c1[0] + a * ex - side * h * ey, c1[1] + a * ey + side * h * ex)


def check_sixbar_b(M, frames, notes):
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(here, "..", "..", "mechanisms", "sixbar_a.toml")
    with open(path, "rb") as f:
        a = tomllib.load(f)
    b = M.doc
    same = a["bodies"] == b["bodies"] and a["joints"] == b["joints"]
    notes.append("bodies, markers and joints identical to sixbar_a.toml: %s; input %s -> %s"
                 % (same, a["inputs"], b["inputs"]))
    g = M.bodies
    A, D, F = g["ground"]["A"], g["ground"]["D"], g["ground"]["F"]
    B0, C0, E0, G0 = g["crank"]["B"], g["coupler"]["C"], g["coupler"]["E"], g["link4"]["G"]

    def side(c1, c2, x):
        return 1.0 if (c2[0] - c1[0]) * (x[1] - c1[1]) - (c2[1] - c1[1]) * (x[0] - c1[0]) > 0 else -1.0
    s1, s2 = side(B0, D, C0), side(E0, F, G0)
    worst = 0.0
    cranks = []
    for v, q in frames:
        th = math.radians(v)
        P = M.poses(q, th)
        phi = P["crank"][0]
        cranks.append(math.degrees(phi))
        c, s = math.cos(phi), math.sin(phi)
        Bw = (A[0] + c * (B0[0] - A[0]) - s * (B0[1] - A[1]), A[1] + s * (B0[0] - A[0]) + c * (B0[1] - A[1]))
        Cw = circle_circle(Bw, dist(B0, C0), D, dist(C0, D), s1)
        # coupler: rigid map of B0, C0 -> Bw, Cw applied to E0
        ang = math.atan2(Cw[1] - Bw[1], Cw[0] - Bw[0]) - math.atan2(C0[1] - B0[1], C0[0] - B0[0])
        c, s = math.cos(ang), math.sin(ang)
        Ew = (Bw[0] + c * (E0[0] - B0[0]) - s * (E0[1] - B0[1]), Bw[1] + s * (E0[0] - B0[0]) + c * (E0[1] - B0[1]))
        Gw = circle_circle(Ew, dist(E0, G0), F, dist(G0, F), s2)
        for body, pt, X in (("coupler", C0, Cw), ("coupler", E0, Ew), ("link4", G0, Gw), ("link5", G0, Gw)):
            worst = max(worst, dist(M.w(P, body, pt), X))
    notes.append("sixbar_a closed form at the numeric crank rotation (%.2f..%.2f deg): max marker "
                 "difference %.2g" % (min(cranks), max(cranks), worst))
    return same and worst < 1e-9


def dyad_transmission(M, frames, dyad):
    """|sin| of the angle at the dyad's middle joint between its two links, over the frames"""
    _, u1, u2, j, j1, j2 = dyad
    (r1, _) = M.joints[j]
    ends = []
    for u, jj in ((u1, j1), (u2, j2)):
        a, b = M.joints[jj]
        ends.append(a if a[0] == u else b)
    mus = []
    for v, q in frames:
        P = M.poses(q, math.radians(v))
        X = M.wm(P, *r1)
        p1, p2 = M.wm(P, *ends[0]), M.wm(P, *ends[1])
        ux, uy, vx, vy = p1[0] - X[0], p1[1] - X[1], p2[0] - X[0], p2[1] - X[1]
        mus.append(abs(ux * vy - uy * vx) / (math.hypot(ux, uy) * math.hypot(vx, vy)))
    return min(mus), max(mus)


# ----------------------------------------------------------------------------


def check(path, verbose):
    res = dict(file=os.path.basename(path), notes=[], ok=False)
    notes = res["notes"]
    try:
        M = Model(path)
    except (Fail, tomllib.TOMLDecodeError, OSError) as ex:
        res["status"] = "FAIL: %s" % ex
        return res
    probs = []
    chain = M.name.startswith("chain_")
    res.update(L=M.L, J=M.J, D=M.D)
    # 1. drawn pose
    gap = max(dist(M.bodies[b1][k1], M.bodies[b2][k2]) for (b1, k1), (b2, k2) in M.joints.values())
    res["gap"] = gap
    if gap > TOL_DRAWN * M.scale:
        probs.append("drawn pose: joint gap %.3g" % gap)
    adj = {b: set() for b in M.bodies}
    for (b1, _), (b2, _) in M.joints.values():
        adj[b1].add(b2)
        adj[b2].add(b1)
    seen, todo = set(), [M.ground]
    while todo:
        b = todo.pop()
        if b not in seen:
            seen.add(b)
            todo += list(adj[b] - seen)
    if seen != set(M.bodies):
        probs.append("bodies not connected: %s" % sorted(set(M.bodies) - seen))
    # 2. mobility
    n = len(M.bodies) - 1
    want_D = n - 2 if chain else 1
    if M.D != want_D:
        probs.append("Grubler D = %d, expected %d" % (M.D, want_D))
    nq = 3 * len(M.mobile)
    # input released: the driver keeps 1 freedom (its angle) on its ground pin, so the
    # mobility is 1 + nq - rank [J | d resid / d theta]
    J0 = M.jac([0.0] * nq, 0.0)
    col = M.dresid_dtheta([0.0] * nq, 0.0)
    rk = rank([row + [c] for row, c in zip(J0, col)])
    rank_mob = 1 + nq - rk
    res["rank_mob"] = rank_mob
    if rank_mob != M.D:
        probs.append("mobility by rank %d != Grubler %d (redundant joints)" % (rank_mob, M.D))
    # counts vs Figure 30
    mob, act = M.L - 2, M.J - 1
    first_left, log, clusters, mixed = plan(M)
    res.update(mob=mob, act=act, newton=(3 * mob, 2 * act), mixed=mixed, left=first_left,
               clusters=clusters, log=log)
    ref = REFERENCE.get(M.name)
    if ref:
        rname, rm, ra, rnu, rne, rmu, rme = ref
        got = (mob, act, 3 * mob, 2 * act, mixed[0], mixed[1])
        want = (rm, ra, rnu, rne, rmu, rme)
        if got != want:
            if M.name in KNOWN_SWAP and got == (ra, rm, rnu, rne, rmu, rme):
                notes.append("Figure 30 %s: matches with the reference's mobile-link and joint counts "
                             "swapped (%d/%d there, %d/%d here); Newton and mixed columns match"
                             % (rname, rm, ra, mob, act))
            elif got[:4] != want[:4] and not (M.name in KNOWN_SWAP and got[:4] == (ra, rm, rnu, rne)):
                probs.append("counts %s != Figure 30 %s %s" % (got, rname, want))
            else:
                res["warn"] = "mixed %d/%d != Figure 30's %d/%d" % (mixed[0], mixed[1], rmu, rme)
                notes.append("WARNING: links, joints and Newton counts match Figure 30 %s, but the mixed "
                             "count %d/%d differs from its %d/%d" % (rname, mixed[0], mixed[1], rmu, rme))
        else:
            notes.append("Figure 30 %s: mobile %d, active joints %d, Newton %d/%d, mixed %d/%d: all match"
                         % ((rname,) + want))
    if not first_left:
        probs.append("fully solvable by propagation + dyads from its input")
    # 3. sweep
    vals = M.values()
    wide = chain or M.D > 1
    try:
        frames = run(M, vals, [0.0] * nq, wide)
    except (Fail, ZeroDivisionError, OverflowError, ValueError) as ex:
        res["status"] = "FAIL: sweep: %s" % ex
        return res
    worst = max(M.frame_residual(q, math.radians(v)) for v, q in frames)
    res["resid"] = worst
    if worst > TOL_FRAME:
        bad = [v for v, q in frames if M.frame_residual(q, math.radians(v)) > TOL_FRAME]
        probs.append("%d frames do not assemble (first at %g, max residual %.3g)" % (len(bad), bad[0], worst))
    sig = []
    for v, q in frames:
        s = singular_values(M.jac(q, math.radians(v), about_centroid=True))
        sig.append((s[0], s[-1], v))
    smin = min(sig)
    res["sigma"] = (smin[0], smin[2], max(s[1] for s in sig))
    if smin[0] < MIN_SIGMA:
        probs.append("near-singular frame at %g (sigma_min %.3g)" % (smin[2], smin[0]))
    step = 0.0
    prev = None
    for v, q in frames:
        P = M.poses(q, math.radians(v))
        pts = [M.wm(P, b, k) for b in M.mobile for k in M.bodies[b]]
        if prev:
            step = max(step, max(dist(a, b) for a, b in zip(pts, prev)))
        prev = pts
    res["step"] = step
    notes.append("largest marker move between frames: %.4f (size %.3g)" % (step, M.scale))
    if step > 0.25 * M.scale:
        probs.append("frames jump (max marker move %.3g)" % step)
    if not wide:
        # backwards from the last frame, and the first frame by small steps from the drawn pose
        back = run(M, vals[::-1], frames[-1][1], False)[::-1]
        dback = max(max_pose_diff(M, qa, qb, math.radians(v)) for (v, qa), (_, qb) in zip(frames, back))
        k = max(1, int(math.ceil(abs(vals[0]) / 0.25)))
        sub = run(M, [vals[0] * i / k for i in range(1, k + 1)], [0.0] * nq, False)[-1][1]
        dfirst = max_pose_diff(M, sub, frames[0][1], math.radians(vals[0]))
        notes.append("backward sweep vs forward: %.2g; first frame direct vs %d sub-steps from the "
                     "drawn pose: %.2g" % (dback, k, dfirst))
        if dback > TOL_SAME or dfirst > TOL_SAME:
            probs.append("branch jump (backward %.3g, first frame %.3g)" % (dback, dfirst))
        if abs(vals[-1] - vals[0]) == 360.0:
            per = max_pose_diff(M, frames[-1][1], frames[0][1], 0.0)
            notes.append("full turn: last frame vs first frame %.2g (periodic motion)" % per)
        kinds = [st[0] for st in log]
        first_cluster = kinds.index("cluster") if "cluster" in kinds else len(log)
        for st in log[first_cluster:]:
            if st[0] != "dyad":
                continue
            lo, hi = dyad_transmission(M, frames, st)
            notes.append("dyad (%s, %s) after the cluster: transmission |sin mu| at %s in [%.3f, %.3f]"
                         % (st[1], st[2], st[3], lo, hi))
            if lo < 0.3:
                probs.append("poor dyad transmission at %s" % st[3])
    else:
        # chains: how close the part after the driven link comes to being pulled straight:
        # |far end of the driven link - other ground pivot| / (number of remaining links)
        far_pin = [r for j, rr in M.joints.items() if j != M.input_joint for r in rr
                   if r[0] == M.driver]
        other = [r for j, rr in M.joints.items() if j != M.input_joint for r in rr
                 if r[0] == M.ground]
        if chain and len(far_pin) == 1 and len(other) == 1:
            far = 0.0
            for v, q in frames:
                P = M.poses(q, math.radians(v))
                far = max(far, dist(M.wm(P, *far_pin[0]), M.bodies[M.ground][other[0][1]]) / (M.L - 2))
            res["far"] = far
            notes.append("|%s.%s - %s.%s| / %d <= %.4f over the sweep (1 = rest of the chain pulled straight)"
                         % (far_pin[0] + other[0] + (M.L - 2, far)))
    if M.name == "sixbar_b" and not check_sixbar_b(M, frames, notes):
        probs.append("sixbar_b differs from sixbar_a")
    res["ok"] = not probs
    res["status"] = "PASS" if not probs else "FAIL: " + "; ".join(probs)
    return res


def main(argv):
    verbose = "-v" in argv
    args = [a for a in argv if a != "-v"]
    here = os.path.dirname(os.path.abspath(__file__))
    if not args:
        args = [os.path.join(here, "..", "..", "mechanisms", f"{name}.toml") for name in REFERENCE]
    files = []
    for a in args:
        if os.path.isdir(a):
            files += sorted(os.path.join(a, f) for f in os.listdir(a) if f.endswith(".toml"))
        else:
            files.append(a)
    order = list(REFERENCE)
    files.sort(key=lambda p: (order.index(os.path.basename(p)[:-5]) if os.path.basename(p)[:-5] in order
                              else len(order), p))
    results = []
    for f in files:
        try:
            r = check(f, verbose)
        except Exception as ex:  # a malformed file must not stop the others
            r = dict(file=os.path.basename(f), ok=False, status="FAIL: %s: %s" % (type(ex).__name__, ex))
        results.append(r)
        if "sigma" in r:
            s = r["sigma"]
            print("%-15s L=%2d J=%2d D=%2d rank-D=%2d | mobile %2d active %2d Newton %2d/%2d mixed %2d/%2d"
                  " | frames resid %.1e | sigma_min %.3f (at %g) | %s" % (
                      r["file"], r["L"], r["J"], r["D"], r["rank_mob"], r["mob"], r["act"], r["newton"][0],
                      r["newton"][1], r["mixed"][0], r["mixed"][1], r["resid"], s[0], s[1], r["status"]),
                  flush=True)
            print("    left over after propagation + dyads: %s" % ", ".join(r["left"]))
            for c in r["clusters"]:
                print("    cluster {%s}%s: pinned %s, %d/%d" % (
                    ", ".join(c[0]), " (under-constrained)" if c[4] else "", ", ".join(c[1]) or "-", c[2], c[3]))
            if verbose:
                for line in r["log"]:
                    print("      plan: " + describe(line))
            for nline in r["notes"]:
                print("    " + nline)
        else:
            print("%-15s %s" % (r["file"], r["status"]))
    nfail = sum(1 for r in results if not r["ok"])
    print()
    for r in results:
        if r.get("warn"):
            print("warning: %s: %s" % (r["file"], r["warn"]))
    print("%d mechanism(s) checked, %d failed" % (len(results), nfail))
    return 1 if nfail else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
