"""dofplan <-> pylinkage 1.3 (dofplan.pylinkage).

Linkages are built the way pylinkage 1.3 documents (Ground, Crank,
RRRDyad, RRPDyad... in a pylinkage.Linkage), converted, and every point's
path is held against pylinkage's own simulation of the same linkage
(Linkage.simulation / step), frame by frame, and against closed forms
written here. No number is copied from dofplan's output.

pylinkage's crank turns by its angular_velocity (radians) per step, and
step() yields the pose after each step: frame k (from 1) is the crank
turned by k * angular_velocity, which is dofplan's input of
degrees(k * angular_velocity) (counter-clockwise positive in both).
"""

import glob
import math
import pathlib
import subprocess
import sys

import numpy as np
import pytest

pl = pytest.importorskip("pylinkage")

import dofplan  # noqa: E402
from dofplan.pylinkage import ConversionError, from_pylinkage, sanitize_name, to_pylinkage  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
MECHANISMS = ROOT / "mechanisms"


# --------------------------------------------------------------------------
# Helpers
# --------------------------------------------------------------------------


def pylinkage_frames(linkage, iterations=None):
    """pylinkage's own simulation, frames x components x 2, up to the first
    frame it cannot assemble (its step() raises UnbuildableError there).
    The simulation context puts the linkage back where it was."""
    frames = []
    with linkage.simulation(iterations=iterations) as sim:
        try:
            for _, coords in sim:
                frames.append(coords)
        except pl.UnbuildableError:
            pass
    return np.array(frames, dtype=float).reshape(len(frames), len(linkage.components), 2)


def size_of(linkage):
    """The linkage's extent at its present pose (for relative tolerances)."""
    xy = np.array(linkage.get_coords(), dtype=float)
    return float(np.max(np.ptp(xy, axis=0)))


def dofplan_paths(m, inputs):
    """dofplan's frames at ``inputs``, as frames x components x 2 in the
    linkage's component order (via ``m.pylinkage_markers``), and which
    frames solved."""
    r = m.simulate(np.asarray(inputs, dtype=float))
    idx = [r.marker_names.index(name) for name in m.pylinkage_markers]
    return r.markers[:, idx, :], r.solved


def crank_inputs(crank, frames):
    """dofplan's input (degrees) at pylinkage's frames 1..frames."""
    return np.degrees(crank.angular_velocity * np.arange(1, frames + 1))


def assert_same_paths(m, linkage, frames, inputs, min_frames):
    """dofplan's paths at ``inputs`` equal pylinkage's ``frames`` wherever
    both assemble, to 1e-9 of the linkage's size."""
    paths, solved = dofplan_paths(m, inputs)
    assert solved.sum() >= min_frames, (int(solved.sum()), min_frames)
    err = np.max(np.abs(paths[solved] - frames[solved]))
    assert err <= 1e-9 * size_of(linkage), err


def fourbar(**crank_options):
    """pylinkage's documented four-bar (pylinkage.simulation's docstring):
    ground 2, crank 1, coupler 2, rocker 1.5: Grashof (1 + 2 <= 2 + 1.5)
    with the crank shortest, a crank-rocker. Plus a coupler point held by
    a FixedDyad on the coupler (crank.output -> rocker)."""
    O1 = pl.Ground(0.0, 0.0, name="O1")
    O2 = pl.Ground(2.0, 0.0, name="O2")
    crank = pl.Crank(anchor=O1, radius=1.0, name="crank", **crank_options)
    rocker = pl.RRRDyad(anchor1=crank.output, anchor2=O2, distance1=2.0, distance2=1.5, name="rocker")
    P = pl.FixedDyad(crank.output, rocker, distance=1.0, angle=math.pi / 4, name="P")
    return pl.Linkage([O1, O2, crank, rocker, P], name="Four-Bar"), crank


def slider_crank(initial=math.radians(30.0), r=1.0, l=3.5, e=0.25):
    """An offset slider-crank the documented way: a Crank and an RRPDyad
    whose line runs through two Ground points. l > r + |e|: it turns fully.
    The hint puts the slider on the right of the crank."""
    O = pl.Ground(0.0, 0.0, name="O")
    L1 = pl.Ground(-1.0, e, name="L1")
    L2 = pl.Ground(1.0, e, name="L2")
    crank = pl.Crank(anchor=O, radius=r, initial_angle=initial, name="crank")
    slider = pl.RRPDyad(
        revolute_anchor=crank.output, line_anchor1=L1, line_anchor2=L2, distance=l, x=4.0, y=e, name="slider"
    )
    return pl.Linkage([O, L1, L2, crank, slider], name="slider-crank"), crank


# --------------------------------------------------------------------------
# pylinkage -> dofplan
# --------------------------------------------------------------------------


def test_the_documented_fourbar_converts_and_follows_pylinkage():
    linkage, crank = fourbar(angular_velocity=0.1)
    before = linkage.get_coords()
    m = from_pylinkage(linkage)
    assert linkage.get_coords() == before  # the linkage is left as it was
    c = m.check()
    assert c.ok and c.mobility == {"grubler": 1, "rank": 1}
    # One body per pylinkage link: the crank, the RRR dyad's two links;
    # the FixedDyad's point rides the coupler (it is rigid with it).
    assert m.bodies == ["ground", "crank", "crank_rocker", "O2_rocker"]
    assert m.pylinkage_markers == ["ground.O1", "ground.O2", "crank.crank", "crank_rocker.rocker", "crank_rocker.P"]
    assert ("O1", "revolute", "ground.O1", "crank.O1") in m.joint_markers
    assert m.inputs == ["crank"] and m.input_kinds == ["angle"]
    assert m.sweep["inputs"] == [{"input": "crank", "from": 0.0, "to": 360.0}]
    assert m.sweep["trace"] == ["crank_rocker.P"]
    # pylinkage's period at 0.1 rad a step: round(2 pi / 0.1) = 63 steps,
    # 6.3 rad, a little more than a turn.
    frames = pylinkage_frames(linkage)
    assert len(frames) == 63
    assert_same_paths(m, linkage, frames, crank_inputs(crank, len(frames)), min_frames=63)
    # The drawn pose is where pylinkage holds the linkage.
    paths, _ = dofplan_paths(m, [0.0])
    assert np.max(np.abs(paths[0] - np.array(before))) <= 1e-12


def test_the_drawing_is_the_linkage_where_it_stands():
    # Stepped 40 times first: the mechanism is drawn there, and frame k
    # after it is input degrees(k w).
    linkage, crank = fourbar()
    for _ in linkage.step(iterations=40):
        pass
    m = from_pylinkage(linkage)
    frames = pylinkage_frames(linkage, iterations=360)
    assert_same_paths(m, linkage, frames, crank_inputs(crank, 360), min_frames=360)


def test_a_clockwise_crank_sweeps_clockwise():
    linkage, crank = fourbar(angular_velocity=-math.tau / 360)
    m = from_pylinkage(linkage)
    assert m.sweep["inputs"][0]["to"] == -360.0
    frames = pylinkage_frames(linkage)
    assert len(frames) == 360
    assert_same_paths(m, linkage, frames, crank_inputs(crank, 360), min_frames=360)


def test_the_slider_crank_follows_pylinkage_and_its_closed_form():
    linkage, crank = slider_crank()
    m = from_pylinkage(linkage)
    c = m.check()
    assert c.ok and c.mobility == {"grubler": 1, "rank": 1}
    # The rod, and a slider block on a guide of the ground along L1 -> L2.
    assert m.bodies == ["ground", "crank", "crank_slider", "slider_block"]
    assert ("slider_slide", "prismatic", "ground.slider_guide", "slider_block.slider") in m.joint_markers
    frames = pylinkage_frames(linkage)
    assert len(frames) == 360
    inputs = crank_inputs(crank, 360)
    assert_same_paths(m, linkage, frames, inputs, min_frames=360)
    # x_C = r cos(phi) + sqrt(l^2 - (r sin(phi) - e)^2), y_C = e.
    paths, solved = dofplan_paths(m, inputs)
    phi = math.radians(30.0) + np.radians(inputs)
    x = np.cos(phi) + np.sqrt(3.5**2 - (np.sin(phi) - 0.25) ** 2)
    assert solved.all()
    assert np.max(np.abs(paths[:, 4, 0] - x)) < 1e-12
    assert np.max(np.abs(paths[:, 4, 1] - 0.25)) < 1e-12


def test_the_documented_slider_crank_agrees_where_both_assemble():
    # pylinkage's RRPDyad docstring: crank 1 about (0, 0), rod 1.5, line
    # y = 1 through L1 (0, 1), L2 (2, 1). It assembles while the crank pin
    # is within 1.5 of the line: |sin(theta) - 1| <= 1.5, i.e. up to
    # theta = 210 degrees (k w = 3.665 rad, between frames 366 and 367).
    O1 = pl.Ground(0.0, 0.0, name="O1")
    L1 = pl.Ground(0.0, 1.0, name="L1")
    L2 = pl.Ground(2.0, 1.0, name="L2")
    crank = pl.Crank(anchor=O1, radius=1.0, angular_velocity=0.01, name="crank")
    slider = pl.RRPDyad(revolute_anchor=crank.output, line_anchor1=L1, line_anchor2=L2, distance=1.5, name="slider")
    linkage = pl.Linkage([O1, L1, L2, crank, slider], name="slider")
    m = from_pylinkage(linkage)
    assert m.check().ok
    frames = pylinkage_frames(linkage, iterations=500)
    assert len(frames) == 366  # pylinkage stops at frame 367
    inputs = crank_inputs(crank, 500)
    paths, solved = dofplan_paths(m, inputs)
    # dofplan solves the same frames and holds the pose past the limit.
    assert solved[:366].all() and not solved[366:].any()
    err = np.max(np.abs(paths[:366] - frames))
    assert err <= 1e-9 * size_of(linkage), err


def test_a_linear_actuator_is_a_slide_input():
    # The actuator's pin drives a rocker through an RRR dyad. pylinkage's
    # actuator goes out at `speed` per step from its extension, and back
    # from the end of its stroke: a triangle wave, written here.
    O = pl.Ground(0.0, 0.0, name="O")
    Q = pl.Ground(3.0, 0.0, name="Q")
    act = pl.LinearActuator(anchor=O, angle=0.4, stroke=1.0, speed=0.05, initial_extension=0.5, name="ram")
    arm = pl.RRRDyad(act.output, Q, distance1=2.0, distance2=2.0, name="arm")
    linkage = pl.Linkage([O, Q, act, arm], name="ram")
    m = from_pylinkage(linkage)
    assert m.check().ok
    assert m.inputs == ["ram"] and m.input_kinds == ["slide"]
    assert ("ram_slide", "prismatic", "ground.ram_guide", "ram.ram") in m.joint_markers
    assert m.sweep["inputs"] == [{"input": "ram", "from": -0.5, "to": 0.5}]
    frames = pylinkage_frames(linkage)
    assert len(frames) == 40  # 2 * stroke / speed
    k = np.arange(1, 41)
    t = (0.5 + 0.05 * k) % 2.0
    ext = np.where(t <= 1.0, t, 2.0 - t)
    assert_same_paths(m, linkage, frames, ext - 0.5, min_frames=40)


def test_an_arc_crank_sweeps_its_arc():
    O1 = pl.Ground(0.0, 0.0, name="O1")
    O2 = pl.Ground(2.0, 0.0, name="O2")
    crank = pl.ArcCrank(
        anchor=O1, radius=1.0, angular_velocity=0.02, arc_start=0.2, arc_end=1.4, initial_angle=0.5, name="arc"
    )
    rocker = pl.RRRDyad(crank.output, O2, 2.0, 1.5, name="rocker")
    linkage = pl.Linkage([O1, O2, crank, rocker], name="arc")
    m = from_pylinkage(linkage)
    assert m.check().ok
    sweep = m.sweep["inputs"][0]
    assert sweep["from"] == pytest.approx(math.degrees(0.2 - 0.5), abs=1e-12)
    assert sweep["to"] == pytest.approx(math.degrees(1.4 - 0.5), abs=1e-12)
    # The arc crank goes up at 0.02 a step and back from 1.4 to 0.2.
    frames = pylinkage_frames(linkage)
    k = np.arange(1, len(frames) + 1)
    t = (0.5 - 0.2 + 0.02 * k) % 2.4
    angle = 0.2 + np.where(t <= 1.2, t, 2.4 - t)
    assert_same_paths(m, linkage, frames, np.degrees(angle - 0.5), min_frames=len(frames))


def test_a_pp_dyad_is_two_blocks_pinned_together():
    # A point on the crank's line (through O and the crank's pin) and on
    # the line y = 1: x = cot(theta), a Scotch-yoke-like slider.
    O = pl.Ground(0.0, 0.0, name="O")
    G1 = pl.Ground(-1.0, 1.0, name="G1")
    G2 = pl.Ground(1.0, 1.0, name="G2")
    crank = pl.Crank(anchor=O, radius=1.0, initial_angle=math.radians(60.0), name="crank")
    X = pl.PPDyad(O, crank.output, G1, G2, name="X")
    linkage = pl.Linkage([O, G1, G2, crank, X], name="yoke")
    m = from_pylinkage(linkage)
    assert m.check().ok
    assert {"X_block1", "X_block2"} <= set(m.bodies)
    frames = pylinkage_frames(linkage, iterations=100)  # up to 160 degrees
    inputs = crank_inputs(crank, 100)
    assert_same_paths(m, linkage, frames, inputs, min_frames=100)
    paths, _ = dofplan_paths(m, inputs)
    theta = np.radians(60.0 + inputs)
    assert np.max(np.abs(paths[:, 4, 0] - np.cos(theta) / np.sin(theta))) < 1e-9


def test_a_tracker_off_the_links_rides_a_slot():
    # pylinkage's PointTracker docstring: a point at 45 degrees from the
    # line crank.output -> O2, which are on no common link: a body pinned
    # at the crank's pin whose slot holds a block pinned at O2.
    linkage, crank = fourbar()
    tracer = pl.PointTracker(crank.output, linkage.components[1], distance=0.5, angle=math.pi / 4, name="tracer")
    linkage = pl.Linkage(list(linkage.components) + [tracer], name="tracked")
    m = from_pylinkage(linkage)
    c = m.check()
    assert c.ok and c.mobility == {"grubler": 1, "rank": 1}
    assert ("tracer_slot", "prismatic", "crank_tracer.tracer_slot", "tracer_block.O2") in m.joint_markers
    frames = pylinkage_frames(linkage)
    assert_same_paths(m, linkage, frames, crank_inputs(crank, len(frames)), min_frames=360)


def test_names_are_sanitised_and_the_mapping_is_kept():
    O1 = pl.Ground(0.0, 0.0, name="pivot.A")
    O2 = pl.Ground(2.0, 0.0, name="pivot_A")  # the sanitised name of the first
    crank = pl.Crank(anchor=O1, radius=1.0, name="drive crank")
    rocker = pl.RRRDyad(crank.output, O2, 2.0, 1.5, name="rocker")
    linkage = pl.Linkage([O1, O2, crank, rocker], name="my four bar")
    m = from_pylinkage(linkage)
    assert m.name == "my_four_bar"
    assert m.pylinkage_markers == [
        "ground.pivot_A",
        "ground.pivot_A_2",
        "drive_crank.drive_crank",
        "drive_crank_rocker.rocker",
    ]
    assert m.inputs == ["drive_crank"]
    assert sanitize_name("a b.c\td") == "a_b_c_d" and sanitize_name("") == "p"
    assert from_pylinkage(linkage, name="other").name == "other"


def test_what_dofplan_cannot_express_is_named():
    from pylinkage.cam import FunctionProfile, HarmonicMotionLaw
    from pylinkage.dyads import TranslatingCamFollower

    O = pl.Ground(0.0, 0.0, name="O")
    G = pl.Ground(0.0, 2.0, name="G")
    crank = pl.Crank(anchor=O, radius=1.0, name="cam")
    profile = FunctionProfile(
        motion_law=HarmonicMotionLaw(),
        base_radius=1.0,
        total_lift=0.5,
        rise_start=0.0,
        rise_end=math.pi / 2,
        dwell_high_end=math.pi,
        fall_end=3 * math.pi / 2,
    )
    follower = TranslatingCamFollower(cam_driver=crank, profile=profile, guide=G, guide_angle=math.pi / 2, name="follower")
    with pytest.raises(ConversionError, match=r"'follower' is a TranslatingCamFollower.*no cam joint"):
        from_pylinkage(pl.Linkage([O, G, crank, follower]))

    # A crank about a moving point: pylinkage's angle is absolute.
    O1 = pl.Ground(0.0, 0.0, name="O1")
    c1 = pl.Crank(anchor=O1, radius=1.0, name="c1")
    c2 = pl.Crank(anchor=c1, radius=0.5, name="c2")
    with pytest.raises(ConversionError, match=r"'c2' \(Crank\) turns about 'c1'.*not a Ground point"):
        from_pylinkage(pl.Linkage([O1, c1, c2]))

    # A slide line through points on two different links.
    linkage, crank = fourbar()
    O1, O2, crank, rocker, _ = linkage.components
    s = pl.RRPDyad(revolute_anchor=O2, line_anchor1=crank.output, line_anchor2=rocker, distance=1.0, name="s")
    # crank.output and rocker ARE on the coupler: that converts...
    assert from_pylinkage(pl.Linkage([O1, O2, crank, rocker, s])).check().ok
    # ...the crank's pin and the ground's O2 are not on one link.
    s = pl.RRPDyad(revolute_anchor=rocker, line_anchor1=crank.output, line_anchor2=O2, distance=2.0, name="s")
    with pytest.raises(ConversionError, match=r"'s' \(RRPDyad\).*no common rigid link"):
        from_pylinkage(pl.Linkage([O1, O2, crank, rocker, s]))

    # An anchor left out of the linkage, and a linkage that does not
    # assemble where it stands.
    with pytest.raises(ConversionError, match=r"'rocker'.*anchor2 'O2' is not a component"):
        from_pylinkage(pl.Linkage([O1, crank, rocker]))
    far = pl.Ground(10.0, 0.0, name="far")
    bad = pl.RRRDyad(crank.output, far, 1.0, 1.0, x=5.0, y=0.0, name="bad")
    with pytest.raises(ConversionError, match=r"'bad' \(RRRDyad\) does not assemble"):
        from_pylinkage(pl.Linkage([O1, far, crank, bad]))
    with pytest.raises(ConversionError, match="no Crank, ArcCrank or LinearActuator"):
        from_pylinkage(pl.Linkage([O1, O2]))
    with pytest.raises(ConversionError, match=r"pylinkage\.mechanism\.Mechanism"):
        from_pylinkage(pl.mechanism.fourbar(crank=1.0, coupler=3.0, rocker=3.0, ground=4.0))
    with pytest.raises(TypeError):
        from_pylinkage("fourbar")
    # Both kinds of except catch it.
    assert issubclass(ConversionError, dofplan.MechanismError) and issubclass(ConversionError, ValueError)


# --------------------------------------------------------------------------
# dofplan -> pylinkage
# --------------------------------------------------------------------------


def by_name(linkage):
    return {c.name: c for c in linkage.components}


@pytest.mark.parametrize("build", [fourbar, slider_crank], ids=["fourbar", "slider_crank"])
def test_a_round_trip_gives_back_the_linkage(build):
    linkage, crank = build()
    back = to_pylinkage(from_pylinkage(linkage))
    assert isinstance(back, pl.Linkage)
    # Where pylinkage itself assembles the original (a step of 0: the
    # slider's constructor only took a hint, which from_pylinkage solves).
    for _ in linkage.step(iterations=1, dt=0):
        pass
    mine, theirs = by_name(linkage), by_name(back)
    assert set(mine) <= set(theirs)
    size = size_of(linkage)
    for name, c in mine.items():
        assert type(theirs[name]).__name__ == type(c).__name__ or name in ("P",), name
        assert np.allclose(theirs[name].position, c.position, rtol=0.0, atol=1e-12 * size), name
    # And it moves as the original does: pylinkage against pylinkage.
    assert by_name(back)["crank"].angular_velocity == pytest.approx(crank.angular_velocity, abs=1e-15)
    a, b = pylinkage_frames(linkage), pylinkage_frames(back)
    order = [list(theirs).index(name) for name in mine]
    assert np.max(np.abs(a - b[:, order, :])) <= 1e-9 * size


def test_a_round_trip_through_a_slot():
    linkage, crank = fourbar()
    tracer = pl.PointTracker(crank.output, linkage.components[1], distance=0.5, angle=math.pi / 4, name="tracer")
    linkage = pl.Linkage(list(linkage.components) + [tracer], name="tracked")
    back = to_pylinkage(from_pylinkage(linkage))
    theirs = by_name(back)
    assert isinstance(theirs["tracer"], pl.FixedDyad)
    a, b = pylinkage_frames(linkage), pylinkage_frames(back)
    order = [list(theirs).index(c.name) for c in linkage.components]
    assert np.max(np.abs(a - b[:, order, :])) <= 1e-9 * size_of(linkage)


def test_the_bundled_fourbar_and_slider_crank_go_to_pylinkage():
    m = dofplan.load(MECHANISMS / "fourbar.toml")
    linkage = to_pylinkage(m)
    parts = by_name(linkage)
    assert [type(c).__name__ for c in linkage.components] == ["Ground", "Ground", "Crank", "RRRDyad", "FixedDyad"]
    assert parts["B"].position == pytest.approx((1.0, 1.0), abs=1e-12)
    assert parts["B"].radius == pytest.approx(math.sqrt(2.0), abs=1e-12)
    assert parts["C"].distance1 == pytest.approx(math.sqrt(14.5), abs=1e-12)
    assert parts["C"].distance2 == pytest.approx(math.sqrt(6.5), abs=1e-12)
    assert parts["P"].position == pytest.approx((3.0, 3.5), abs=1e-12)

    # The slider-crank against its closed form, through pylinkage alone:
    # crank r = 1 from 30 degrees, rod 3.5, track y = 0.25 (the file's
    # header), x_C = r cos(phi) + sqrt(l^2 - (r sin(phi) - e)^2).
    linkage = to_pylinkage(dofplan.load(MECHANISMS / "slider_crank.toml"))
    parts = by_name(linkage)
    assert isinstance(parts["C"], pl.RRPDyad) and isinstance(parts["B"], pl.Crank)
    frames = pylinkage_frames(linkage)
    assert len(frames) == 360  # the file's sweep: 1 degree a frame
    k = list(parts).index("C")
    phi = np.radians(30.0 + np.arange(1, 361))
    x = np.cos(phi) + np.sqrt(3.5**2 - (np.sin(phi) - 0.25) ** 2)
    assert np.max(np.abs(frames[:, k, 0] - x)) < 1e-12
    assert np.max(np.abs(frames[:, k, 1] - 0.25)) < 1e-12


PLANAR = sorted(glob.glob(str(MECHANISMS / "*.toml")))


@pytest.mark.parametrize("path", PLANAR, ids=lambda p: pathlib.Path(p).stem)
def test_every_planar_file_converts_or_says_why(path):
    """Each bundled planar file either converts, and pylinkage's simulation
    of the result follows dofplan's where both assemble, or is refused
    with a ConversionError naming what pylinkage cannot solve."""
    m = dofplan.load(path)
    try:
        linkage = to_pylinkage(m)
    except ConversionError as e:
        assert m.name in str(e)
        assert any(word in str(e) for word in ("input", "cannot be reached", "slide", "prismatic", "block")), str(e)
        return
    frames = pylinkage_frames(linkage, iterations=90)
    assert len(frames) > 0
    # pylinkage's frame k is the file's sweep k steps from the drawing
    # (input 0): the crank turns by one sweep step per pylinkage step.
    sweep = m.sweep["inputs"][0]
    step = (sweep["to"] - sweep["from"]) / (m.sweep["steps"] - 1)
    r = m.simulate(step * np.arange(1, len(frames) + 1))
    drawn = m.simulate([0.0]).markers[0]
    size = float(np.max(np.ptp(drawn, axis=0)))
    checked = 0
    for j, c in enumerate(linkage.components):
        if isinstance(c, pl.Ground):
            continue
        # The dofplan marker at the point's drawn position (markers joined
        # at a pin coincide in every solved frame).
        k = int(np.argmin(np.linalg.norm(drawn - np.array(c.position), axis=1)))
        assert np.linalg.norm(drawn[k] - c.position) <= 1e-12 * size
        ok = r.solved[: len(frames)]
        err = np.max(np.abs(r.markers[: len(frames)][ok, k, :] - frames[ok, j, :]))
        assert err <= 1e-9 * size, (c.name, err)
        checked += 1
    assert checked and r.solved[: len(frames)].sum() >= min(len(frames), 40)


def test_a_crank_joint_written_the_other_way_turns_the_crank_clockwise():
    # fourbar.toml with joint A's markers swapped: a positive input now
    # turns the crank clockwise, and so does pylinkage's crank.
    text = (MECHANISMS / "fourbar.toml").read_text().replace(
        'markers = ["ground.A", "crank.A"]', 'markers = ["crank.A", "ground.A"]'
    )
    m = dofplan.loads(text)
    linkage = to_pylinkage(m)
    crank = by_name(linkage)["B"]
    assert crank.angular_velocity == pytest.approx(-math.radians(1.0), abs=1e-15)
    frames = pylinkage_frames(linkage, iterations=360)
    k = np.arange(1, 361)
    # B = A + sqrt(2) (cos, sin)(45 degrees - k degrees): by hand.
    b = math.sqrt(2.0) * np.stack([np.cos(np.radians(45.0 - k)), np.sin(np.radians(45.0 - k))], axis=1)
    assert np.max(np.abs(frames[:, list(by_name(linkage)).index("B"), :] - b)) < 1e-12
    r = m.simulate(k.astype(float))
    names = list(by_name(linkage))
    for name, marker in (("B", "coupler.B"), ("C", "coupler.C"), ("P", "coupler.P")):
        assert np.max(np.abs(r.marker(marker) - frames[:, names.index(name), :])) <= 1e-9 * 4.5


def test_what_pylinkage_cannot_express_is_named():
    with pytest.raises(ConversionError, match="spatial"):
        to_pylinkage(dofplan.load(MECHANISMS / "spatial" / "rssr.toml"))
    with pytest.raises(ConversionError, match=r"input 's' is a slide"):
        to_pylinkage(dofplan.load(MECHANISMS / "trammel.toml"))
    # Stephenson III driven at F: a triad after the crank.
    with pytest.raises(ConversionError, match=r"sixbar_b.*cannot be reached .* one pylinkage dyad at a time"):
        to_pylinkage(dofplan.load(MECHANISMS / "sixbar_b.toml"))
    # Two inputs.
    text = (MECHANISMS / "fourbar.toml").read_text().replace(
        "[sweep]", '[inputs.phi]\nkind = "angle"\njoint = "D"\n\n[sweep]'
    )
    with pytest.raises(ConversionError, match=r"2 inputs \(theta, phi\)"):
        to_pylinkage(dofplan.loads(text))
    # An input between two moving bodies (the coupler turned on the crank).
    text = (MECHANISMS / "fourbar.toml").read_text().replace('joint = "A"', 'joint = "B"')
    with pytest.raises(ConversionError, match=r"input 'theta' does not turn a body about the ground"):
        to_pylinkage(dofplan.loads(text))


def test_importing_dofplan_does_not_import_pylinkage():
    code = "import sys, dofplan; assert 'pylinkage' not in sys.modules; print('ok')"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0 and out.stdout.strip() == "ok", out.stderr
