#!/usr/bin/env python3
"""The Python package's speed, side by side with pylinkage 1.3 and with the
Rust batch path, in one run (docs/guide/python.md's speed table).

Set-up (a venv with the package, pylinkage and numba):

    python3 -m venv /tmp/pyspeed && /tmp/pyspeed/bin/pip install ./python pylinkage==1.3.0 numba
    /tmp/pyspeed/bin/python tools/bench/python_speed.py [--passes 15]

Rows:

- **sweep** (fourbar, stress_50): the file's own sweep (361 frames) from
  Python, ``m.simulate(x)`` (arrays of every pose and marker, residuals)
  against pylinkage's fastest path on the same mechanism and frames, its
  numba kernel called directly (``tools/bench/pylinkage.py`` builds the
  linkage and explains the choice). Both after warm-up; per frame, median
  over passes. The two are checked against each other: every point
  pylinkage computes against the dofplan markers it stands for.
- **one frame**: ``m.frame(theta)`` on the four-bar (the live pose moved
  one frame: the markers' array and the status), and ``m.simulate([theta])``
  (a run of one frame: every array, the Result built).
- **10^6 frames**: ``m.simulate(x)`` of a million four-bar frames against
  the Rust batch path on the same frames (``solve_batch_parallel`` on the
  interpreter, every core, nothing read off: the extension's
  ``_batch_seconds`` hook times it in Rust).

Targets (the issue's): >= 50x pylinkage on every sweep row; one frame from
Python <= 2 us; the 10^6-frame sweep within 10% of the Rust batch per frame.
The table says met or not for each.
"""

import argparse
import importlib.util
import json
import os
import statistics
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.realpath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
# The peer script is named pylinkage.py: load it by path, under another
# name, so that `import pylinkage` inside it finds the package.
sys.path[:] = [p for p in sys.path if os.path.realpath(p or os.curdir) != HERE]
_spec = importlib.util.spec_from_file_location("pylinkage_peer", os.path.join(HERE, "pylinkage.py"))
peer = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(peer)

import dofplan  # noqa: E402


def median_per_frame(f, frames, passes, target_s=0.02):
    """Median over `passes` of a pass's time per frame (us); a pass repeats
    `f` enough to last about `target_s`."""
    f()
    t0 = time.perf_counter()
    f()
    one = time.perf_counter() - t0
    calls = max(1, int(target_s / max(one, 1e-9)))
    samples = []
    for _ in range(passes):
        t0 = time.perf_counter_ns()
        for _ in range(calls):
            f()
        samples.append((time.perf_counter_ns() - t0) / 1e3 / (calls * frames))
    return statistics.median(samples), min(samples), max(samples)


def sweep_row(name, passes):
    path = os.path.join(REPO, "mechanisms", name + ".toml")
    m = dofplan.load(path)
    x = m.sweep_inputs()
    frames = len(x)
    ours = median_per_frame(lambda: m.simulate(x), frames, passes)
    with open(path, "rb") as fh:
        mech = peer.tomllib.load(fh)
    built = peer.build(mech)
    theirs = median_per_frame(lambda: peer.run(built, frames), frames, passes)
    # Checked against each other: pylinkage's rows against our markers.
    r = m.simulate(x)
    ref = {k: r.marker(k) for k in r.marker_names}
    diff = peer.max_diff(built, peer.run(built, frames), ref)
    return ours, theirs, diff


def one_frame(passes):
    """A frame at a time from Python: `m.frame(theta)` (markers and status
    from the live pose), and `m.simulate([theta])` (a run of one frame,
    every array and the Result)."""
    m = dofplan.load(os.path.join(REPO, "mechanisms", "fourbar.toml"))
    thetas = iter(np.tile(np.linspace(0.0, 359.0, 360), 100_000))
    live = median_per_frame(lambda: m.frame(next(thetas)), 1, passes, target_s=0.05)
    run = median_per_frame(lambda: m.simulate([30.0]), 1, passes, target_s=0.05)
    return live, run


def million(passes):
    m = dofplan.load(os.path.join(REPO, "mechanisms", "fourbar.toml"))
    x = np.linspace(0.0, 3600.0, 1_000_000).reshape(-1, 1)
    ours, rust = [], []
    for _ in range(passes):
        t0 = time.perf_counter()
        m.simulate(x)
        ours.append((time.perf_counter() - t0) * 1e6 / len(x))
        rust.append(m._m._batch_seconds(x) * 1e6 / len(x))
    return ours, rust


def fmt(t):
    return "%.3f (%.3f-%.3f)" % t


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--passes", type=int, default=15)
    ap.add_argument("--json", action="store_true", help="the figures as JSON")
    args = ap.parse_args()
    rows = []
    print("Python package speed, us per frame: median (min-max) of %d passes" % args.passes)
    print("%-22s %-22s %-22s %-9s %s" % ("row", "dofplan (Python)", "peer", "ratio", "target"))
    for name in ("fourbar", "stress_50"):
        ours, theirs, diff = sweep_row(name, args.passes)
        ratio = theirs[0] / ours[0]
        met = "met" if ratio >= 50 else "not met"
        print("%-22s %-22s %-22s %-9s >= 50x pylinkage: %s (max |diff| %.1e)"
              % (name + " sweep", fmt(ours), fmt(theirs) + " pl", "%.1fx" % ratio, met, diff))
        rows.append({"row": name + " sweep", "dofplan_us": ours[0], "pylinkage_us": theirs[0],
                     "ratio": ratio, "max_diff": diff})
    live, run = one_frame(args.passes)
    print("%-22s %-22s %-22s %-9s <= 2 us: %s" % ("one frame, m.frame", fmt(live), "", "",
                                                    "met" if live[0] <= 2.0 else "not met"))
    print("%-22s %-22s" % ("one frame, m.simulate", fmt(run)))
    rows.append({"row": "one frame", "frame_us": live[0], "simulate_us": run[0]})
    ours, rust = million(max(3, args.passes // 5))
    o, r = statistics.median(ours), statistics.median(rust)
    print("%-22s %-22s %-22s %-9s within 10%%: %s" % (
        "10^6 frames (fourbar)", "%.4f (%.4f-%.4f)" % (o, min(ours), max(ours)),
        "%.4f (%.4f-%.4f) Rust" % (r, min(rust), max(rust)), "%.2fx" % (o / r),
        "met" if o <= 1.1 * r else "not met"))
    rows.append({"row": "10^6 frames", "dofplan_us": o, "rust_batch_us": r})
    if args.json:
        print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
