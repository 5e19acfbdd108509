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


# Every bad text of the Rust loader tests (tests/inputs/bad_input.rs): its
# base four-bar (TOML and JSON) and each `toml_err(&fourbar(&[...]))` or
# `json_err(&fourbar_json(&[...]))` case's line edits, read out of the Rust
# source so the two test suites cannot drift apart. Each must raise
# MechanismError from Python with the text `dofplan check` prints.
BAD_INPUT_RS = ROOT / "tests" / "inputs" / "bad_input.rs"


def _rust_literal(src, i):
    """The Rust string literal starting at src[i] (plain or raw) and the index after it."""
    if src.startswith("r", i):
        j = i + 1
        hashes = 0
        while src[j] == "#":
            hashes += 1
            j += 1
        assert src[j] == '"', src[i : i + 20]
        end = src.index('"' + "#" * hashes, j + 1)
        return src[j + 1 : end], end + 1 + hashes
    assert src[i] == '"', src[i : i + 20]
    out, j = [], i + 1
    while src[j] != '"':
        c = src[j]
        if c == "\\":
            n = src[j + 1]
            if n == "\n":
                # A line continuation: the newline and the next line's indent go.
                j += 2
                while src[j] in " \t":
                    j += 1
                continue
            if n == "u":
                end = src.index("}", j)
                out.append(chr(int(src[j + 3 : end], 16)))
                j = end + 1
                continue
            out.append({"n": "\n", "t": "\t", "\\": "\\", '"': '"', "'": "'", "0": "\0", "r": "\r"}[n])
            j += 2
            continue
        out.append(c)
        j += 1
    return "".join(out), j + 1


def _skip(src, i):
    """Past whitespace and comments."""
    while True:
        while src[i] in " \t\n,":
            i += 1
        if src.startswith("//", i):
            i = src.index("\n", i)
        elif src.startswith("/*", i):
            i = src.index("*/", i) + 2
        else:
            return i


def _rust_base(src, name):
    i = src.index(f"const {name}:")
    i = src.index("= [", i) + 3
    lines = []
    while True:
        i = _skip(src, i)
        if src[i] == "]":
            return lines
        text, i = _rust_literal(src, i)
        lines.append(text)


def _rust_edits(src, i):
    """The `[(n, "text"), ...]` list starting at src[i] == '['."""
    edits, i = [], i + 1
    while True:
        i = _skip(src, i)
        if src[i] == "]":
            return edits
        assert src[i] == "(", src[i : i + 40]
        i = _skip(src, i + 1)
        j = i
        while src[j].isdigit():
            j += 1
        n = int(src[i:j])
        i = _skip(src, j)
        text, i = _rust_literal(src, i)
        i = _skip(src, i)
        assert src[i] == ")", src[i : i + 40]
        edits.append((n, text))
        i += 1


def _rust_bad_cases():
    src = BAD_INPUT_RS.read_text()
    bases = {"toml": _rust_base(src, "FOURBAR"), "json": _rust_base(src, "FOURBAR_JSON")}
    cases = []
    for call, fmt in (("toml_err(&fourbar(&", "toml"), ("json_err(&fourbar_json(&", "json")):
        start = 0
        while (k := src.find(call, start)) >= 0:
            line = src.count("\n", 0, k) + 1
            lines = list(bases[fmt])
            for n, text in _rust_edits(src, k + len(call)):
                lines[n - 1] = text
            cases.append((f"bad_input.rs:{line}", fmt, "\n".join(lines) + "\n"))
            start = k + 1
    return cases


RUST_BAD = _rust_bad_cases()


def test_every_bad_case_of_the_rust_tests_is_read():
    # As many as the Rust file has calls: the reader above cannot silently skip some.
    src = BAD_INPUT_RS.read_text()
    assert len(RUST_BAD) == src.count("toml_err(&fourbar(&") + src.count("json_err(&fourbar_json(&") >= 40


@pytest.mark.parametrize("case", RUST_BAD, ids=lambda c: c[0])
def test_a_bad_case_of_the_rust_tests_raises_what_check_prints(case, tmp_path):
    where, fmt, text = case
    path = tmp_path / f"t.{fmt}"
    path.write_text(text)
    code, _, err = run_cli("check", path)
    assert code != 0, where
    with pytest.raises(dofplan.MechanismError) as e:
        dofplan.load(path)
    assert str(e.value).strip() == err.strip(), where
    with pytest.raises(dofplan.MechanismError) as again:
        dofplan.loads(text, format=fmt, name=str(path))
    assert str(again.value) == str(e.value)
    assert e.value.diagnostics and all(d["file"] == str(path) for d in e.value.diagnostics)


@pytest.mark.parametrize("name", ["slider_crank_press", "fourbar_weights", "arc_yoke_press", "cardan_torque", "excavator_load"])
@pytest.mark.parametrize("rate", [None, 2.0])
def test_forces_are_the_cli_s(name, rate):
    path = MECHANISMS / "loads" / f"{name}.toml"
    args = ["analyze", path, "--forces", "--json", "--steps", 37]
    if rate is not None:
        args += ["--rate", rate]
    code, out, err = run_cli(*args)
    assert code == 0, err
    got = dofplan.load(path).forces(rate=rate, steps=37)
    assert got == json.loads(out)
    assert got["forces"] == ("static" if rate is None else "kinetostatic")
    first = next(iter(got["frames"][0]["input_force"]))
    assert all(isinstance(f["input_force"][first], float) for f in got["frames"])


@pytest.mark.parametrize("name", ["fourbar_weights", "cardan_torque"])
def test_forces_speeding_up_are_the_cli_s(name):
    path = MECHANISMS / "loads" / f"{name}.toml"
    code, out, err = run_cli("analyze", path, "--forces", "--json", "--steps", 19, "--rate", 2, "--acceleration", -4)
    assert code == 0, err
    got = dofplan.load(path).forces(rate=2, acceleration=-4, steps=19)
    assert got == json.loads(out)
    assert (got["rate"], got["acceleration"]) == (2.0, -4.0)
    with pytest.raises(ValueError, match="needs a rate"):
        dofplan.load(path).forces(acceleration=1.0)


def test_forces_of_a_file_without_loads_raise_the_cli_s_message():
    code, _, err = run_cli("analyze", MECHANISMS / "fourbar.toml", "--forces")
    assert code != 0
    with pytest.raises(dofplan.DofplanError) as e:
        dofplan.load(MECHANISMS / "fourbar.toml").forces()
    assert str(e.value).strip() == err.strip()
