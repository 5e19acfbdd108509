"""The Ray recipe of docs/guide/python.md: a design study of the bundled
four-bar on Ray, from a laptop to a cluster. Run from the repository's
root: `python python/examples/ray_study.py [ADDRESS]` (no address: a local
Ray on this machine's cores; `auto` on a cluster's node; `ray://HEAD:10001`
from outside it). Checked with `mypy --strict` and run in CI."""

import pathlib
import sys

import numpy as np
import ray

import dofplan
import dofplan.ray as dray
from dofplan import study

root = pathlib.Path(__file__).resolve().parents[2]
m = dofplan.load(root / "mechanisms" / "fourbar.toml")
ray.init(address=sys.argv[1] if len(sys.argv) > 1 else None, include_dashboard=False)

# Where should the ground pivot D and the coupler point go for P to pass
# near these points? 400 random candidates, each run over its sweep.
targets = np.array([[2.6, 3.4], [3.4, 4.0], [2.0, 4.6], [1.0, 3.0]])
samples = study.random({"D.x": (3.5, 4.5), "D.y": (-0.5, 0.5), "coupler.P.y": (3.0, 4.5)}, 400, seed=1)
found = dray.sweep(m, samples, study.PathError("coupler.P", targets), steps=181)
print(f"best of {len(found)}: {found.parameters(found.best)}, score {found.scores[found.best]:.4f}")

# How far do the coupler point's paths stray when every point is off by
# up to 0.01? analyze --sensitivity --tolerance 0.01 --monte-carlo 500's numbers.
spread = dray.tolerance(m, 0.01, 500, seed=1)
print(f"tolerance 0.01: largest {spread.largest['coupler.P']:.4f}, mean {spread.mean['coupler.P']:.4f}")

# Synthesis from four seeds, the best first.
runs = dray.restarts(m, [1, 2, 3, 4], path=targets, marker="coupler.P", evaluations=2000, time_limit=60.0)
print(f"synthesis: best rms {runs.best.error['rms']:.4f} (seed {runs.seeds[0]})")
ray.shutdown()
