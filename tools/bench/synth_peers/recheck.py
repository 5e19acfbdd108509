#!/usr/bin/env python3
"""Re-check a four-bar by dofplan's own simulation (tools/bench/synth_peers).

Every tool's final four-bar is given as the pose of its five points on the
assembly branch its own objective used, at the crank angle that becomes
dofplan's input 0:

    A  crank's ground pivot      D  rocker's ground pivot
    B  crank-coupler joint       C  coupler-rocker joint
    P  the coupler point traced

``write_fourbar`` writes a copy of mechanisms/fourbar.toml with those
coordinates (only the numbers of the drawing change: the crank stays the
input, driven at joint A), so dofplan keeps the branch of that drawn pose
(``simulate``'s default ``--branch keep``).  ``recheck`` then runs

* ``dofplan check --json``: does the crank turn fully (its assembly range is
  the whole turn), and the Grashof class of the loop; the crank counts as
  turning fully only if the dense sweep below also solves every frame on
  the drawn branch;
* ``dofplan simulate --csv`` densely: 36,001 frames from 0 to 360 degrees
  (36,000 crank steps), and E = the sum over the targets of the squared
  distance to the nearest simulated point of coupler.P (free timing), or the
  sum of squared distances at the targets' own inputs (given timing).

Only frames dofplan reports "solved" count; a crank that does not turn fully
is reported as such (E over the frames it reaches).

CLI (for one file): recheck.py DOFPLAN FILE.toml TARGET.csv
"""

import csv
import json
import math
import os
import re
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
FOURBAR = os.path.join(REPO, "mechanisms", "fourbar.toml")
DENSE_STEPS = 36000


def read_targets(path):
    """(inputs or None, points (n, 2)) from a target CSV: x,y or input,x,y;
    '#' comments and a header line of words allowed."""
    rows = []
    with open(path) as f:
        for line in f:
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            try:
                rows.append([float(v) for v in line.split(",")])
            except ValueError:
                continue  # the header
    arr = np.array(rows, dtype=float)
    if arr.shape[1] == 3:
        return arr[:, 0].copy(), arr[:, 1:].copy()
    return None, arr


def write_fourbar(points, out, note=""):
    """A copy of mechanisms/fourbar.toml drawn at ``points`` (dict name ->
    (x, y) for A, B, C, D, P): every marker of that name in every body gets
    the new coordinates (the two markers of a joint coincide), comments and
    key order kept."""
    with open(FOURBAR) as f:
        text = f.read()

    def sub(m):
        x, y = points[m.group(1)]
        return "%s = [%r, %r]" % (m.group(1), float(x), float(y))

    body = re.sub(r"\b([ABCDP]) = \[[^\]]*\]", sub, text)
    head = ("# Written by tools/bench/synth_peers for a re-check%s; a copy of mechanisms/fourbar.toml\n"
            "# with the drawing's numbers replaced (its comments below describe the original).\n"
            % (": " + note if note else ""))
    with open(out, "w") as f:
        f.write(head + body)
    return out


def check(dofplan, path):
    """(full_turn, grashof class) from ``dofplan check --json``."""
    p = subprocess.run([dofplan, "check", path, "--json"], capture_output=True, text=True)
    if p.returncode != 0:
        return False, "check failed: " + (p.stderr.strip().splitlines() or ["?"])[-1]
    d = json.loads(p.stdout)
    ranges = d.get("ranges", {}).get("theta", [])
    full = any(lo <= -180.0 + 1e-9 and hi >= 180.0 - 1e-9 for lo, hi in ranges)
    g = d.get("grashof") or [{}]
    return full, g[0].get("class", "?")


def simulate(dofplan, path, lo, hi, steps):
    """coupler.P per frame, (steps, 2), NaN where the frame is not solved."""
    cmd = [dofplan, "simulate", path, "--from", repr(float(lo)), "--to", repr(float(hi)),
           "--steps", str(int(steps)), "--csv"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError("%s: %s" % (" ".join(cmd), p.stderr.strip()[-300:]))
    rows = csv.reader(p.stdout.splitlines())
    head = next(rows)
    st, cx, cy = head.index("status"), head.index("coupler.P.x"), head.index("coupler.P.y")
    out = []
    for r in rows:
        if r[st] == "solved":
            out.append((float(r[cx]), float(r[cy])))
        else:
            out.append((math.nan, math.nan))
    return np.array(out, dtype=float)


def nearest_sum_sq(curve, targets):
    """Sum over targets of the squared distance to the nearest curve point."""
    c = curve[np.isfinite(curve).all(axis=1)]
    if len(c) == 0:
        return math.inf
    d2 = ((targets[:, None, :] - c[None, :, :]) ** 2).sum(axis=2)
    return float(d2.min(axis=1).sum())


def given_sum_sq(dofplan, path, inputs, targets):
    """Sum of squared distances at the targets' own inputs (degrees from the
    drawing), each frame simulated by dofplan."""
    n = len(inputs)
    steps = np.diff(inputs)
    if n > 1 and np.allclose(steps, steps[0]):
        pts = simulate(dofplan, path, inputs[0], inputs[-1], n)
    else:
        pts = np.vstack([simulate(dofplan, path, t, t, 1) for t in inputs])
    if not np.isfinite(pts).all():
        return math.inf
    return float(((pts - targets) ** 2).sum())


def recheck(dofplan, path, target_csv):
    """dict: full_turn, check_turns_fully, grashof, E (the target file's
    timing), solved_frames."""
    inputs, targets = read_targets(target_csv)
    full, cls = check(dofplan, path)
    res = {"full_turn": full, "check_turns_fully": full, "grashof": cls}
    try:
        curve = simulate(dofplan, path, 0.0, 360.0, DENSE_STEPS + 1)
        res["solved_frames"] = int(np.isfinite(curve).all(axis=1).sum())
        # Turning fully needs both: check's assembly range, and every frame
        # of the dense sweep solved on the drawn branch (near a change point
        # check can report a full range that the drawn branch does not keep).
        res["full_turn"] = full and res["solved_frames"] == DENSE_STEPS + 1
        if inputs is None:
            res["E"] = nearest_sum_sq(curve, targets)
        else:
            res["E"] = given_sum_sq(dofplan, path, inputs, targets)
    except RuntimeError as e:
        res["E"] = math.inf
        res["error"] = str(e)
    return res


if __name__ == "__main__":
    if len(sys.argv) != 4:
        raise SystemExit("usage: recheck.py DOFPLAN FILE.toml TARGET.csv")
    print(json.dumps(recheck(*sys.argv[1:])))
