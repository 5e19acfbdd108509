#!/usr/bin/env python3
"""Generate the two bundled over-constrained (non-generic) mechanisms of
Brunkhart 1994, section 2.1.3-2.1.4: the "table" of fig. 14b and the V-link
of fig. 13.  Both have Grubler mobility 0 and move with mobility 1, because
one joint of each repeats what the others already impose.

Deterministic, stdlib only.  Usage:  python3 tools/generate/overconstrained.py [outdir]
(default outdir: <repo>/mechanisms).  The writer is tools/generate/mechanisms.py's;
tools/check/mechanisms.py checks both files with its own closed form.
"""
import math
import os
import sys

from mechanisms import Mech, add, fmt, sub


def table():
    # The geometry of tests/planar/rank.rs (PARALLELOGRAM_EXTRA).
    A, E, D = (0, 0), (2, 0), (4, 0)
    link = (1, 1.5)
    B, F, C = add(A, link), add(E, link), add(D, link)
    T = (3, 2.5)  # a point of the table top, traced
    a = math.hypot(*link)
    phi0 = math.degrees(math.atan2(link[1], link[0]))
    lo, hi = -phi0, 180.0 - phi0
    sweep = (-40.0, 110.0)
    assert lo < sweep[0] and sweep[1] < hi
    hdr = """\
table: Brunkhart's "table" (1994, fig. 14b): a parallelogram four-bar with an extra link
parallel to the crank and the rocker.  Ground A = (0,0), E = (2,0), D = (4,0); crank A->B,
extra E->F and rocker D->C all drawn as the vector (1, 1.5) (length %(a).5f); the coupler (the
table top) carries B, F, C with |BF| = |FC| = 2 = |AE| = |ED|.  ABFE and EFCD are parallelograms,
so the top translates and the extra link stays parallel to the crank: it removes no freedom.
Over-constrained but consistent (non-generic): Grubler L = 5, J = 6, D = 3*4 - 2*6 = 0, while
the mobility by the Jacobian's rank is 1, and `dofplan check` names joint F redundant.  Any
epsilon change to E or F makes the linkage a rigid structure or unconstructible.
Drawn crank angle phi0 = atan2(1.5, 1) = %(phi0).4f deg.  Change points (all links collinear)
at input theta = %(lo).4f and %(hi).4f deg; past them the four-bar may fold into its crossed
mode, where the extra link no longer fits.  The sweep (theta = %(s0)g .. %(s1)g) stays between
them.  Top point T = (3, 2.5) is traced: a circle of radius %(a).5f about (2, 1).""" % dict(
        a=a, phi0=phi0, lo=lo, hi=hi, s0=sweep[0], s1=sweep[1])
    m = Mech("table", hdr)
    m.body("ground", [("A", A), ("E", E), ("D", D)], fixed=True)
    m.body("crank", [("A", A), ("B", B)])
    m.body("coupler", [("B", B), ("F", F), ("C", C), ("T", T)])
    m.body("rocker", [("D", D), ("C", C)])
    m.body("extra", [("E", E), ("F", F)])
    m.joint("A", "revolute", "ground.A", "crank.A")
    m.joint("B", "revolute", "crank.B", "coupler.B")
    m.joint("C", "revolute", "coupler.C", "rocker.C")
    m.joint("D", "revolute", "rocker.D", "ground.D")
    m.joint("E", "revolute", "ground.E", "extra.E")
    m.joint("F", "revolute", "extra.F", "coupler.F")
    m.inputs.append(("theta", "angle", "A"))
    steps = int(sweep[1] - sweep[0]) + 1
    m.sweep = dict(input="theta", **{"from": sweep[0], "to": sweep[1]}, steps=steps, trace=["coupler.T"])
    return m


def vlink():
    # The crank-rocker of fourbar.toml, and a V pinned to its coupler at U and W.
    A, D, B, C, P = (0, 0), (4, 0), (1, 1), (4.5, 2.5), (3, 3.5)
    U, W, T = (2, 2), (4, 3), (2.5, 4.5)
    hdr = """\
vlink: the over-constrained linkage of Brunkhart's fig. 13: the crank-rocker four-bar of
fourbar.toml with a V-shaped link pinned to the coupler at two holes, U = (2, 2) and W = (4, 3).
The V's holes match the coupler's exactly (|UW| = %(uw).5f on both), so the V rides on the
coupler as one rigid body.  Grubler: L = 5, J = 6, D = 3*4 - 2*6 = 0 (the figure's "0(?)"); the
Jacobian's rank gives 1, and `dofplan check` names joint W redundant: with the coupler placed,
joint U pins the V and joint W only repeats the distance |UW|.  An epsilon change to one hole
makes the linkage unconstructible.
Sweep: a full crank turn, as fourbar (a crank-rocker: no change points); the V's tip T is
traced.""" % dict(uw=math.hypot(*sub(W, U)))
    m = Mech("vlink", hdr)
    m.body("ground", [("A", A), ("D", D)], fixed=True)
    m.body("crank", [("A", A), ("B", B)])
    m.body("coupler", [("B", B), ("C", C), ("P", P), ("U", U), ("W", W)])
    m.body("rocker", [("C", C), ("D", D)])
    m.body("vee", [("U", U), ("T", T), ("W", W)])
    m.joint("A", "revolute", "ground.A", "crank.A")
    m.joint("B", "revolute", "crank.B", "coupler.B")
    m.joint("C", "revolute", "coupler.C", "rocker.C")
    m.joint("D", "revolute", "rocker.D", "ground.D")
    m.joint("U", "revolute", "coupler.U", "vee.U")
    m.joint("W", "revolute", "coupler.W", "vee.W")
    m.inputs.append(("theta", "angle", "A"))
    m.sweep = dict(input="theta", **{"from": 0.0, "to": 360.0}, steps=361, trace=["vee.T"])
    return m


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    outdir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "..", "mechanisms")
    os.makedirs(outdir, exist_ok=True)
    for fn in (table, vlink):
        m = fn()
        L, J, D = m.grubler()
        assert D == 0, (m.name, L, J, D)
        with open(os.path.join(outdir, m.name + ".toml"), "w") as f:
            f.write(m.text())
        print("wrote %s.toml  (L=%d, J=%d, D=%d)" % (m.name, L, J, D))


if __name__ == "__main__":
    main()
