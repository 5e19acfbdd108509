"""Design studies in one process (`dofplan.study`): candidates drawn at new
parameter values, sweeps over grids and random samples, the Monte-Carlo
tolerance study against `dofplan analyze --sensitivity --tolerance
--monte-carlo` to the bit, and synthesis restarts against `dofplan.synth`
run seed by seed. `test_ray.py` runs the same studies as Ray tasks."""

import json
import math

import numpy as np
import pytest

import dofplan
from dofplan import study

from test_cli_agreement import MECHANISMS, run_cli

FOURBAR = MECHANISMS / "fourbar.toml"


def fourbar():
    return dofplan.load(FOURBAR)


def test_parameters_are_the_cli_s():
    for path in (FOURBAR, MECHANISMS / "spatial" / "rssr.toml"):
        m = dofplan.load(path)
        code, out, err = run_cli("analyze", path, "--sensitivity", "--json", "--steps", 3)
        assert code == 0, err
        cli = json.loads(out)["parameters"]
        assert list(m.parameters.items()) == [(p["name"], p["drawn"]) for p in cli]


def test_a_candidate_is_the_file_with_its_points_moved_to_the_last_bit():
    m = fourbar()
    assert m.with_parameters({}).source() == m.source()
    v = 4.123456789012345
    c = m.with_parameters({"D.x": v})
    assert c.parameters["D.x"] == v and c.parameters["D.y"] == 0.0
    # Both markers of joint D moved; nothing else in the text changed.
    changed = [(a, b) for a, b in zip(m.source()[0].splitlines(), c.source()[0].splitlines()) if a != b]
    assert len(changed) == 2 and all(repr(v) in b for _, b in changed)
    # The candidate runs with every joint closed, its ground pivot where it was put.
    r = c.simulate(steps=73, check=True)
    assert np.nanmax(r.residual) < 1e-12
    assert np.allclose(r.marker("ground.D")[np.all(np.isfinite(r.marker("ground.D")), axis=1)], [v, 0.0], atol=0)


def test_a_candidate_s_path_is_the_closed_form_four_bar_s():
    # The coupler point of a crank-rocker from the circle intersection by
    # hand: B on the crank, C where |BC| and |DC| meet on the drawn branch.
    m = fourbar()
    c = m.with_parameters({"D.x": 4.4, "coupler.P.y": 3.2})
    r = c.simulate([0.0, 30.0, 60.0, 90.0], check=True)
    pts = {n: np.array([c.parameters[f"{n}.x"], c.parameters[f"{n}.y"]]) for n in ("A", "B", "C", "D", "coupler.P")}
    crank = np.linalg.norm(pts["B"] - pts["A"])
    coupler = np.linalg.norm(pts["C"] - pts["B"])
    rocker = np.linalg.norm(pts["C"] - pts["D"])
    b0 = math.atan2(*(pts["B"] - pts["A"])[::-1])
    # P in the coupler's frame (along BC, and across it).
    u = (pts["C"] - pts["B"]) / coupler
    w = np.array([-u[1], u[0]])
    along, across = (pts["coupler.P"] - pts["B"]) @ u, (pts["coupler.P"] - pts["B"]) @ w
    def cross(p, q):
        return p[0] * q[1] - p[1] * q[0]

    side = np.sign(cross(pts["C"] - pts["B"], pts["D"] - pts["B"]))
    for k, deg in enumerate([0.0, 30.0, 60.0, 90.0]):
        t = b0 + math.radians(deg)
        B = pts["A"] + crank * np.array([math.cos(t), math.sin(t)])
        e = pts["D"] - B
        L = np.linalg.norm(e)
        x = (coupler**2 - rocker**2 + L**2) / (2 * L)
        h = math.sqrt(coupler**2 - x**2)
        n = np.array([-e[1], e[0]]) / L
        for s in (1.0, -1.0):
            C = B + x * e / L + s * h * n
            if np.sign(cross(C - B, pts["D"] - B)) == side:
                break
        U = (C - B) / coupler
        P = B + along * U + across * np.array([-U[1], U[0]])
        assert np.allclose(r.marker("coupler.P")[k], P, atol=1e-12), (deg, r.marker("coupler.P")[k], P)


def test_grid_and_random_samples():
    g = study.grid({"D.x": [3.5, 4.0], "coupler.P.y": [3.0, 3.5, 4.0]})
    assert g.names == ["D.x", "coupler.P.y"] and len(g) == 6
    assert g.values.tolist() == [[3.5, 3.0], [3.5, 3.5], [3.5, 4.0], [4.0, 3.0], [4.0, 3.5], [4.0, 4.0]]
    a = study.random({"D.x": (3.5, 4.5), "D.y": (-0.2, 0.2)}, 50, seed=7)
    b = study.random({"D.x": (3.5, 4.5), "D.y": (-0.2, 0.2)}, 50, seed=7)
    assert np.array_equal(a.values, b.values) and a.values.shape == (50, 2)
    assert a.values[:, 0].min() >= 3.5 and a.values[:, 0].max() <= 4.5
    assert not np.array_equal(a.values, study.random({"D.x": (3.5, 4.5), "D.y": (-0.2, 0.2)}, 50, seed=8).values)
    with pytest.raises(ValueError, match="low above high"):
        study.random({"D.x": (2, 1)}, 3)
    with pytest.raises(ValueError, match="at least one value"):
        study.grid({"D.x": []})


def test_path_error_by_hand():
    class R:
        def __init__(self, path):
            self.path = np.asarray(path, dtype=float)

        def marker(self, name):
            return self.path

    path = [[0, 0], [1, 0], [np.nan, np.nan], [3, 0]]
    free = study.PathError("p", [[0, 1], [2.5, 0.5]])
    # (0,1) is 1 from (0,0); (2.5,0.5) is 0.5 from (3,0) in each axis.
    assert free(R(path)) == 1.0 + 0.5
    given = study.PathError("p", [[0, 1], [1, 0], [2, 0], [3, 0]], timing="given")
    assert given(R(path)) == math.inf
    assert given(R([[0, 0], [1, 0], [2, 2], [3, 0]])) == 1.0 + 4.0
    assert free(R([[np.nan, np.nan]])) == math.inf


def test_a_sweep_scores_each_candidate_as_running_it_by_hand_does():
    m = fourbar()
    targets = m.simulate(steps=37).marker("coupler.P")[::4]
    score = study.PathError("coupler.P", targets)
    s = study.grid({"D.x": [3.8, 4.0, 4.2], "coupler.P.y": [3.4, 3.5], "B.x": [1.0, 4.0], "B.y": [1.0, 0.0]})
    found = study.sweep(m, s, score, steps=73, chunk_size=5)
    assert len(found) == 24
    for i in range(len(s)):
        p = found.parameters(i)
        if (p["B.x"], p["B.y"]) == (p["D.x"], 0.0):
            # B put on D: the coupler's circles coincide, no plan.
            assert math.isnan(found.scores[i]) and "cannot be met at the drawn pose" in found.errors[i]
            continue
        by_hand = score(m.with_parameters(p).simulate(steps=73))
        assert found.errors[i] is None and found.scores[i] == by_hand
    # The drawing's own path is on the grid: it scores zero, and wins.
    drawn = [i for i in range(len(s)) if found.parameters(i) == {"D.x": 4.0, "coupler.P.y": 3.5, "B.x": 1.0, "B.y": 1.0}]
    assert found.best == drawn[0] and found.scores[found.best] < 1e-24
    # Chunks change nothing.
    again = study.sweep(m, s, score, steps=73, chunk_size=1)
    assert np.array_equal(again.scores, found.scores, equal_nan=True) and again.errors == found.errors


def test_a_sweep_names_what_is_not_a_parameter():
    with pytest.raises(KeyError, match="E.x: not design parameters of fourbar"):
        study.sweep(fourbar(), study.grid({"E.x": [1.0]}), lambda r: 0.0)


@pytest.mark.parametrize("path", [FOURBAR, MECHANISMS / "spatial" / "rssr.toml"], ids=lambda p: p.stem)
def test_the_tolerance_study_is_the_cli_s_to_the_bit(path):
    m = dofplan.load(path)
    code, out, err = run_cli(
        "analyze", path, "--sensitivity", "--tolerance", 0.01, "--monte-carlo", 30, "--seed", 5, "--steps", 37, "--json"
    )
    assert code == 0, err
    cli = json.loads(out)["monte_carlo"]
    t = study.tolerance(m, 0.01, 30, seed=5, steps=37, chunk_size=7)
    assert t.to_dict() == cli
    assert t.deviations.shape == (30, len(t.markers)) and t.candidates.shape == (30, len(m.parameters))
    assert np.all(np.abs(t.candidates - np.array(list(m.parameters.values()))) <= 0.01)
    for k, name in enumerate(t.markers):
        assert t.largest[name] == np.nanmax(t.deviations[:, k])
    one = study.tolerance(m, 0.01, 30, seed=5, steps=37, chunk_size=30)
    assert np.array_equal(one.deviations, t.deviations) and one.to_dict() == cli


def test_restarts_are_synth_run_seed_by_seed():
    m = fourbar()
    targets = m.simulate([0.0, 60.0, 120.0, 180.0, 240.0, 300.0]).marker("coupler.P") + [0.05, 0.0]
    options = dict(path=targets, marker="coupler.P", vary=["D", "coupler.P"], evaluations=600, time_limit=60.0)
    found = study.restarts(m, [3, 1, 2], **options)
    alone = {s: dofplan.synth(m, seed=s, **options) for s in (1, 2, 3)}
    assert sorted(found.seeds) == [1, 2, 3]
    assert list(found.errors) == sorted(alone[s].error["sum_sq"] for s in (1, 2, 3))
    for s, run in zip(found.seeds, found.runs):
        assert run.text == alone[s].text and run.error == alone[s].error
    assert found.best is found.runs[0]
    with pytest.raises(ValueError, match="seeds=\\[...\\]"):
        study.restarts(m, [1], seed=2, **options)
