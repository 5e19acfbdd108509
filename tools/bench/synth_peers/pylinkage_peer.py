#!/usr/bin/env python3
"""pylinkage 1.3.0 path synthesis as a peer (tools/bench/synth_peers/run.sh).

pylinkage's optimizers take a fitness function of the user's: it has no
path-synthesis objective of its own.  So the search is pylinkage's, the
simulation is pylinkage's, and the objective is the task's error:

* the four-bar is pylinkage's own dyad decomposition (Ground A, Ground D,
  Crank B about A, RRRDyad C from B and D, FixedDyad P on B->C), compiled
  once (``Linkage.compile``); a candidate sets the positions and the
  constraint vector of that ``SolverData`` and runs pylinkage's numba
  kernel ``pylinkage.solver.simulation.simulate`` for 180 crank steps of
  2 degrees (one turn, the crank built one step back so row k is at
  theta0 + 2k degrees).  RRRDyad keeps the intersection nearest the previous
  frame, so the assembly branch is the one drawn at the start;
* the design vector (10 numbers, 11 with given timing): A.x, A.y, D.x, D.y,
  crank |AB|, coupler |BC|, rocker |DC|, |BP|, the angle of BP from BC,
  the branch (< 0.5: C right of B->D, else left) [, theta0: the crank's
  angle at input 0];
* free timing: E = sum over the targets of the squared distance to the
  nearest of the 180 frames' coupler points; given timing: E = sum of
  squared distances at the targets' own inputs (multiples of 2 degrees
  from theta0); a candidate that breaks anywhere in the turn (NaN) scores
  +inf, so only fully turning cranks survive, as dofplan's --full-turn;
* the box: A and D within the targets' bounding box widened by half its
  larger side on each side, lengths in [1e-6, that box's diagonal],
  angles in [0, 2 pi], branch in [0, 1];
* the optimizers, with their defaults, on a duck-typed "linkage" whose
  get_constraints() is the design vector (pylinkage's wrappers take any
  object with get_constraints/get_coords):
  - ``pylinkage.optimization.differential_evolution_optimization``
    (SciPy's differential_evolution: best1bin, popsize 15 per dimension,
    maxiter 1000, tol 0.01, mutation (0.5, 1), recombination 0.7, SciPy's
    final L-BFGS-B polish; workers=1: single-threaded), seeded;
  - ``pylinkage.optimization.particle_swarm_optimization`` (local-best
    ring PSO: 100 particles, 200 iterations, inertia 0.6, leader 3.0,
    follower 0.1, 17 neighbours; single-threaded).  It draws from
    ``np.random.default_rng()`` without a seed: runs are repeats.

Prints one JSON line: the best E (its own objective), the search time, the
evaluation count and the five points at theta0 on its branch.

Usage: pylinkage_peer.py TARGET.csv --method de|pso [--seed N]
       [--maxiter N] [--iterations N]
"""

import argparse
import json
import math
import os
import sys
import time

# Do not let this folder shadow packages (the repo's tools/bench/pylinkage.py
# is one folder up, but keep sys.path clean anyway).
_HERE = os.path.dirname(os.path.realpath(__file__))
sys.path[:] = [p for p in sys.path if os.path.realpath(p or os.curdir) != _HERE]

import numpy as np  # noqa: E402

import pylinkage  # noqa: E402
from pylinkage.actuators import Crank  # noqa: E402
from pylinkage.components import Ground  # noqa: E402
from pylinkage.dyads import FixedDyad, RRRDyad  # noqa: E402
from pylinkage.optimization import (  # noqa: E402
    differential_evolution_optimization,
    particle_swarm_optimization,
)
from pylinkage.simulation import Linkage  # noqa: E402
from pylinkage.solver.simulation import simulate  # noqa: E402

STEP_DEG = 2.0
FRAMES = 180


def read_targets(path):
    rows = []
    with open(path) as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            try:
                rows.append([float(v) for v in line.split(",")])
            except ValueError:
                continue
    arr = np.array(rows, dtype=float)
    if arr.shape[1] == 3:
        return arr[:, 0].copy(), arr[:, 1:].copy()
    return None, arr


class Design:
    """What pylinkage's optimizer wrappers read of a "linkage": the design
    vector as its constraints, and no joint coordinates."""

    def __init__(self, x0):
        self.x0 = [float(v) for v in x0]

    def get_constraints(self):
        return list(self.x0)

    def get_coords(self):
        return []


def place(x, theta):
    """A, B, C, D, P at crank angle theta on the design's branch, or None."""
    ax, ay, dx, dy, r, lbc, ldc, dp, ap, br = x[:10]
    bx, by = ax + r * math.cos(theta), ay + r * math.sin(theta)
    ux, uy = dx - bx, dy - by
    d = math.hypot(ux, uy)
    if d < 1e-12:
        return None
    a = (lbc * lbc - ldc * ldc + d * d) / (2 * d)
    h2 = lbc * lbc - a * a
    if h2 < 0:
        return None
    h = math.sqrt(h2) * (1.0 if br >= 0.5 else -1.0)
    ux, uy = ux / d, uy / d
    cx, cy = bx + a * ux - h * uy, by + a * uy + h * ux
    base = math.atan2(cy - by, cx - bx)
    px, py = bx + dp * math.cos(base + ap), by + dp * math.sin(base + ap)
    return {"A": [ax, ay], "B": [bx, by], "C": [cx, cy], "D": [dx, dy], "P": [px, py]}


class Evaluator:
    """The fitness pylinkage's optimizers call: (linkage, params, init_pos)
    -> E, through pylinkage's compiled kernel."""

    def __init__(self, inputs, targets):
        self.inputs, self.targets = inputs, targets
        self.given = inputs is not None
        if self.given:
            k = inputs / STEP_DEG
            if not np.allclose(k, np.round(k)):
                raise SystemExit("given inputs must be multiples of %g degrees" % STEP_DEG)
            self.rows = np.round(k).astype(int) % FRAMES
        # pylinkage's four-bar, compiled once; only its numbers change.
        a, d = Ground(0.0, 0.0, name="A"), Ground(4.0, 0.0, name="D")
        crank = Crank(anchor=a, radius=1.0, angular_velocity=math.radians(STEP_DEG), name="B")
        c = RRRDyad(crank.output, d, 3.8, 2.5, x=4.5, y=2.5, name="C")
        p = FixedDyad(crank.output, c, 3.2, 0.5, name="P")
        lk = Linkage([a, d, crank, c, p], name="fourbar")
        lk.compile()
        sd = lk._solver_data
        if list(sd.solve_order) != [0, 1, 2, 3, 4] or list(sd.constraint_offsets) != [0, 0, 0, 2, 4]:
            raise SystemExit("unexpected pylinkage SolverData layout: %r %r"
                             % (sd.solve_order, sd.constraint_offsets))
        self.args = (sd.joint_types, sd.parent_indices, sd.constraint_offsets, sd.solve_order)
        self.evaluations = 0

    def curve(self, x):
        """coupler P over one turn from theta0, (FRAMES, 2), or None."""
        theta0 = x[10] if self.given else 0.0
        step = math.radians(STEP_DEG)
        start = place(x, theta0 - step)
        if start is None:
            return None
        pos = np.array([start[n] for n in "ADBCP"], dtype=np.float64)
        cons = np.array([x[4], step, x[5], x[6], x[7], x[8]], dtype=np.float64)
        traj = simulate(pos, cons, *self.args, FRAMES, 1.0)
        return traj[:, 4, :]

    def error(self, x):
        c = self.curve(x)
        if c is None or not np.isfinite(c).all():
            return math.inf
        if self.given:
            return float(((c[self.rows] - self.targets) ** 2).sum())
        d2 = ((self.targets[:, None, :] - c[None, :, :]) ** 2).sum(axis=2)
        return float(d2.min(axis=1).sum())

    def __call__(self, linkage, params, init_pos=None):
        self.evaluations += 1
        return self.error(list(params))


def bounds_for(targets, given):
    lo, hi = targets.min(axis=0), targets.max(axis=0)
    big = float((hi - lo).max())
    lo, hi = lo - big / 2, hi + big / 2
    diag = float(np.hypot(*(hi - lo)))
    lb = [lo[0], lo[1], lo[0], lo[1], 1e-6, 1e-6, 1e-6, 1e-6, 0.0, 0.0]
    ub = [hi[0], hi[1], hi[0], hi[1], diag, diag, diag, diag, 2 * math.pi, 1.0]
    if given:
        lb.append(0.0)
        ub.append(2 * math.pi)
    return [float(v) for v in lb], [float(v) for v in ub]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("target")
    ap.add_argument("--method", choices=["de", "pso"], required=True)
    ap.add_argument("--seed", type=int, default=1, help="SciPy DE's seed (PSO is unseeded)")
    ap.add_argument("--maxiter", type=int, default=None, help="DE: default pylinkage's (1000)")
    ap.add_argument("--iterations", type=int, default=None, help="PSO: default pylinkage's (200)")
    a = ap.parse_args()
    inputs, targets = read_targets(a.target)
    ev = Evaluator(inputs, targets)
    lb, ub = bounds_for(targets, ev.given)
    design = Design([(l + u) / 2 for l, u in zip(lb, ub)])
    ev.error(design.x0)  # numba: compile or load its cache before the clock
    ev.evaluations = 0
    extra = {}
    t0 = time.perf_counter()
    if a.method == "de":
        if a.maxiter is not None:
            extra["maxiter"] = a.maxiter
        ens = differential_evolution_optimization(
            ev, design, bounds=(lb, ub), order_relation=min, seed=a.seed, verbose=False, **extra)
        settings = {"strategy": "best1bin", "popsize": 15, "maxiter": extra.get("maxiter", 1000),
                    "tol": 0.01, "seed": a.seed, "workers": 1}
    else:
        if a.iterations is not None:
            extra["iterations"] = a.iterations
        ens = particle_swarm_optimization(
            ev, design, dimensions=len(lb), bounds=(lb, ub), order_relation=min,
            verbose=False, **extra)
        settings = {"n_particles": 100, "iterations": extra.get("iterations", 200),
                    "inertia": 0.6, "leader": 3.0, "follower": 0.1, "neighbors": 17}
    seconds = time.perf_counter() - t0
    x = [float(v) for v in ens.dimensions[0]]
    score = float(ens.scores["score"][0])
    theta0 = x[10] if ev.given else 0.0
    print(json.dumps({
        "tool": "pylinkage %s" % pylinkage.__version__,
        "method": "SciPy DE" if a.method == "de" else "PSO",
        "settings": settings,
        "objective": score,
        "objective_name": "sum of squares on its 2-degree simulation",
        "evaluations": ev.evaluations,
        "seconds": seconds,
        "threads": 1,
        "design": x,
        "pose": place(x, theta0),
    }))


if __name__ == "__main__":
    main()
