#!/usr/bin/env python3
"""Time pylinkage's numba simulation path on dofplan's mechanisms, and check it.

Side-by-side peer measurement for the user guide's "Move time, measured"
(docs/guide/performance.md) and "Many frames in one call: `solve_batch`"
(docs/guide/batch.md) tables: how long does pylinkage take
per frame to simulate one linkage over many crank angles, on this machine,
for the same mechanisms (fourbar, stress_10 .. stress_50) and the same sweep?

Set-up (stdlib + numpy + pylinkage; numba makes pylinkage's solver compiled):

    python3 -m venv /tmp/pl && /tmp/pl/bin/pip install pylinkage==1.3.0 numba

and the dofplan binary, for the correctness check:

    cargo build --release -p dofplan --bin dofplan

Usage:

    /tmp/pl/bin/python tools/bench/pylinkage.py [--passes 31] [--long 20000]
        [--dofplan target/release/dofplan] [mechanism name or .toml ...]

(default: fourbar stress_10 stress_20 stress_30 stress_40 stress_50).

What is timed, and why that path
--------------------------------
pylinkage (1.3.0) has one compiled simulation kernel,
``pylinkage.solver.simulation.simulate`` (``@njit``): a loop over steps that
advances every crank by ``angular_velocity * dt``, solves every dyad in the
linkage's solve order (circle-circle intersection keeping the solution
nearest the previous position, polar projection for rigid points) and copies
the positions into a freshly allocated ``(iterations, n_joints, 2)``
trajectory.  Everything else reaches it:

* ``Linkage.step_fast()`` calls it after copying component positions into
  the ``SolverData`` arrays (and back afterwards), in Python;
* ``Mechanism`` (the newer links-and-joints API) is converted to the same
  ``SolverData`` and the same kernel;
* ``population.simulate_batch`` / ``Ensemble.simulate`` is a *Python* loop
  over members (parameter sets of one topology), calling ``simulate`` once per
  member on that member's constraints.  It batches linkages, not frames: its
  per-frame cost is the kernel's, plus per-member Python overhead.  It is not
  a faster path for one linkage over many input values, so it is not timed.

So the timed path is ``simulate`` called directly on the ``SolverData`` that
``Linkage.compile()`` builds -- pylinkage's fastest honest path, without
``step_fast``'s Python copies (also timed, for reference).  JIT compilation is
excluded by a warm-up call.  Each timed call gets a fresh copy of the initial
positions (made before the clock starts), because ``simulate`` advances them
in place.  A pass is enough consecutive calls over the sweep to last about
5 ms; the figure is the median over passes of pass time / frames.

Mapping dofplan's sweep onto pylinkage's crank
----------------------------------------------
dofplan's input is the crank's rotation relative to the drawn pose, frames at
``from + i (to - from) / (steps - 1)`` degrees.  A pylinkage ``Crank`` only
turns at a constant ``angular_velocity`` (radians per step), and the kernel
advances it *before* recording a frame: row ``k`` of the trajectory is after
``k + 1`` steps.  So the crank is built at ``drawn + from - step`` with
``angular_velocity = step`` and the sweep's ``steps`` iterations; row ``k``
is then at ``from + k step``, as dofplan's frame ``k``.  The crank angle is
accumulated (atan2 of the last position plus the step), not recomputed from
``k``, so it drifts by rounding over long runs -- the long-run check measures
that.  Only uniform sweeps of one angle input on a revolute ground joint can
be expressed this way.

Branches: every circle-circle dyad starts at its drawn position, and
pylinkage keeps the intersection nearest the previous position, so it
follows the drawn assembly branch (dofplan's keep-branch from the drawn pose)
as long as no frame comes near a dead point; the stress chains are designed
to stay far from one (tools/generate/stress.py).

Correctness: ``dofplan simulate FILE --json`` gives every marker's world
position per frame (``frames[i]["markers"]["body.marker"] = [x, y]``); every
point pylinkage computes is compared with each dofplan marker it stands for
(both markers of a joint), on every frame.  The long run (``--long`` frames
at the sweep's step, the crank wrapping round many turns) is checked the
same way against ``dofplan simulate FILE --from A --to B --steps N --csv``
(the same markers, as columns; JSON would be 220 MB for stress_50).
"""

import argparse
import csv
import json
import math
import os
import statistics
import subprocess
import sys
import time
import tomllib

# This script is named pylinkage.py, and Python puts its folder first on
# sys.path: without this, `import pylinkage` below would import the script
# itself instead of the package.
_HERE = os.path.dirname(os.path.realpath(__file__))
sys.path[:] = [p for p in sys.path if os.path.realpath(p or os.curdir) != _HERE]

import numpy as np  # noqa: E402

from pylinkage.actuators import Crank  # noqa: E402
from pylinkage.components import Ground  # noqa: E402
from pylinkage.dyads import FixedDyad, RRRDyad  # noqa: E402
from pylinkage.simulation import Linkage  # noqa: E402
from pylinkage.solver.simulation import simulate  # noqa: E402

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
DEFAULT_MECHANISMS = ["fourbar", "stress_10", "stress_20", "stress_30", "stress_40", "stress_50"]
PASS_TARGET_S = 0.005  # about 5 ms a pass, as dofplan's own tables


# ---------------------------------------------------------------------------
# Building the pylinkage linkage from a dofplan file
# ---------------------------------------------------------------------------


class Built:
    """A pylinkage Linkage made from a dofplan file, and what its rows mean.

    ``components[i]`` is row ``i`` of pylinkage's trajectory; ``markers[i]``
    lists the dofplan ``"body.marker"`` keys that row stands for.  ``start``
    is the kernel's initial state (the drawn pose, crank one step back),
    kept apart because ``simulate`` and ``step_fast`` advance the
    ``SolverData`` positions in place.
    """

    def __init__(self, linkage, components, markers, step_deg, frames):
        self.linkage = linkage
        self.components = components
        self.markers = markers
        self.step_deg = step_deg
        self.frames = frames
        self.start = linkage._solver_data.positions.copy()
        self.args = kernel_args(linkage)


def _dist(p, q):
    return math.hypot(q[0] - p[0], q[1] - p[1])


def _angle(p, q):
    return math.atan2(q[1] - p[1], q[0] - p[0])


def build(mech):
    """Decompose a planar, revolute-only, one-crank dofplan file into
    pylinkage components: Ground points, one Crank, RRRDyads (a joint between
    two bodies that each have one placed point) and FixedDyads (any further
    point of a body with two placed points).  This is the dyad decomposition
    pylinkage's API asks for; positions start at the drawn pose so that the
    nearest-solution rule keeps the drawn branch."""
    bodies = mech["bodies"]
    joints = mech["joints"]
    sweep = mech["sweep"]
    inp = mech["inputs"][sweep["input"]]
    if mech.get("dimension", 2) != 2 or inp["kind"] != "angle":
        raise SystemExit("only planar files driven by an angle input are supported")

    # One point per joint (its two markers coincide) and per loose marker.
    point_of = {}  # "body.marker" -> point id
    where = {}  # point id -> drawn [x, y]
    keys = {}  # point id -> ["body.marker", ...]
    for jname, j in joints.items():
        if j["kind"] != "revolute":
            raise SystemExit("joint %s: only revolute joints are supported" % jname)
        for key in j["markers"]:
            point_of[key] = jname
            keys.setdefault(jname, []).append(key)
        b, m = j["markers"][0].split(".")
        where[jname] = bodies[b]["markers"][m]
    for bname, b in bodies.items():
        for m, xy in b["markers"].items():
            key = "%s.%s" % (bname, m)
            if key not in point_of:
                point_of[key] = key
                keys[key] = [key]
                where[key] = xy
    points_of_body = {
        bname: [point_of["%s.%s" % (bname, m)] for m in b["markers"]] for bname, b in bodies.items()
    }

    comp = {}  # point id -> pylinkage component (or anchor proxy)
    order = []  # point ids in creation (= topological) order

    def add(pid, c, anchor=None):
        comp[pid] = anchor if anchor is not None else c
        order.append((pid, c))

    ground = [n for n, b in bodies.items() if b.get("fixed")]
    if len(ground) != 1:
        raise SystemExit("exactly one fixed body expected")
    for pid in points_of_body[ground[0]]:
        add(pid, Ground(where[pid][0], where[pid][1], name=pid))
    placed = {ground[0]}

    # The crank: the body the input joint drives, turning relative to ground
    # (counter-clockwise when ground holds the joint's first marker).
    jin = inp["joint"]
    b1, b2 = (k.split(".")[0] for k in joints[jin]["markers"])
    if ground[0] not in (b1, b2):
        raise SystemExit("the input joint must be on the ground")
    crank_body, sense = (b2, 1.0) if b1 == ground[0] else (b1, -1.0)
    lo, hi, steps = float(sweep["from"]), float(sweep["to"]), int(sweep["steps"])
    step_deg = (hi - lo) / (steps - 1) if steps > 1 else 0.0
    others = [p for p in points_of_body[crank_body] if p != jin]
    tip = others[0]
    pivot = where[jin]
    # Built one step before the sweep's first angle: the kernel steps, then records.
    start = _angle(pivot, where[tip]) + sense * math.radians(lo - step_deg)
    crank = Crank(
        anchor=comp[jin],
        radius=_dist(pivot, where[tip]),
        angular_velocity=sense * math.radians(step_deg),
        initial_angle=start,
        name=tip,
    )
    add(tip, crank, anchor=crank.output)
    for q in others[1:]:
        add(q, FixedDyad(comp[jin], comp[tip], _dist(pivot, where[q]),
                         _angle(pivot, where[q]) - _angle(pivot, where[tip]), name=q))
    placed.add(crank_body)

    while len(placed) < len(bodies):
        progress = False
        # A body with two placed points is placed: its other points are rigid.
        for bname in bodies:
            known = [p for p in points_of_body[bname] if p in comp]
            if bname in placed or len(known) < 2:
                continue
            p0, p1 = known[0], known[1]
            base = _angle(where[p0], where[p1])
            for q in points_of_body[bname]:
                if q not in comp:
                    add(q, FixedDyad(comp[p0], comp[p1], _dist(where[p0], where[q]),
                                     _angle(where[p0], where[q]) - base, name=q))
            placed.add(bname)
            progress = True
        if progress:
            continue
        # Otherwise a joint between two bodies with one placed point each: RRR.
        for jname, j in joints.items():
            if jname in comp:
                continue
            ba, bb = (k.split(".")[0] for k in j["markers"])
            ka = [p for p in points_of_body[ba] if p in comp]
            kb = [p for p in points_of_body[bb] if p in comp]
            if ka and kb:
                pa, pb = ka[0], kb[0]
                x, y = where[jname]
                add(jname, RRRDyad(comp[pa], comp[pb], _dist(where[pa], where[jname]),
                                   _dist(where[pb], where[jname]), x=x, y=y, name=jname))
                progress = True
                break
        if not progress:
            raise SystemExit("no dyad decomposition found (not a chain of dyads?)")

    components = [c for _, c in order]
    linkage = Linkage(components, name=mech["name"])
    linkage.compile()
    return Built(linkage, components, [keys[pid] for pid, _ in order], step_deg, steps)


# ---------------------------------------------------------------------------
# Running pylinkage's kernel, and dofplan
# ---------------------------------------------------------------------------


def kernel_args(linkage):
    """The SolverData arrays simulate() takes, after the positions."""
    sd = linkage._solver_data
    return (sd.constraints, sd.joint_types, sd.parent_indices, sd.constraint_offsets, sd.solve_order)


def run(built, iterations):
    """One kernel call from the initial (drawn) pose: (iterations, n, 2)."""
    return simulate(built.start.copy(), *built.args, iterations, 1.0)


def dofplan_sweep(binary, path):
    """dofplan's frames for the file's own sweep, from ``simulate --json``:
    marker key -> (frames, 2) array."""
    out = subprocess.run([binary, "simulate", path, "--json"], check=True,
                         capture_output=True, text=True).stdout
    frames = json.loads(out)["frames"]
    bad = [i for i, f in enumerate(frames) if f["status"] != "solved"]
    if bad:
        raise SystemExit("%s: dofplan frames %s not solved" % (path, bad[:5]))
    return {key: np.array([f["markers"][key] for f in frames]) for key in frames[0]["markers"]}


def dofplan_run(binary, path, lo, step, n):
    """dofplan's frames at ``lo + k step`` (k < n), from ``simulate --csv``
    with the sweep overridden: marker key -> (n, 2) array.  CSV rather than
    JSON because 20,000 frames of stress_50 are 220 MB of JSON."""
    cmd = [binary, "simulate", path, "--from", repr(lo), "--to", repr(lo + (n - 1) * step),
           "--steps", str(n), "--csv"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, text=True)
    rows = csv.reader(proc.stdout)
    head = next(rows)
    status = head.index("status")
    xcols = [c for c, h in enumerate(head) if h.endswith(".x") and h.count(".") == 2]
    data = []
    for r in rows:
        if r[status] != "solved":
            raise SystemExit("%s: dofplan frame %s not solved" % (path, r[0]))
        data.append([float(r[c]) for c in xcols] + [float(r[c + 1]) for c in xcols])
    if proc.wait():
        raise SystemExit("%s failed" % " ".join(cmd))
    data = np.array(data)
    m = len(xcols)
    return {head[c][:-2]: np.stack([data[:, k], data[:, m + k]], axis=1) for k, c in enumerate(xcols)}


def max_diff(built, traj, ref):
    """Largest |coordinate difference| between every pylinkage row and each
    dofplan marker it stands for, over every frame (NaN if any is NaN)."""
    diffs = []
    for i, keys in enumerate(built.markers):
        for key in keys:
            if ref[key].shape != traj[:, i, :].shape:
                raise SystemExit("frame counts differ: dofplan %d, pylinkage %d"
                                 % (ref[key].shape[0], traj.shape[0]))
            diffs.append(np.abs(traj[:, i, :] - ref[key]).max())
    return float(np.max(diffs))  # np.max propagates NaN


# ---------------------------------------------------------------------------
# Timing
# ---------------------------------------------------------------------------


def time_passes(built, iterations, passes):
    """Per-frame times (µs) of `passes` passes; a pass is `calls` consecutive
    kernel calls of `iterations` frames, each from a fresh copy of the drawn
    pose, `calls` chosen for ~5 ms a pass."""
    args = built.args
    # Warm-up: JIT-compile (or load numba's cache) and size a pass.
    run(built, iterations)
    t0 = time.perf_counter()
    run(built, iterations)
    one = time.perf_counter() - t0
    calls = max(1, math.ceil(PASS_TARGET_S / max(one, 1e-9)))
    per_frame = []
    for _ in range(passes):
        starts = np.repeat(built.start[np.newaxis], calls, axis=0)  # C-contiguous rows
        t0 = time.perf_counter_ns()
        for c in range(calls):
            simulate(starts[c], *args, iterations, 1.0)
        dt = time.perf_counter_ns() - t0
        per_frame.append(dt / 1e3 / (calls * iterations))
    return per_frame


def time_step_fast(built, passes):
    """Per-frame times (µs) of the public ``Linkage.step_fast()`` over the
    sweep, one call a pass: the same kernel plus Python copies of the
    component positions in and out.  The components are reset to the
    initial pose before each call (outside the clock).  Also returns the max
    difference of its trajectory from the direct kernel call's."""
    lk = built.linkage
    pose = lk.get_coords()
    lk.step_fast(iterations=built.frames)
    per_frame = []
    for _ in range(passes):
        lk.set_coords(pose)
        t0 = time.perf_counter_ns()
        traj = lk.step_fast(iterations=built.frames)
        per_frame.append((time.perf_counter_ns() - t0) / 1e3 / built.frames)
    lk.set_coords(pose)
    same = float(np.abs(traj - run(built, built.frames)).max())
    return per_frame, same


# ---------------------------------------------------------------------------


def resolve(name):
    if name.endswith(".toml") or os.sep in name:
        return name
    return os.path.join(REPO, "mechanisms", name + ".toml")


def fmt_times(t):
    return "%.3f | %.3f–%.3f" % (statistics.median(t), min(t), max(t))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mechanisms", nargs="*", default=DEFAULT_MECHANISMS)
    ap.add_argument("--passes", type=int, default=31, help="timed passes (median taken); >= 11")
    ap.add_argument("--long", type=int, default=20000, help="frames of the long run (0: skip)")
    ap.add_argument("--dofplan", default=os.path.join(REPO, "target", "release", "dofplan"))
    a = ap.parse_args()
    if a.passes < 11:
        ap.error("--passes must be at least 11")

    import numba
    import pylinkage

    print("pylinkage %s, numba %s, numpy %s, python %s" % (
        getattr(pylinkage, "__version__", "?"), numba.__version__, np.__version__,
        sys.version.split()[0]))
    print("%d cpus, load average at start %.2f %.2f %.2f" % ((os.cpu_count(),) + os.getloadavg()))
    print("timed: pylinkage.solver.simulation.simulate (numba, one core), after warm-up; "
          "medians of %d passes of ~%g ms\n" % (a.passes, PASS_TARGET_S * 1e3))

    rows, fast_rows = [], []
    for name in a.mechanisms:
        path = resolve(name)
        with open(path, "rb") as f:
            mech = tomllib.load(f)
        built = build(mech)

        d = max_diff(built, run(built, built.frames), dofplan_sweep(a.dofplan, path))
        rows.append((name, built.frames, time_passes(built, built.frames, a.passes), d))
        fast_t, same = time_step_fast(built, a.passes)
        fast_rows.append((name, built.frames, len(built.components), fast_t, same))

        if a.long:
            # The crank wraps around many turns, each frame from the last.
            lo = float(mech["sweep"]["from"])
            ref = dofplan_run(a.dofplan, path, lo, built.step_deg, a.long)
            d = max_diff(built, run(built, a.long), ref)
            del ref
            rows.append((name, a.long, time_passes(built, a.long, a.passes), d))
        print("  done %s (%d pylinkage points)" % (name, len(built.components)), file=sys.stderr)

    print("| mechanism | frames | pylinkage numba µs/frame (median) | min–max over passes "
          "| max \\|Δ\\| vs dofplan |")
    print("|---|---:|---:|---|---:|")
    for name, n, t, d in rows:
        print("| %s | %d | %s | %.1e |" % (name, n, fmt_times(t), d))

    print("\nFor reference, the public wrapper Linkage.step_fast() on the sweep "
          "(one call a pass, its Python copies included):\n")
    print("| mechanism | frames | pylinkage points | step_fast µs/frame (median) | min–max "
          "| max \\|Δ\\| vs direct call |")
    print("|---|---:|---:|---:|---|---:|")
    for name, n, npts, t, same in fast_rows:
        print("| %s | %d | %d | %s | %.1e |" % (name, n, npts, fmt_times(t), same))
    print("\nload average at end %.2f %.2f %.2f" % os.getloadavg())


if __name__ == "__main__":
    main()
