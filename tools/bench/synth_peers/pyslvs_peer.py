#!/usr/bin/env python3
"""Pyslvs 22.7 path synthesis as a peer (tools/bench/synth_peers/run.sh).

Runs in Pyslvs's own venv (see README.md; Pyslvs is AGPL: run from here, never
linked into anything shipped).  Problem: the four-bar of Pyslvs's own
collection ("Four bar linkage mechanism": joints 0 and 1 grounded, input
0->2, coupler point 4 traced) on Pyslvs's own objective,
``pyslvs.optimization.FPlanar``: every target gets its own crank-angle
variable (free timing), and the fitness is the sum over the targets of the
*distance* (not squared) from the coupler point at that angle to the target.
Search: ``pyslvs.metaheuristics`` DE with the defaults
``pyslvs.metaheuristics.default(AlgorithmType.DE)`` gives (population 400,
strategy 1, F 0.6, CR 0.9, 1,000 generations), single-threaded.  Pyslvs
seeds its C ``rand()`` from ``time(NULL)``: runs are repeats, not seeds.

The box (our choice; FPlanar needs one): both ground pivots within the
targets' bounding box widened by half its larger side on each side (a square
of that half-width about its centre, as FPlanar's placement (x, y, r) takes
it), every link length in [0, the widened box's diagonal].

FPlanar has no given-timing mode (its angle variables share one range for
every target), so only free-timing targets are run.

Prints one JSON line: the fitness, the search time, and the five points of
the best four-bar at the first target's angle, solved by FPlanar.result()
(full precision, read from the located VPoints), on the branch its
expression fixes.

Usage: pyslvs_peer.py TARGET.csv [--max-gen N]
"""

import argparse
import json
import time

from pyslvs import __version__, collection_list, parse_vpoints
from pyslvs.metaheuristics import AlgorithmType, algorithm, default
from pyslvs.optimization import FPlanar


def read_xy(path):
    pts = []
    with open(path) as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            try:
                v = [float(s) for s in line.split(",")]
            except ValueError:
                continue
            if len(v) != 2:
                raise SystemExit("Pyslvs's FPlanar has free timing only: expected x,y rows")
            pts.append((v[0], v[1]))
    return pts


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("target")
    ap.add_argument("--max-gen", type=int, default=None, help="default: Pyslvs's own (1000)")
    a = ap.parse_args()
    pts = read_xy(a.target)
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    wx, wy = max(xs) - min(xs), max(ys) - min(ys)
    big = max(wx, wy)
    cx, cy = (max(xs) + min(xs)) / 2, (max(ys) + min(ys)) / 2
    r = (big + big) / 2  # half-width of the widened box's larger side
    upper = ((wx + big) ** 2 + (wy + big) ** 2) ** 0.5

    fb = collection_list("Four bar linkage mechanism")
    vpoints = parse_vpoints(fb["expression"])
    mech = {
        "expression": vpoints,
        "input": list(fb["input"]),
        "same": fb["same"],
        "placement": {0: (cx, cy, r), 1: (cx, cy, r)},
        "target": {4: pts},
        "upper": upper,
        "lower": 0.0,
    }
    func = FPlanar(mech)
    settings = default(AlgorithmType.DE)
    if a.max_gen is not None:
        settings["max_gen"] = a.max_gen
    t0 = time.perf_counter()
    alg = algorithm(AlgorithmType.DE)(func, settings)
    alg.run()
    seconds = time.perf_counter() - t0
    v, fitness = alg.result()
    # result() solves the best candidate at its first angle and locates the
    # expression's VPoints (the same objects as `vpoints`) there.
    func.result(v)
    names = ["A", "D", "B", "C", "P"]  # joints 0..4 of the collection
    pose = {n: [vp.cx, vp.cy] for n, vp in zip(names, vpoints)}
    print(json.dumps({
        "tool": "Pyslvs %s" % __version__,
        "method": "DE",
        "settings": {k: (int(x) if isinstance(x, bool) else x) for k, x in settings.items()},
        "objective": float(fitness),
        "objective_name": "FPlanar: sum of distances at its own angles",
        "evaluations": int(func.callback),
        "seconds": seconds,
        "threads": 1,
        "pose": pose,
    }))


if __name__ == "__main__":
    main()
