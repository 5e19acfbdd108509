"""The ten-line start of docs/guide/python.md: load the bundled four-bar,
run its sweep, read a path and its speed, and draw it. Run from the
repository's root: `python python/examples/quickstart.py`. Checked with
`mypy --strict` in CI against the package's types."""

import pathlib

import numpy as np

import dofplan

root = pathlib.Path(__file__).resolve().parents[2]
m = dofplan.load(root / "mechanisms" / "fourbar.toml")
print(m, "mobility:", m.check().mobility)
theta = np.linspace(0.0, 360.0, 721)
r = m.rates(theta, rate=2.0 * np.pi)  # one turn per unit of time
path = r.marker("coupler.P")
assert r.velocity is not None
speed = np.linalg.norm(r.velocity[:, r.marker_names.index("coupler.P")], axis=1)
print(f"coupler.P: {len(path)} points, fastest {speed.max():.3f} at theta = {theta[speed.argmax()]:.1f} deg")
svg: str = r.svg()
print(f"the sweep drawn: {len(svg)} bytes of SVG")
