"""Tests of the Python package, as a user calls it: the bundled files
loaded, checked and simulated, every solved frame held to its joints from
the returned arrays (independently of dofplan's own residual), positions
against closed forms written here, and bad input against clear errors."""

import glob
import json
import math
import os
import pathlib

import numpy as np
import pytest

import dofplan

ROOT = pathlib.Path(__file__).resolve().parents[2]
MECHANISMS = ROOT / "mechanisms"
PLANAR = sorted(glob.glob(str(MECHANISMS / "*.toml")))
SPATIAL = sorted(glob.glob(str(MECHANISMS / "spatial" / "*.toml")))


def size_of(r):
    """The mechanism's extent over the first placed frame's markers (for
    relative tolerances)."""
    placed = [k for k in range(len(r)) if np.isfinite(r.markers[k]).all()]
    m = r.markers[placed[0]] if placed else np.zeros((1, 2))
    return float(np.max(np.ptp(m, axis=0))) or 1.0


def joint_gaps(m, r):
    """Per frame, the largest distance between the two markers of a revolute
    or spherical joint (the markers that must coincide), computed from the
    returned marker positions."""
    names = r.marker_names
    gaps = np.zeros(len(r))
    for _, kind, a, b in m.joint_markers:
        if kind not in ("revolute", "spherical", "universal"):
            continue
        d = r.markers[:, names.index(a), :] - r.markers[:, names.index(b), :]
        gaps = np.maximum(gaps, np.linalg.norm(d, axis=1))
    return gaps


def test_the_package_has_a_version_and_its_errors():
    assert dofplan.__version__
    assert issubclass(dofplan.MechanismError, dofplan.DofplanError)
    assert issubclass(dofplan.PlanError, dofplan.DofplanError)


def test_a_fourbar_loads_with_its_names():
    m = dofplan.load(MECHANISMS / "fourbar.toml")
    assert m.name == "fourbar"
    assert m.dimension == 2
    assert m.bodies == ["ground", "crank", "coupler", "rocker"]
    assert "coupler.P" in m.markers
    assert m.inputs == ["theta"] and m.input_kinds == ["angle"]
    assert m.sweep == {
        "inputs": [{"input": "theta", "from": 0.0, "to": 360.0}],
        "steps": 361,
        "trace": ["coupler.P"],
    }
    assert [j[0] for j in m.joint_markers] == m.joints
    assert "fourbar" in repr(m)
    assert m.simulate([0.0]).residual is None


def test_check_is_the_cli_s_check():
    m = dofplan.load(MECHANISMS / "fourbar.toml")
    c = m.check()
    assert c.ok
    d = c.to_dict()
    # The same document `dofplan check --json` prints, as attributes.
    assert c.mobility == d["mobility"]
    assert d["name"] == "fourbar"
    assert c.grashof == d["grashof"]
    with pytest.raises(AttributeError, match="has no field 'nonsense'"):
        c.nonsense


def test_plan_and_emit():
    m = dofplan.load(MECHANISMS / "fourbar.toml")
    p = m.plan()
    assert str(p).startswith("plan for fourbar")
    assert len(p.steps()) == 5
    code = m.emit()
    assert "pub fn solve" in code
    assert m.svg().lstrip().startswith("<svg") and m._repr_svg_() == m.svg()


def test_the_slider_crank_follows_its_closed_form():
    # mechanisms/slider_crank.toml: crank r = 1 from 30 deg, rod l = 3.5,
    # track at e = 0.25: x_C = r cos(phi) + sqrt(l^2 - (r sin(phi) - e)^2).
    m = dofplan.load(MECHANISMS / "slider_crank.toml")
    theta = np.linspace(-720.0, 720.0, 1441)
    r = m.simulate(theta)
    assert r.solved.all()
    phi = np.radians(30.0 + theta)
    x = np.cos(phi) + np.sqrt(3.5**2 - (np.sin(phi) - 0.25) ** 2)
    c = r.marker("slider.C")
    assert np.max(np.abs(c[:, 0] - x)) < 1e-12
    assert np.max(np.abs(c[:, 1] - 0.25)) < 1e-12
    # The crank's angle is the input, in (-180, 180].
    crank = r.body("crank")[:, 0]
    wrapped = (theta + 180.0) % 360.0 - 180.0
    wrapped[wrapped == -180.0] = 180.0
    assert np.max(np.abs(crank - wrapped)) < 1e-9


@pytest.mark.parametrize("path", PLANAR, ids=lambda p: pathlib.Path(p).stem)
def test_every_planar_sweep_holds_its_joints(path):
    m = dofplan.load(path)
    if m.sweep is None:
        pytest.skip("no sweep in the file")
    r = m.simulate(steps=min(m.sweep["steps"], 181), check=True)
    assert r.poses.shape == (len(r), len(m.bodies), 3)
    assert r.markers.shape == (len(r), len(m.markers), 2)
    ok = r.solved
    assert ok.any(), r
    gaps = joint_gaps(m, r)
    assert np.max(gaps[ok]) <= 1e-9 * size_of(r), (path, np.max(gaps[ok]))
    assert np.max(r.residual[ok]) <= 1e-9


@pytest.mark.parametrize("path", SPATIAL, ids=lambda p: pathlib.Path(p).stem)
def test_every_spatial_sweep_holds_its_joints_and_bodies_stay_rigid(path):
    m = dofplan.load(path)
    assert m.dimension == 3
    r = m.simulate(steps=min(m.sweep["steps"], 61))
    assert r.poses.shape == (len(r), len(m.bodies), 7)
    assert r.markers.shape == (len(r), len(m.markers), 3)
    ok = r.solved
    assert ok.any()
    q = r.poses[:, :, 3:]
    assert np.max(np.abs(np.linalg.norm(q, axis=2) - 1.0)) < 1e-12
    assert np.all(q[:, :, 0] >= 0.0)
    gaps = joint_gaps(m, r)
    assert np.max(gaps[ok]) <= 1e-9 * size_of(r), (path, np.max(gaps[ok]))
    # Each marker is its body's pose applied to where it is drawn: the
    # quaternion rotates the drawn offset from the body's origin.
    for k, name in enumerate(m.markers):
        body = m.bodies.index(name.split(".")[0])
        drawn = r.markers[0, k] if r.solved[0] else None
        if drawn is None:
            continue
        p0, q0 = r.poses[0, body, :3], r.poses[0, body, 3:]
        local = rotate(conj(q0), drawn - p0)
        for f in np.flatnonzero(ok)[:: max(1, len(r) // 7)]:
            p, qf = r.poses[f, body, :3], r.poses[f, body, 3:]
            assert np.linalg.norm(p + rotate(qf, local) - r.markers[f, k]) < 1e-9 * size_of(r)


def conj(q):
    return np.array([q[0], -q[1], -q[2], -q[3]])


def rotate(q, v):
    """v rotated by the unit quaternion q = (w, x, y, z)."""
    w, u = q[0], q[1:]
    return v + 2.0 * np.cross(u, np.cross(u, v) + w * v)


def test_a_rocker_is_held_past_its_limits_and_the_frames_say_so():
    # mechanisms/rocker_rocker.toml assembles for theta in
    # [-105.5224878141, 45.5224878141] only (its header derives it).
    m = dofplan.load(MECHANISMS / "rocker_rocker.toml")
    theta = np.linspace(-20.0, 80.0, 101)
    r = m.simulate(theta)
    inside = theta <= 45.5224878141
    assert r.solved[inside].all()
    assert not r.solved[~inside].any()
    assert {r.status_of(f) for f in np.flatnonzero(~inside)} == {"limited"}
    # Held: the pose reached stays at the last frame that assembled.
    last = np.flatnonzero(inside)[-1]
    assert np.all(r.inputs[~inside, 0] == r.inputs[last, 0])
    s = m.simulate(theta, policy="search")
    assert {s.status_of(f) for f in np.flatnonzero(~inside)} == {"searched"}
    assert abs(s.inputs[-1, 0] - 45.5224878141) < 1e-6


def test_inputs_of_two_columns_and_the_wrong_shapes():
    m = dofplan.load(MECHANISMS / "fourbar.toml")
    with pytest.raises(ValueError, match=r"1 input\(s\) \(theta\), but the inputs have 2 column"):
        m.simulate(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="shape"):
        m.simulate(np.zeros((3, 1, 1)))
    with pytest.raises(ValueError, match="not all finite"):
        m.simulate([0.0, float("nan")])
    with pytest.raises(ValueError, match="policy must be"):
        m.simulate([0.0], policy="jump")
    with pytest.raises(ValueError, match="steps must be from 1"):
        m.simulate(steps=0)
    with pytest.raises(KeyError, match="no marker 'coupler.Q'"):
        m.simulate([0.0]).marker("coupler.Q")
    r = m.simulate(np.array([[0.0], [90.0]]))
    assert len(r) == 2 and r.solved.all()


def test_a_file_with_errors_raises_its_diagnostics():
    text = 'name = "bad"\n[bodies.a]\nfixed = tru\n'
    with pytest.raises(dofplan.MechanismError) as e:
        dofplan.loads(text, name="bad.toml")
    message = str(e.value)
    assert "bad.toml:3:9" in message
    [d] = e.value.diagnostics
    assert (d["file"], d["line"], d["column"]) == ("bad.toml", 3, 9)
    assert "boolean" in d["message"]
    with pytest.raises(dofplan.MechanismError, match="cannot read the file"):
        dofplan.load(MECHANISMS / "no_such_file.toml")
    with pytest.raises(ValueError, match="format must be"):
        dofplan.loads(text, format="yaml")


def test_an_unknown_marker_is_named_with_its_position():
    text = (MECHANISMS / "fourbar.toml").read_text().replace('"coupler.B"', '"coupler.Z"', 1)
    with pytest.raises(dofplan.MechanismError) as e:
        dofplan.loads(text, name="fourbar.toml")
    d = e.value.diagnostics[0]
    assert "has no marker `Z`" in d["message"] and "coupler" in d["message"]
    assert d["line"] is not None and d["column"] is not None


def test_a_dict_loads_like_its_json_file():
    text = (MECHANISMS / "fourbar.toml").read_text()
    toml_m = dofplan.loads(text)
    d = json.loads(json.dumps(toml_dict(text)))
    m = dofplan.from_dict(d)
    a, b = toml_m.simulate(), m.simulate()
    assert np.array_equal(a.markers, b.markers)
    d["joints"]["A"]["markers"][1] = "crank.Q"
    with pytest.raises(dofplan.MechanismError) as e:
        dofplan.from_dict(d)
    assert e.value.diagnostics[0]["path"] is not None


def toml_dict(text):
    try:
        import tomllib
    except ImportError:  # Python < 3.11
        import tomli as tomllib
    return tomllib.loads(text)


def test_results_plot_with_matplotlib_when_it_is_there():
    plt = pytest.importorskip("matplotlib.pyplot")
    m = dofplan.load(MECHANISMS / "fourbar.toml")
    ax = m.simulate().plot()
    assert ax.get_title() == "fourbar"
    plt.close("all")


def test_the_slider_crank_s_rates_are_its_closed_form_s_derivatives():
    # x_C(phi) = r cos(phi) + S, S = sqrt(l^2 - u^2), u = r sin(phi) - e:
    # x' = -r sin(phi) - u u'/S, x'' = -r cos(phi) - (u'^2 + u u'')/S - (u u')^2/S^3.
    m = dofplan.load(MECHANISMS / "slider_crank.toml")
    theta = np.linspace(0.0, 360.0, 73)
    omega, alpha = 2.5, -0.75  # rad per unit of time, and per unit of time squared
    r = m.rates(theta, rate=omega, acceleration=alpha)
    assert (r.rate_status == 0).all()
    rr, l, e = 1.0, 3.5, 0.25
    phi = np.radians(30.0 + theta)
    u, du, ddu = rr * np.sin(phi) - e, rr * np.cos(phi), -rr * np.sin(phi)
    S = np.sqrt(l**2 - u**2)
    dx = -rr * np.sin(phi) - u * du / S
    ddx = -rr * np.cos(phi) - (du**2 + u * ddu) / S - (u * du) ** 2 / S**3
    k = r.marker_names.index("slider.C")
    assert np.max(np.abs(r.velocity[:, k, 0] - dx * omega)) < 1e-12
    assert np.max(np.abs(r.acceleration[:, k, 0] - (ddx * omega**2 + dx * alpha))) < 1e-11
    assert np.max(np.abs(r.velocity[:, k, 1])) < 1e-12
    crank = r.body_names.index("crank")
    assert np.max(np.abs(r.omega[:, crank] - omega)) < 1e-12
    assert np.max(np.abs(r.alpha[:, crank] - alpha)) < 1e-12


def test_spatial_rates_are_the_positions_derivatives():
    # A second, independent path: central differences of the positions.
    m = dofplan.load(MECHANISMS / "spatial" / "rssr.toml")
    theta = np.linspace(10.0, 350.0, 35)
    h = 1e-4  # degrees
    r = m.rates(theta, rate=1.0)  # one radian per unit of time
    plus, minus = m.simulate(theta + h), m.simulate(theta - h)
    assert r.velocity.shape == r.markers.shape and r.omega.shape == (len(theta), len(m.bodies), 3)
    fd = (plus.markers - minus.markers) / (2.0 * np.radians(h))
    ok = r.rate_status == 0
    assert ok.sum() > 30
    scale = np.max(np.abs(r.velocity[ok])) + 1.0
    assert np.max(np.abs(r.velocity[ok] - fd[ok])) < 1e-6 * scale


def test_rates_are_nan_where_a_frame_is_held():
    m = dofplan.load(MECHANISMS / "rocker_rocker.toml")
    r = m.rates(np.array([0.0, 30.0, 60.0]), rate=1.0)
    assert list(r.rate_status) == [0, 0, 1]
    assert r.rate_status_names[1] == "not solved"
    assert np.isnan(r.velocity[2]).all() and np.isfinite(r.velocity[:2]).all()
    with pytest.raises(ValueError, match="one rate per input"):
        dofplan.load(MECHANISMS / "spatial" / "excavator.toml").rates([0.0], rate=1.0)


@pytest.mark.parametrize("name", ["fourbar", "rocker_rocker", "stress_10"])
def test_a_long_run_on_every_core_is_one_core_s_to_the_bit(name):
    m = dofplan.load(MECHANISMS / f"{name}.toml")
    # 9000 frames of a sweep twice as wide as the file's, over and over,
    # from the drawing (a first frame that assembles: the parallel path's
    # condition): past the limits and back, holds across the blocks.
    one = m.sweep_inputs()[:, 0]
    wide = np.concatenate([[0.0], np.tile(2.0 * one - 7.0, 9000 // len(one) + 1)])[:9000]
    a = m.simulate(wide, check=True)
    b = m.simulate(wide, parallel=False, check=True)
    for field in ("poses", "markers", "inputs", "status", "residual"):
        x, y = getattr(a, field), getattr(b, field)
        assert x.shape == y.shape and np.array_equal(x, y, equal_nan=True), (name, field)
    assert a.solved[0]
    if name == "rocker_rocker":
        assert not a.solved.all() and a.solved[1000:].any()


def fourbar_builder():
    b = dofplan.Builder("fourbar")
    b.ground(A=(0, 0), D=(4, 0))
    b.body("crank", A=(0, 0), B=(1, 1))
    b.body("coupler", B=(1, 1), C=(4.5, 2.5), P=(3, 3.5))
    b.body("rocker", C=(4.5, 2.5), D=(4, 0))
    b.revolute("A", "ground.A", "crank.A").revolute("B", "crank.B", "coupler.B")
    b.revolute("C", "coupler.C", "rocker.C").revolute("D", "rocker.D", "ground.D")
    b.crank("theta", joint="A")
    b.sweep("theta", 0, 360, steps=73, trace=["coupler.P"])
    return b


def test_a_built_fourbar_moves_as_its_hand_computation_says():
    m = fourbar_builder().build()
    assert m.check().ok
    r = m.simulate()
    assert r.solved.all()
    # Independently: B turns about A by theta; C closes |BC| and |CD|; P is
    # fixed in the coupler's frame.
    A, D = np.array([0.0, 0.0]), np.array([4.0, 0.0])
    B0, C0, P0 = np.array([1.0, 1.0]), np.array([4.5, 2.5]), np.array([3.0, 3.5])
    lbc, lcd = np.linalg.norm(C0 - B0), np.linalg.norm(D - C0)
    for k, t in enumerate(np.radians(r.requested[:, 0])):
        B = A + np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]]) @ (B0 - A)
        d = np.linalg.norm(D - B)
        a = (lbc**2 - lcd**2 + d**2) / (2 * d)
        h = np.sqrt(lbc**2 - a**2)
        u = (D - B) / d
        n = np.array([-u[1], u[0]])
        # The drawn branch: C on the left of B -> D.
        C = B + a * u + h * n
        assert np.linalg.norm(r.marker("coupler.C")[k] - C) < 1e-12
        e0, e = (C0 - B0) / lbc, (C - B) / lbc
        c, s = e0 @ e, e0[0] * e[1] - e0[1] * e[0]
        rot = np.array([[c, -s], [s, c]])
        assert np.linalg.norm(r.marker("coupler.P")[k] - (B + rot @ (P0 - B0))) < 1e-12


def test_a_builder_writes_the_toml_it_builds():
    b = fourbar_builder()
    text = b.to_toml()
    a, c = b.build().simulate(), dofplan.loads(text).simulate()
    assert np.array_equal(a.markers, c.markers)
    b.prismatic("S", "ground.A", "crank.B")
    with pytest.raises(dofplan.MechanismError) as e:
        b.build()
    assert any(d["path"] and "S" in d["path"] for d in e.value.diagnostics), e.value.diagnostics


def test_results_draw_themselves_as_the_cli_draws_a_sweep():
    m = dofplan.load(MECHANISMS / "fourbar.toml")
    r = m.simulate(steps=37)
    svg = r._repr_svg_()
    assert svg.lstrip().startswith("<svg") and "coupler.P" in svg
    s = dofplan.load(MECHANISMS / "spatial" / "rssr.toml").simulate(steps=13)
    assert "<svg" in s.svg()


def test_a_dragged_marker_follows_its_targets_with_every_joint_closed():
    # The crank pin of the four-bar can only move on its circle about A:
    # targets on that circle, computed here.
    m = dofplan.load(MECHANISMS / "fourbar.toml")
    t = np.radians(np.linspace(0.0, 60.0, 13))
    targets = np.stack([np.cos(t) - np.sin(t), np.sin(t) + np.cos(t)], axis=1)  # B0 = (1, 1) turned by t
    r = m.drag("crank.B", targets)
    assert r.input_names == ["crank.B.x", "crank.B.y"]
    assert r.solved.all(), [r.status_of(k) for k in range(len(r))]
    assert np.max(np.linalg.norm(r.marker("crank.B") - targets, axis=1)) < 1e-9
    assert np.max(joint_gaps(m, r)) < 1e-9
    assert np.max(np.abs(r.body("crank")[:, 0] - np.degrees(t))) < 1e-7
    # Off the circle: held under "limit" at the last target met, come as
    # close as the joints allow (stretched) by default.
    far = [[3.0, 3.0]]
    assert m.drag("crank.B", far, policy="limit").status_of(0) == "limited"
    assert m.drag("crank.B", far).status_of(0) == "stretched"
    with pytest.raises(ValueError, match="no marker `coupler.Q` to drag"):
        m.drag("coupler.Q", targets)
    with pytest.raises(dofplan.PlanError, match="fixed"):
        m.drag("ground.A", targets)
    with pytest.raises(ValueError, match=r"shape \(frames, 2\)"):
        m.drag("crank.B", np.zeros((3, 3)))


def test_a_spatial_marker_is_dragged_along_its_path():
    m = dofplan.load(MECHANISMS / "spatial" / "rssr.toml")
    name = m.sweep["trace"][0]
    path = m.simulate(np.linspace(0.0, 20.0, 5)).marker(name)
    r = m.drag(name, path)
    assert r.solved.all(), [r.status_of(k) for k in range(len(r))]
    assert np.max(joint_gaps(m, r)) < 1e-9 * size_of(r)
    assert np.max(np.linalg.norm(r.marker(name) - path, axis=1)) < 1e-9 * size_of(r)


# A crank-rocker written here in Pyslvs's expression form: ground pivots at
# (0, 0) and (90, 0), a coupler point P3 on link L2.
CRANK_ROCKER = """M[
J[R, color[Green], P[0.0, 0.0], L[ground, L1]],
J[R, color[Green], P[12.92, 32.53], L[L1, L2]],
J[R, color[Green], P[73.28, 67.97], L[L2, L3]],
J[R, color[Green], P[33.3, 66.95], L[L2]],
J[R, color[Green], P[90.0, 0.0], L[ground, L3]],
]"""


def test_a_pyslvs_expression_imports_and_moves_with_its_links_rigid():
    m = dofplan.from_pmks(CRANK_ROCKER, inputs=[(0, 1)], name="crank_rocker")
    assert m.bodies == ["ground", "L1", "L2", "L3"]
    assert m.inputs == ["P0_P1"]
    r = m.simulate(np.linspace(0.0, 360.0, 73))
    assert r.solved.all()
    # The drawn pose is the expression's coordinates.
    drawn = {"P0": (0.0, 0.0), "P1": (12.92, 32.53), "P2": (73.28, 67.97), "P3": (33.3, 66.95), "P4": (90.0, 0.0)}
    for name in r.marker_names:
        assert np.allclose(r.markers[0, r.marker_names.index(name)], drawn[name.split(".")[1]], atol=1e-12)
    # Link lengths hold in every frame (computed from the expression).
    for a, b in (("L1.P0", "L1.P1"), ("L2.P1", "L2.P2"), ("L2.P1", "L2.P3"), ("L3.P2", "L3.P4")):
        length = np.hypot(*np.subtract(drawn[b.split(".")[1]], drawn[a.split(".")[1]]))
        got = np.linalg.norm(r.marker(b) - r.marker(a), axis=1)
        assert np.max(np.abs(got - length)) < 1e-9
    assert np.max(joint_gaps(m, r)) < 1e-9
    assert "Imported by `dofplan import`" in dofplan.pmks_to_toml(CRANK_ROCKER, [(0, 1)])


def test_a_bad_expression_is_an_error_at_its_column():
    with pytest.raises(dofplan.MechanismError) as e:
        dofplan.from_pmks("M[J[R, P[0, 0], L[ground, L1]], J[X, P[1,1], L[L1]]]")
    d = e.value.diagnostics[0]
    assert (d["line"], d["column"]) == (1, 35)
    assert "unknown joint type `X`" in d["message"]


def test_analyze_reports_the_transmission_angle_of_the_positions():
    m = dofplan.load(MECHANISMS / "fourbar.toml")
    a = m.analyze(rate=2.0, steps=37)
    assert a["mechanism"] == "fourbar" and len(a["frames"]) == 37
    for f in a["frames"]:
        mk = f["markers"]
        # The angle at C between the coupler (C -> B) and the rocker (C -> D).
        u = np.subtract(mk["coupler.B"], mk["coupler.C"])
        v = np.subtract(mk["rocker.D"], mk["rocker.C"])
        mu = np.degrees(np.arccos(u @ v / np.linalg.norm(u) / np.linalg.norm(v)))
        [loop] = f["transmission"]
        assert abs(min(loop["angle"], 180.0 - loop["angle"]) - min(mu, 180.0 - mu)) < 1e-9
        assert f["angular"]["crank"]["omega"] == pytest.approx(2.0, abs=1e-12)
    with pytest.raises(ValueError, match="steps must be from 1"):
        m.analyze(steps=0)


def test_sensitivity_ranks_the_parameters_and_bounds_a_tolerance():
    m = dofplan.load(MECHANISMS / "fourbar.toml")
    s = m.sensitivity(tolerance=0.01, monte_carlo=20, seed=3, steps=19)
    names = [p["name"] for p in s["parameters"]]
    assert "B.x" in names and "coupler.P.y" in names
    assert s["traced"] == ["coupler.P"]
    largest = [r["largest"] for r in s["ranking"]]
    assert largest == sorted(largest, reverse=True)
    # The same seed, the same study.
    assert m.sensitivity(tolerance=0.01, monte_carlo=20, seed=3, steps=19) == s


def test_a_mechanism_pickles_as_its_text_and_runs_in_other_processes():
    import multiprocessing
    import pickle

    m = dofplan.load(MECHANISMS / "slider_crank.toml")
    again = pickle.loads(pickle.dumps(m))
    assert again.file == m.file and again.bodies == m.bodies
    chunks = [np.linspace(k * 90.0, (k + 1) * 90.0, 46) for k in range(4)]
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        paths = pool.starmap(_slider_path, [(m, c) for c in chunks])
    for c, p in zip(chunks, paths):
        assert np.array_equal(p, m.simulate(c).marker("slider.C"))


def _slider_path(m, theta):
    return m.simulate(theta).marker("slider.C")


def test_a_drawing_off_by_a_little_is_assembled_and_then_loads():
    text = (MECHANISMS / "fourbar.toml").read_text()
    off = text.replace("C = [4.5, 2.5]", "C = [4.52, 2.47]", 1)
    assert off != text
    with pytest.raises(dofplan.MechanismError, match="does not hold"):
        dofplan.loads(off)
    a = dofplan.assemble_text(off, name="off.toml")
    assert not a.unchanged and "coupler.C" in a.report
    m = a.mechanism
    r = m.simulate([0.0, 90.0])
    assert r.solved.all() and np.max(joint_gaps(m, r)) < 1e-9
    # The coupler's moved marker keeps the links' lengths it was drawn with
    # on the rocker's side; nothing moved far.
    c = r.marker("coupler.C")[0]
    assert np.linalg.norm(c - [4.52, 2.47]) < 0.05
    assert dofplan.assemble(MECHANISMS / "fourbar.toml").unchanged


def test_synth_recovers_a_fourbar_from_its_own_path_and_the_file_reproduces_it():
    # Targets: the bundled four-bar's coupler point at 18 crank angles,
    # given timing. The drawing is moved off (C and D shifted), and the
    # search varies C and D back.
    truth = dofplan.load(MECHANISMS / "fourbar.toml")
    theta = np.linspace(0.0, 340.0, 18)
    p = truth.simulate(theta).marker("coupler.P")
    targets = np.column_stack([theta, p])
    text = (MECHANISMS / "fourbar.toml").read_text()
    moved = dofplan.loads(
        text.replace("C = [4.5, 2.5]", "C = [4.6, 2.4]").replace("D = [4, 0]", "D = [4.1, 0.1]"),
        name="moved.toml",
    )
    s = dofplan.synth(
        moved, path=targets, marker="coupler.P", timing="given", vary=["C", "D"],
        time_limit=20.0, target=1e-20, seed=7,
    )
    assert s.error["rms"] < 1e-9, s.result["error"]
    assert set(s.parameters) >= {"C.x", "C.y", "D.x", "D.y"}
    # From the written file, independently of the search's state.
    m = s.mechanism
    got = m.simulate(theta).marker("coupler.P")
    assert np.sqrt(np.mean(np.sum((got - p) ** 2, axis=1))) < 1e-9
    with pytest.raises(ValueError, match="give one goal"):
        dofplan.synth(moved)
    with pytest.raises(dofplan.DofplanError, match="no marker 'coupler.Q'"):
        dofplan.synth(moved, path=targets, marker="coupler.Q")


def test_frame_by_frame_from_the_live_pose_is_the_sweep_s():
    m = dofplan.load(MECHANISMS / "rocker_rocker.toml")
    theta = np.linspace(0.0, 80.0, 41)
    r = m.simulate(theta)
    for k, t in enumerate(theta):
        at, status = m.frame(t)
        assert status == r.status_of(k)
        assert np.array_equal(at, r.markers[k])
    # Held past the limit; back from the drawing after reset.
    assert m.frame(80.0)[1] == "limited"
    m.reset()
    at, status = m.frame(0.0)
    assert status == "solved" and np.array_equal(at, r.markers[0])
    with pytest.raises(ValueError, match="takes 1 finite input"):
        m.frame([1.0, 2.0])


def test_synth_stops_on_ctrl_c():
    # A search of two minutes, interrupted by SIGINT as Ctrl-C sends it: the
    # search stops at its next generation and KeyboardInterrupt is raised.
    import signal
    import subprocess
    import sys
    import time

    script = f"""
import sys, time
import numpy as np
import dofplan
m = dofplan.load({str(MECHANISMS / 'fourbar.toml')!r})
targets = m.simulate([0.0, 60.0, 120.0, 180.0, 240.0, 300.0]).marker("coupler.P") + [0.3, 0.0]
print("searching", flush=True)
t = time.monotonic()
try:
    dofplan.synth(m, path=targets, marker="coupler.P", time_limit=120.0)
    print("finished", flush=True)
except KeyboardInterrupt:
    print(f"interrupted after {{time.monotonic() - t:.2f}} s", flush=True)
"""
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "searching"
    time.sleep(1.0)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=60)
    assert out.startswith("interrupted after"), (out, err)
    assert float(out.split()[2]) < 30.0


def test_an_epicyclic_train_turns_as_willis_says_past_many_turns():
    # mechanisms/gears/epicyclic.toml: sun rS = 2 and ring rR = 4 on the
    # arm, planet rP = 1 between them; inputs the arm's angle c and the
    # sun's angle s relative to the arm. Relative to the arm the planet
    # turns -(rS/rP) s and the ring -(rS/rR) s (Willis), so absolutely
    # c - 2 s and c - s / 2, however many turns that is.
    m = dofplan.load(MECHANISMS / "gears" / "epicyclic.toml")
    c = np.linspace(-1000.0, 1000.0, 201)
    s = -0.73 * c
    r = m.simulate(np.column_stack([c, s]))
    assert r.solved.all()

    def wrapped(a):
        return (a + 180.0) % 360.0 - 180.0

    for body, angle in [("planet", c - 2.0 * s), ("ring", c - 0.5 * s)]:
        got = r.body(body)[:, 0]
        gap = np.abs(wrapped(got - angle))
        assert np.max(gap) < 1e-9, (body, np.max(gap))


def test_a_slot_s_end_holds_the_scotch_yoke():
    # mechanisms/slots/scotch_yoke.toml with its slot's ends at +-0.8: the
    # crank (r = 1, drawn at 30 deg) lifts its pin r sin(30 + theta) up the
    # slot, so past theta = asin(0.8) - 30 deg the frames are held there.
    text = (MECHANISMS / "slots" / "scotch_yoke.toml").read_text()
    m = dofplan.loads(text.replace("ends = [-1.25, 1.25]", "ends = [-0.8, 0.8]"))
    theta = np.linspace(0.0, 60.0, 61)
    r = m.simulate(theta)
    end = np.degrees(np.arcsin(0.8)) - 30.0
    assert (r.solved == (theta <= end)).all()
    x = r.marker("yoke.Y")[:, 0] - 3.0
    held = np.cos(np.radians(30.0 + theta[theta <= end][-1])) - np.cos(np.radians(30.0))
    assert np.max(np.abs(x[theta > end] - held)) < 1e-12


def test_an_arc_slot_moves_the_curved_lever_as_its_four_bar():
    # mechanisms/slots/curved_lever.toml: the crank's pin P (r = 1 about
    # O, drawn at 60 deg) in an arc of radius 3.5 about the lever's C, C
    # 3 from the lever's pivot Q = (4, 0): C is where the circle about Q
    # meets the circle about P, on the side it is drawn.
    m = dofplan.load(MECHANISMS / "slots" / "curved_lever.toml")
    theta = np.linspace(0.0, 360.0, 73)
    r = m.simulate(theta)
    assert r.solved.all()
    phi = np.radians(60.0 + theta)
    p = np.stack([np.cos(phi), np.sin(phi)], axis=1)
    q = np.array([4.0, 0.0])
    d = np.linalg.norm(q - p, axis=1)
    a = (3.5**2 - 3.0**2 + d**2) / (2 * d)
    h = np.sqrt(3.5**2 - a**2)
    u = (q - p) / d[:, None]
    c = p + a[:, None] * u + h[:, None] * np.stack([-u[:, 1], u[:, 0]], axis=1)
    assert np.max(np.abs(r.marker("lever.C") - c)) < 1e-12
    assert np.max(np.abs(r.marker("crank.P") - p)) < 1e-12
