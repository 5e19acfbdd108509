"""The package says what the command line says: every bundled file's sweep
from Python against `dofplan simulate --json` (positions to 1e-12, the same
statuses), `check` against `dofplan check --json`, and bad files' errors
against the text `dofplan check` prints for them.

The CLI is the binary in $DOFPLAN_BIN (`.ci/run` sets it to its release
build), else the repository's target/release or target/debug one.
"""

import glob
import json
import os
import pathlib
import subprocess

import numpy as np
import pytest

import dofplan

ROOT = pathlib.Path(__file__).resolve().parents[2]
MECHANISMS = ROOT / "mechanisms"
FILES = sorted(glob.glob(str(MECHANISMS / "*.toml"))) + sorted(glob.glob(str(MECHANISMS / "spatial" / "*.toml")))


def cli():
    given = os.environ.get("DOFPLAN_BIN")
    if given:
        return given
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "dofplan"
        if p.exists():
            return str(p)
    raise RuntimeError(
        "no dofplan binary: build it (cargo build -p dofplan) or set DOFPLAN_BIN"
    )


def run_cli(*args):
    done = subprocess.run([cli(), *map(str, args)], capture_output=True, text=True, env={**os.environ, "NO_COLOR": "1"})
    return done.returncode, done.stdout, done.stderr


@pytest.mark.parametrize("path", FILES, ids=lambda p: pathlib.Path(p).stem)
def test_a_sweep_from_python_is_the_cli_s(path):
    m = dofplan.load(path)
    steps = min(m.sweep["steps"], 91)
    code, out, err = run_cli("simulate", path, "--json", "--steps", steps)
    assert code == 0, err
    frames = json.loads(out)["frames"]
    r = m.simulate(steps=steps)
    assert len(frames) == len(r)
    for k, f in enumerate(frames):
        assert f["status"] == r.status_of(k), (k, f["status"])
        if f["markers"] is None:
            # No pose of the run yet: null there, NaN here.
            assert f["status"] == "unreached" and np.isnan(r.markers[k]).all() and np.isnan(r.poses[k]).all()
            continue
        for name, at in f["markers"].items():
            got = r.marker(name)[k]
            if f["status"] in ("solved", "stretched", "limited", "searched"):
                assert np.max(np.abs(got - np.asarray(at))) <= 1e-12 * max(1.0, np.max(np.abs(at))), (k, name)


@pytest.mark.parametrize("path", FILES, ids=lambda p: pathlib.Path(p).stem)
def test_check_from_python_is_the_cli_s(path):
    code, out, _ = run_cli("check", path, "--json")
    c = dofplan.load(path).check()
    assert c.ok == (code == 0)
    assert c.to_dict() == json.loads(out)


# Small edits of the bundled four-bar, one line each (the kinds of bad input
# tests/inputs/bad_input.rs covers): the exception's message is the text
# `dofplan check` prints for the same file.
FOURBAR = (MECHANISMS / "fourbar.toml").read_text()
EDITS = {
    "syntax": ("fixed = true", "fixed = tru"),
    "unknown key": ("fixed = true", "fixed = true\ncolour = 1"),
    "unknown marker": ('"crank.B"', '"crank.Q"'),
    "unknown body": ('"rocker.C"', '"rockr.C"'),
    "bad kind": ('kind = "revolute"', 'kind = "hinge"'),
    "joint open": ("C = [4.5, 2.5], D = [4, 0]", "C = [4.5, 2.9], D = [4, 0]"),
    "no ground": ("fixed = true", "fixed = false"),
    "input on nothing": ('joint = "A"', 'joint = "Z"'),
    "sweep steps": ("steps = 361", "steps = 0"),
    "nan": ("D = [4, 0] }", "D = [nan, 0] }"),
}


@pytest.mark.parametrize("edit", sorted(EDITS))
def test_a_bad_file_raises_what_check_prints(edit, tmp_path):
    old, new = EDITS[edit]
    assert old in FOURBAR, edit
    text = FOURBAR.replace(old, new, 1)
    path = tmp_path / "fourbar.toml"
    path.write_text(text)
    code, _, err = run_cli("check", path)
    assert code != 0, edit
    with pytest.raises(dofplan.MechanismError) as e:
        dofplan.load(path)
    assert str(e.value).strip() == err.strip(), edit
    d = e.value.diagnostics[0]
    assert d["file"] == str(path)
    assert d["line"] is not None or d["path"] is not None or "file" in d, edit
