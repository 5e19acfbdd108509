"""The example notebook (python/examples/quickstart.ipynb) runs from top to
bottom in a fresh kernel, and its mechanism and result show themselves as
SVG, so the guide's notebook cannot rot."""

import pathlib

import pytest

nbclient = pytest.importorskip("nbclient")
nbformat = pytest.importorskip("nbformat")

NOTEBOOK = pathlib.Path(__file__).resolve().parents[1] / "examples" / "quickstart.ipynb"


def test_the_example_notebook_runs_and_shows_svg():
    nb = nbformat.read(NOTEBOOK, as_version=4)
    nbclient.NotebookClient(nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}).execute()
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outputs if o.output_type == "error"]
    svgs = [o for o in outputs if "image/svg+xml" in o.get("data", {})]
    # The mechanism's drawing and the result's frames.
    assert len(svgs) >= 2, [list(o.get("data", {})) for o in outputs]
