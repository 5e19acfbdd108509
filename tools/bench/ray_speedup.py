#!/usr/bin/env python3
"""How a design study scales from one local Ray worker to two
(docs/guide/python.md's Ray table), in one run.

Set-up (a venv with the package and its Ray extra):

    python3 -m venv /tmp/pyray && /tmp/pyray/bin/pip install './python[ray]'
    /tmp/pyray/bin/python tools/bench/ray_speedup.py [--candidates 800] [--passes 3]

The study: random samples of the four-bar's ground pivot D and coupler
point P (``dofplan.study.random``), each candidate drawn, planned and run
over 721 frames of its sweep and scored by the built-in path error
(``dofplan.study.PathError``). Timed three ways on the same candidates:
in this process (``dofplan.study.sweep``), and as Ray tasks
(``dofplan.ray.sweep``) with Ray started on 1 CPU and then on 2 (a fresh
instance each, warmed up by one study first, so worker start-up is not
timed). Medians over passes. Every Ray run's scores are checked equal to
the single process's, to the bit.
"""

import argparse
import os
import statistics
import sys
import time

import numpy as np
import ray

import dofplan
import dofplan.ray as dray
from dofplan import study

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--candidates", type=int, default=800)
    ap.add_argument("--passes", type=int, default=3)
    ap.add_argument("--steps", type=int, default=721)
    args = ap.parse_args()

    m = dofplan.load(os.path.join(ROOT, "mechanisms", "fourbar.toml"))
    targets = m.simulate(steps=37).marker("coupler.P")[::4] + [0.02, -0.01]
    score = study.PathError("coupler.P", targets)
    samples = study.random({"D.x": (3.6, 4.4), "D.y": (-0.3, 0.3), "coupler.P.y": (3.0, 4.0)}, args.candidates, seed=1)

    def timed(run):
        times, out = [], None
        for _ in range(args.passes):
            t = time.perf_counter()
            out = run()
            times.append(time.perf_counter() - t)
        return statistics.median(times), out

    local_s, expected = timed(lambda: study.sweep(m, samples, score, steps=args.steps))
    rows = [("in process (dofplan.study)", local_s)]
    for cpus in (1, 2):
        ray.init(num_cpus=cpus, include_dashboard=False, log_to_driver=False)
        dray.sweep(m, samples, score, steps=args.steps)  # workers started
        s, got = timed(lambda: dray.sweep(m, samples, score, steps=args.steps))
        ray.shutdown()
        if not np.array_equal(got.scores, expected.scores, equal_nan=True):
            sys.exit(f"Ray on {cpus} CPU(s) scored differently from the single process")
        rows.append((f"Ray, {cpus} local worker{'s' if cpus > 1 else ''}", s))

    per = args.candidates
    print(f"{args.candidates} four-bar candidates x {args.steps} frames, median of {args.passes} passes, {os.cpu_count()} cores")
    print(f"{'run':<30} {'seconds':>8} {'ms/candidate':>13} {'vs 1 worker':>12}")
    one = rows[1][1]
    for name, s in rows:
        print(f"{name:<30} {s:8.3f} {1e3 * s / per:13.3f} {one / s:11.2f}x")


if __name__ == "__main__":
    main()
