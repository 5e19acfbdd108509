"""Conversion between dofplan mechanisms and pylinkage 1.3 linkages.

pylinkage (https://pypi.org/project/pylinkage/) builds a planar linkage as
a list of *points* (its "joints"): ``Ground`` points, motor inputs
(``Crank``, ``ArcCrank``, ``LinearActuator``) and Assur dyads that place
one more point from points already placed (``RRRDyad``: two links meeting
at a pin; ``RRPDyad``: a link whose far end slides on a line; ``PPDyad``:
a pin on two lines; ``FixedDyad`` and ``PointTracker``: a point held at a
distance and angle). Its container is ``pylinkage.Linkage`` (the same
class as ``pylinkage.simulation.Linkage``). dofplan's model is bodies with
markers and joints between markers; this module turns one into the other::

    from dofplan.pylinkage import from_pylinkage, to_pylinkage
    m = from_pylinkage(linkage)       # a dofplan.Mechanism
    m.check().ok, m.simulate()
    linkage2 = to_pylinkage(m)        # back, where pylinkage can say it

This module is not imported by ``import dofplan``; pylinkage is imported
only when one of these functions is called. The mapping, name by name, is
in ``docs/guide/python-interop.md``.
"""

from __future__ import annotations

import math
import re
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from . import Mechanism, MechanismError, from_dict

__all__ = ["ConversionError", "from_pylinkage", "to_pylinkage", "sanitize_name"]


class ConversionError(MechanismError, ValueError):
    """A linkage or mechanism that the other side cannot express.

    Both a :class:`dofplan.MechanismError` and a :class:`ValueError`, so
    either ``except`` catches it. The message names the pylinkage joint (or
    the dofplan joint, body or input) and says why. ``diagnostics`` holds
    the message as one dict, shaped like a load error's.
    """

    def __init__(self, message: str) -> None:
        super().__init__(message)
        self.diagnostics = [
            {
                "file": None,
                "line": None,
                "column": None,
                "path": None,
                "message": message,
                "help": None,
                "notes": [],
            }
        ]


def _import_pylinkage() -> Any:
    """pylinkage, imported on first use (dofplan does not depend on it)."""
    try:
        import pylinkage
    except ImportError:
        raise ImportError(
            "dofplan.pylinkage needs pylinkage 1.3: pip install 'pylinkage>=1.3,<2'"
        ) from None
    # The component API (components/actuators/dyads/simulation) is the one
    # this module reads and writes; it appeared in pylinkage 1.x.
    for attr in ("Ground", "Crank", "RRRDyad", "RRPDyad", "FixedDyad", "Linkage"):
        if not hasattr(pylinkage, attr):
            raise ImportError(
                f"dofplan.pylinkage needs pylinkage 1.3's component API; the installed "
                f"pylinkage {getattr(pylinkage, '__version__', '?')} has no pylinkage.{attr}"
            )
    return pylinkage


# --------------------------------------------------------------------------
# Names
# --------------------------------------------------------------------------

_BAD = re.compile(r"[.\s]")


def sanitize_name(name: Any) -> str:
    """A pylinkage name as a dofplan name: dofplan names may not be empty
    or hold dots or white space (``body.marker`` splits at the dot), so
    each dot or white-space character becomes ``_`` and an empty name
    becomes ``p``. Valid names are kept as they are."""
    text = _BAD.sub("_", str(name))
    return text or "p"


def _unique(base: str, taken: set) -> str:
    """``base``, or ``base_2``, ``base_3``... whichever is not taken yet
    (recorded as taken)."""
    name, k = base, 2
    while name in taken:
        name = f"{base}_{k}"
        k += 1
    taken.add(name)
    return name


# --------------------------------------------------------------------------
# pylinkage -> dofplan
# --------------------------------------------------------------------------


def _unit(dx: float, dy: float, what: str) -> Tuple[float, float]:
    n = math.hypot(dx, dy)
    if not n > 0.0 or not math.isfinite(n):
        raise ConversionError(what)
    return (dx / n, dy / n)


class _Points:
    """The linkage's points in dofplan's terms: who carries each one, where
    it is, and the bodies and joints built around them."""

    def __init__(self, names: List[str], positions: List[Tuple[float, float]]) -> None:
        self.names = names
        self.positions = positions
        # Derived names (guides, sliding joints) must not take a point's
        # name, which is needed as a marker and a joint name.
        self.point_names = set(names)
        self.bodies: Dict[str, Dict[str, Any]] = {"ground": {"fixed": True, "markers": {}}}
        self.body_names = {"ground"}
        self.carriers: List[List[str]] = [[] for _ in names]
        self.joints: Dict[str, Dict[str, Any]] = {}
        self.joint_names = set(self.point_names)

    def new_body(self, base: str) -> str:
        name = _unique(sanitize_name(base), self.body_names)
        self.bodies[name] = {"markers": {}}
        return name

    def put(self, k: int, body: str) -> None:
        """Point ``k`` as a marker of ``body`` (its name, its position)."""
        if body in self.carriers[k]:
            return
        x, y = self.positions[k]
        self.bodies[body]["markers"][self.names[k]] = [x, y]
        self.carriers[k].append(body)

    def guide(self, body: str, base: str, at: Tuple[float, float], direction: Tuple[float, float]) -> str:
        """A marker with a direction (the line of a prismatic joint)."""
        taken = set(self.bodies[body]["markers"]) | self.point_names
        name = _unique(sanitize_name(base), taken)
        self.bodies[body]["markers"][name] = {
            "at": [at[0], at[1]],
            "dir": [direction[0], direction[1]],
        }
        return name

    def prismatic(self, base: str, guide: str, slider: str) -> str:
        name = _unique(sanitize_name(base), self.joint_names)
        self.joints[name] = {"kind": "prismatic", "markers": [guide, slider]}
        return name

    def common_body(self, a: int, b: int) -> Optional[str]:
        """A body that carries both points (they are then rigidly a pair)."""
        for body in self.carriers[a]:
            if body in self.carriers[b]:
                return body
        return None


def _component_kind(c: Any) -> str:
    """The pylinkage class a component is handled as, by isinstance
    (subclasses convert as their base)."""
    from pylinkage.actuators import ArcCrank, Crank, LinearActuator
    from pylinkage.components import Ground, PointTracker
    from pylinkage.dyads import FixedDyad, PPDyad, RRPDyad, RRRDyad

    for cls, kind in (
        (Ground, "ground"),
        (ArcCrank, "arc_crank"),
        (Crank, "crank"),
        (LinearActuator, "linear"),
        (RRRDyad, "rrr"),
        (RRPDyad, "rrp"),
        (PPDyad, "pp"),
        (FixedDyad, "fixed"),
        (PointTracker, "fixed"),
    ):
        if isinstance(c, cls):
            return kind
    return "unknown"


def _anchor_refs(c: Any, kind: str) -> List[Tuple[str, Any]]:
    """The component's anchors as (role, anchor), in pylinkage's order,
    proxies (``crank.output``) unwrapped to their component."""
    if kind in ("crank", "arc_crank", "linear"):
        roles = ["anchor"]
    elif kind in ("rrr", "fixed"):
        roles = ["anchor1", "anchor2"]
    elif kind == "rrp":
        roles = ["revolute_anchor", "line_anchor1", "line_anchor2"]
    elif kind == "pp":
        roles = ["line1_anchor1", "line1_anchor2", "line2_anchor1", "line2_anchor2"]
    else:
        roles = []
    out = []
    for role in roles:
        a = getattr(c, role)
        a = getattr(a, "_parent", a)  # _AnchorProxy -> its component
        out.append((role, a))
    return out


def from_pylinkage(linkage: Any, name: Optional[str] = None) -> Mechanism:
    """Converts a pylinkage 1.3 linkage into a :class:`dofplan.Mechanism`.

    ``linkage`` is a ``pylinkage.Linkage`` (``pylinkage.simulation.Linkage``)
    built from the component API. Its points are taken where the linkage
    holds them now: each dyad is solved from its anchors with pylinkage's
    own solvers (``pylinkage.solver.joints``) starting from its current
    position, as one ``step(dt=0)`` would, without changing the linkage.
    That pose is the mechanism's drawing (input 0).

    - ``Ground`` points: markers of the fixed body ``ground``.
    - ``Crank`` / ``ArcCrank`` ``c`` about ground point ``A``: body ``c``
      (markers ``A`` and ``c``), a revolute joint at ``A`` and an
      ``angle`` input ``c`` on it (counter-clockwise, as pylinkage's
      angle grows).
    - ``LinearActuator`` ``a``: a slider body ``a``, a prismatic joint
      ``a_slide`` on the ground marker ``a_guide`` (at the anchor, along
      the actuator's angle) and a ``slide`` input ``a``.
    - ``RRRDyad`` ``d`` with anchors ``p``, ``q``: links ``p_d`` and ``q_d``.
    - ``RRPDyad`` ``d``: the link ``r_d`` from its revolute anchor ``r``, a
      slider block ``d_block`` pinned to it at ``d`` and sliding on the
      guide marker ``d_guide`` (along ``line_anchor1 -> line_anchor2``) of
      the body carrying both line anchors (prismatic joint ``d_slide``).
    - ``PPDyad`` ``d``: two blocks ``d_block1``/``d_block2`` on guides
      ``d_guide1``/``d_guide2``, pinned together at ``d``.
    - ``FixedDyad`` / ``PointTracker`` ``d``: a marker ``d`` of the body
      carrying both anchors; when no body does, a body ``p_d`` pinned at
      ``anchor1`` whose slot ``d_slot`` (through ``anchor1``, toward
      ``anchor2``) holds a block ``d_block`` pinned at ``anchor2``.
    - A point on several bodies: revolute joints joining them, named after
      the point (``X``), or ``X_body`` for each when there are more than
      two bodies (the hub is ``ground`` if the point is on it).
    - ``[sweep]``: the first input over a full turn (in the sense the crank
      turns), an ``ArcCrank`` over its arc, a ``LinearActuator`` over its
      stroke, 361 frames, tracing the last point that is not a ground
      point.

    Names are pylinkage's where they are valid dofplan names; a dot or
    white space becomes ``_`` (:func:`sanitize_name`) and a clash gets
    ``_2``, ``_3``... The returned mechanism's ``pylinkage_markers`` lists,
    for each component of ``linkage.components`` in order, the
    ``body.marker`` holding its point; ``name`` defaults to the linkage's.

    Raises :class:`ConversionError` (a :class:`dofplan.MechanismError` and
    a :class:`ValueError`) naming the pylinkage joint that cannot be
    expressed and why: cam followers and other classes, a crank about a
    moving point, a slide line through points on no common link, a dyad
    that does not assemble where it is. A drawing that dofplan itself
    refuses raises the :class:`dofplan.MechanismError` of ``from_dict``.
    """
    pl = _import_pylinkage()
    from pylinkage.simulation import Linkage

    if not isinstance(linkage, Linkage):
        mech_cls = getattr(getattr(pl, "mechanism", None), "Mechanism", None)
        if mech_cls is not None and isinstance(linkage, mech_cls):
            raise ConversionError(
                "from_pylinkage reads a pylinkage.Linkage (Ground, Crank, RRRDyad...); this is a "
                "pylinkage.mechanism.Mechanism (the low-level links-and-joints model), which it "
                "does not read: build the linkage with the component API"
            )
        raise TypeError(f"from_pylinkage takes a pylinkage.Linkage, not {type(linkage).__name__}")

    comps = list(linkage.components)
    if not comps:
        raise ConversionError(f"pylinkage linkage {linkage.name!r} has no components")
    index = {id(c): k for k, c in enumerate(comps)}
    kinds = [_component_kind(c) for c in comps]

    # What dofplan cannot say, before anything is built.
    for c, kind in zip(comps, kinds):
        if kind == "unknown":
            raise ConversionError(
                f"pylinkage joint {c.name!r} is a {type(c).__name__}, which dofplan cannot express: "
                "it converts Ground, Crank, ArcCrank, LinearActuator, RRRDyad, RRPDyad, PPDyad, "
                "FixedDyad and PointTracker (dofplan has no cam joint)"
            )
        for role, a in _anchor_refs(c, kind):
            if id(a) not in index:
                raise ConversionError(
                    f"pylinkage joint {c.name!r} ({type(c).__name__}): its {role} {a.name!r} is not "
                    "a component of the linkage; add it to the Linkage's components"
                )
        if kind in ("crank", "arc_crank", "linear"):
            a = _anchor_refs(c, kind)[0][1]
            if kinds[index[id(a)]] != "ground":
                raise ConversionError(
                    f"pylinkage joint {c.name!r} ({type(c).__name__}) turns about {a.name!r}, a "
                    f"{type(a).__name__}, not a Ground point: pylinkage drives it by its angle from "
                    "the world's x axis, and a dofplan input is relative to the body it is on, so "
                    "only actuators on Ground points convert"
                )

    # Solve order: each component once its anchors are placed (pylinkage's
    # own rule; its _find_solve_order is private).
    order: List[int] = [k for k, kind in enumerate(kinds) if kind == "ground"]
    placed = set(order)
    progress = True
    while progress and len(order) < len(comps):
        progress = False
        for k, c in enumerate(comps):
            if k in placed:
                continue
            if all(index[id(a)] in placed for _, a in _anchor_refs(c, kinds[k])):
                order.append(k)
                placed.add(k)
                progress = True
    if len(order) < len(comps):
        stuck = [comps[k].name for k in range(len(comps)) if k not in placed]
        raise ConversionError(
            f"pylinkage joints {', '.join(map(repr, stuck))} depend on each other in a cycle: "
            "no order places their anchors first"
        )

    positions = _assemble(comps, kinds, order, index)

    # Names: pylinkage's, sanitised, unique among the points.
    taken: set = set()
    names = [_unique(sanitize_name(c.name), taken) for c in comps]
    P = _Points(names, positions)

    inputs: List[Tuple[str, str, Any, Dict[str, Any]]] = []
    for k in order:
        c, kind = comps[k], kinds[k]
        anchors = [index[id(a)] for _, a in _anchor_refs(c, kind)]
        pos = positions[k]
        if kind == "ground":
            P.put(k, "ground")
        elif kind in ("crank", "arc_crank"):
            a = anchors[0]
            body = P.new_body(names[k])
            P.put(a, body)
            P.put(k, body)
            if kind == "crank":
                turn = -360.0 if c.angular_velocity < 0 else 360.0
                sweep = {"from": 0.0, "to": turn}
            else:
                # The arc, in degrees from where the crank is on it.
                now = float(c.angle)
                sweep = {"from": math.degrees(c.arc_start - now), "to": math.degrees(c.arc_end - now)}
            inputs.append((names[k], "angle", ("revolute", a, body), sweep))
        elif kind == "linear":
            a = anchors[0]
            body = P.new_body(names[k])
            P.put(k, body)
            d = (math.cos(c.angle), math.sin(c.angle))
            g = P.guide("ground", f"{names[k]}_guide", positions[a], d)
            j = P.prismatic(f"{names[k]}_slide", f"ground.{g}", f"{body}.{names[k]}")
            ext = (pos[0] - positions[a][0]) * d[0] + (pos[1] - positions[a][1]) * d[1]
            inputs.append((names[k], "slide", j, {"from": -ext, "to": c.stroke - ext}))
        elif kind == "rrr":
            for a in anchors:
                body = P.new_body(f"{names[a]}_{names[k]}")
                P.put(a, body)
                P.put(k, body)
        elif kind == "rrp":
            r, l1, l2 = anchors
            guide_body = P.common_body(l1, l2)
            if guide_body is None:
                raise ConversionError(
                    f"pylinkage joint {c.name!r} (RRPDyad) slides on the line through "
                    f"{comps[l1].name!r} and {comps[l2].name!r}, which are on no common rigid link "
                    "(pylinkage moves them independently): a dofplan prismatic joint needs its "
                    "line fixed in one body"
                )
            d = _unit(
                positions[l2][0] - positions[l1][0],
                positions[l2][1] - positions[l1][1],
                f"pylinkage joint {c.name!r} (RRPDyad): its line anchors {comps[l1].name!r} and "
                f"{comps[l2].name!r} coincide, so the line has no direction",
            )
            rod = P.new_body(f"{names[r]}_{names[k]}")
            P.put(r, rod)
            P.put(k, rod)
            block = P.new_body(f"{names[k]}_block")
            P.put(k, block)
            g = P.guide(guide_body, f"{names[k]}_guide", pos, d)
            P.prismatic(f"{names[k]}_slide", f"{guide_body}.{g}", f"{block}.{names[k]}")
        elif kind == "pp":
            for i, (l1, l2) in enumerate(((anchors[0], anchors[1]), (anchors[2], anchors[3])), 1):
                guide_body = P.common_body(l1, l2)
                if guide_body is None:
                    raise ConversionError(
                        f"pylinkage joint {c.name!r} (PPDyad): its line {i} runs through "
                        f"{comps[l1].name!r} and {comps[l2].name!r}, which are on no common rigid "
                        "link: a dofplan prismatic joint needs its line fixed in one body"
                    )
                d = _unit(
                    positions[l2][0] - positions[l1][0],
                    positions[l2][1] - positions[l1][1],
                    f"pylinkage joint {c.name!r} (PPDyad): the two points of its line {i} coincide",
                )
                block = P.new_body(f"{names[k]}_block{i}")
                P.put(k, block)
                g = P.guide(guide_body, f"{names[k]}_guide{i}", pos, d)
                P.prismatic(f"{names[k]}_slide{i}", f"{guide_body}.{g}", f"{block}.{names[k]}")
        elif kind == "fixed":
            a1, a2 = anchors
            body = P.common_body(a1, a2)
            if body is not None:
                # The anchors are a rigid pair: the point is on their body.
                P.put(k, body)
            else:
                # The anchors move apart: the point rides a body pinned at
                # anchor1 whose x axis always points at anchor2, i.e. a slot
                # through anchor1 in which anchor2 slides (a pin in a slot,
                # which dofplan writes as a block: a prismatic and a
                # revolute joint).
                d = _unit(
                    positions[a2][0] - positions[a1][0],
                    positions[a2][1] - positions[a1][1],
                    f"pylinkage joint {c.name!r} ({type(c).__name__}): its anchors "
                    f"{comps[a1].name!r} and {comps[a2].name!r} coincide, so its angle has no "
                    "reference direction",
                )
                body = P.new_body(f"{names[a1]}_{names[k]}")
                P.put(a1, body)
                P.put(k, body)
                slot = P.guide(body, f"{names[k]}_slot", positions[a1], d)
                block = P.new_body(f"{names[k]}_block")
                P.put(a2, block)
                P.prismatic(f"{names[k]}_slot", f"{body}.{slot}", f"{block}.{names[a2]}")

    if not inputs:
        raise ConversionError(
            f"pylinkage linkage {linkage.name!r} has no Crank, ArcCrank or LinearActuator: "
            "a dofplan mechanism needs an input to move it"
        )

    # Revolute joints where a point is on several bodies: from a hub (the
    # ground when the point is on it) to each other body.
    revolute: Dict[Tuple[int, str], str] = {}
    for k in range(len(comps)):
        bodies = P.carriers[k]
        if len(bodies) < 2:
            continue
        hub = "ground" if "ground" in bodies else bodies[0]
        others = [b for b in bodies if b != hub]
        for b in others:
            base = names[k] if len(others) == 1 else f"{names[k]}_{b}"
            if len(others) == 1:
                # The point's own name: it was reserved for this joint.
                P.joint_names.discard(base)
            j = _unique(base, P.joint_names)
            P.joints[j] = {"kind": "revolute", "markers": [f"{hub}.{names[k]}", f"{b}.{names[k]}"]}
            revolute[(k, b)] = j

    d_inputs: Dict[str, Dict[str, str]] = {}
    for input_name, kind, joint, _ in inputs:
        if kind == "angle":
            joint = revolute[(joint[1], joint[2])]
        d_inputs[input_name] = {"kind": kind, "joint": joint}

    trace_k = next((k for k in reversed(range(len(comps))) if kinds[k] != "ground"), None)
    first, _, _, span = inputs[0]
    sweep: Dict[str, Any] = {"input": first, "from": span["from"], "to": span["to"], "steps": 361}
    if trace_k is not None:
        sweep["trace"] = [f"{P.carriers[trace_k][0]}.{names[trace_k]}"]

    mech_name = sanitize_name(name if name is not None else linkage.name)
    d = {
        "name": mech_name,
        "bodies": P.bodies,
        "joints": P.joints,
        "inputs": d_inputs,
        "sweep": sweep,
    }
    m = from_dict(d, name=f"pylinkage:{mech_name}")
    # Where each pylinkage point went, in the linkage's component order.
    m.pylinkage_markers = [f"{P.carriers[k][0]}.{names[k]}" for k in range(len(comps))]
    return m


def _assemble(comps: List[Any], kinds: List[str], order: List[int], index: Dict[int, int]) -> List[Tuple[float, float]]:
    """Every point where pylinkage puts it at the linkage's present input:
    each component solved from its anchors by pylinkage's own solver
    functions, from its current position (the same choice of branch as a
    ``step(dt=0)``), without touching the linkage (a step would, and the
    actuators' set_coord resets their direction of travel)."""
    from pylinkage.solver.joints import (
        solve_crank,
        solve_fixed,
        solve_line_line,
        solve_linear,
        solve_revolute,
    )

    pos: List[Optional[Tuple[float, float]]] = [None] * len(comps)

    def at(a: Any) -> Tuple[float, float]:
        return pos[index[id(getattr(a, "_parent", a))]]  # type: ignore[return-value]

    for k in order:
        c, kind = comps[k], kinds[k]
        cur = (c.x, c.y)
        if kind == "ground":
            p = (float(c.x), float(c.y)) if c.x is not None and c.y is not None else None
        elif kind == "crank":
            ax, ay = at(c.anchor)
            if cur[0] is None or cur[1] is None:
                p = None
            else:
                p = solve_crank(float(cur[0]), float(cur[1]), ax, ay, float(c.radius), 0.0, 0.0)
        elif kind == "arc_crank":
            ax, ay = at(c.anchor)
            p = (ax + c.radius * math.cos(c.angle), ay + c.radius * math.sin(c.angle))
        elif kind == "linear":
            ax, ay = at(c.anchor)
            p = (ax + c.extension * math.cos(c.angle), ay + c.extension * math.sin(c.angle))
        elif kind == "rrr":
            (x1, y1), (x2, y2) = at(c.anchor1), at(c.anchor2)
            hx = cur[0] if cur[0] is not None else (x1 + x2) / 2
            hy = cur[1] if cur[1] is not None else (y1 + y2) / 2
            p = solve_revolute(hx, hy, x1, y1, float(c.distance1), x2, y2, float(c.distance2))
        elif kind == "rrp":
            rx, ry = at(c.revolute_anchor)
            (x1, y1), (x2, y2) = at(c.line_anchor1), at(c.line_anchor2)
            hx = cur[0] if cur[0] is not None else rx
            hy = cur[1] if cur[1] is not None else ry
            p = solve_linear(hx, hy, rx, ry, float(c.distance), x1, y1, x2, y2)
        elif kind == "pp":
            pts = [at(a) for a in (c.line1_anchor1, c.line1_anchor2, c.line2_anchor1, c.line2_anchor2)]
            p = solve_line_line(*[v for xy in pts for v in xy])
        else:  # fixed
            (x1, y1), (x2, y2) = at(c.anchor1), at(c.anchor2)
            p = solve_fixed(x1, y1, x2, y2, float(c.distance), float(c.angle))
        if p is None or not all(math.isfinite(float(v)) for v in p):
            raise ConversionError(
                f"pylinkage joint {c.name!r} ({type(c).__name__}) does not assemble where the "
                "linkage is now (its constraints have no solution from its anchors' positions): "
                "dofplan draws the mechanism at a pose that assembles; move the crank to one"
            )
        pos[k] = (float(p[0]), float(p[1]))
    return pos  # type: ignore[return-value]


# --------------------------------------------------------------------------
# dofplan -> pylinkage
# --------------------------------------------------------------------------


def _wrap(deg: np.ndarray) -> np.ndarray:
    return (deg + 180.0) % 360.0 - 180.0


def to_pylinkage(mechanism: Mechanism) -> Any:
    """Converts a dofplan mechanism into a ``pylinkage.Linkage``, where
    pylinkage can express it, at the drawn pose (input 0).

    pylinkage builds a linkage from the ground and one crank, one dyad at a
    time. What converts: a planar mechanism of revolute joints and sliders
    with one ``angle`` input that turns a body about the ground at a
    revolute joint (the crank), every other body reachable by

    - an RRR dyad: two bodies, each pinned at a point already placed,
      meeting at a pin (``RRRDyad``);
    - an RRP dyad: a body pinned at a point already placed, and a slider
      block on a guide of the ground pinned to it (``RRPDyad``; its line is
      two new Ground points ``J_line1``, ``J_line2`` for the prismatic
      joint ``J``);
    - any further point of a body already placed (``FixedDyad``);
    - a pin in a slot: a body pinned at a placed point whose slot, running
      through that pin, holds a block pinned at another placed point (what
      :func:`from_pylinkage` makes of a ``FixedDyad`` whose anchors are on
      no common link): its points are FixedDyads of the two pins.

    Each pylinkage point is a pin (the markers a revolute joint joins,
    named after the markers' common name, else the first joint) or a
    marker on no joint (named after the marker, or ``body.marker`` when
    the name is taken); points on a fixed body are ``Ground`` points. The
    crank's ``angular_velocity`` is the mechanism's sweep step (1 degree
    without a sweep), in radians, with the sign of the way the crank turns
    as the input grows. Which bodies are fixed, which joint the input
    drives and the slide directions are read from a few frames of the
    mechanism's own motion (±60 degrees of the input), since the Python
    API does not list them.

    Anything else raises :class:`ConversionError` (a :class:`ValueError`)
    naming the joint, body or input and why: spatial mechanisms, no input
    or several, a ``slide`` input, an input between two moving bodies,
    constraints, blocks carrying more than their pin, and bodies pylinkage
    cannot reach one dyad at a time (a triad, a slider on a moving guide
    other than the slot above, a loop that needs a second freedom).
    """
    _import_pylinkage()
    from pylinkage.actuators import Crank
    from pylinkage.components import Ground
    from pylinkage.dyads import FixedDyad, RRPDyad, RRRDyad
    from pylinkage.simulation import Linkage

    m = mechanism
    where = f"mechanism {m.name!r}"
    if m.dimension != 2:
        raise ConversionError(f"{where} is spatial: pylinkage's linkages are planar")
    if len(m.inputs) != 1:
        raise ConversionError(
            f"{where} has {len(m.inputs)} inputs ({', '.join(m.inputs) or 'none'}): to_pylinkage "
            "converts a mechanism driven by one crank"
        )
    input_name, input_kind = m.inputs[0], m.input_kinds[0]
    if input_kind != "angle":
        raise ConversionError(
            f"{where}: input {input_name!r} is a {input_kind}; to_pylinkage converts one angle "
            "input (a crank); pylinkage's LinearActuator oscillates within its stroke, unlike a "
            "dofplan slide"
        )
    joints = list(m.joint_markers)
    for jname, kind, _, _ in joints:
        if kind not in ("revolute", "prismatic"):
            raise ConversionError(
                f"{where}: {jname!r} is a {kind} joint or constraint, which pylinkage's dyads "
                "cannot express (to_pylinkage converts revolute and prismatic joints)"
            )

    # The drawing, and a few frames each way to see what moves.
    marker_names = m.markers
    mi = {n: k for k, n in enumerate(marker_names)}
    bodies = m.bodies
    bi = {n: k for k, n in enumerate(bodies)}
    drawn = m.simulate([0.0])
    if not drawn.solved[0]:
        raise ConversionError(f"{where} does not solve at its drawn pose (input 0)")
    X = drawn.markers[0]
    size = float(np.max(np.ptp(X, axis=0))) or 1.0
    probe = np.arange(0.0, 61.0, 2.0)
    runs = [m.simulate(probe), m.simulate(-probe)]
    poses = np.concatenate([r.poses[r.solved] for r in runs])
    marks = np.concatenate([r.markers[r.solved] for r in runs])
    inp = np.concatenate([r.inputs[r.solved, 0] for r in runs])
    if np.count_nonzero(np.abs(inp) > 1e-9) < 2:
        raise ConversionError(
            f"{where}: input {input_name!r} does not move the mechanism within 60 degrees of its "
            "drawn pose, so to_pylinkage cannot tell its moving bodies from its ground"
        )
    tol_angle, tol_len = 1e-9, 1e-9 * size
    still = (np.max(np.abs(_wrap(poses[:, :, 0] - poses[:1, :, 0])), axis=0) <= tol_angle) & (
        np.max(np.linalg.norm(poses[:, :, 1:] - poses[:1, :, 1:], axis=2), axis=0) <= tol_len
    )
    # A body that stays put at every probe frame is ground to pylinkage: a
    # fixed body, or one held still by its joints (pylinkage's Ground).
    fixed = [bool(s) for s in still]
    if not any(fixed):
        raise ConversionError(f"{where} has no body that stays still: pylinkage needs a ground")

    def body_of(marker: str) -> str:
        return marker.split(".", 1)[0]

    # The crank: a revolute joint between a still body and a moving one
    # whose relative angle is the input (second marker's body turning
    # counter-clockwise relative to the first's as the input grows).
    crank = None
    for jname, kind, a, b in joints:
        if kind != "revolute":
            continue
        ba, bb = bi[body_of(a)], bi[body_of(b)]
        if fixed[ba] == fixed[bb]:
            continue
        rel = poses[:, bb, 0] - poses[:, ba, 0]
        if np.max(np.abs(_wrap(rel - inp))) <= 1e-7:
            moving, ground_marker = (bb, a) if fixed[ba] else (ba, b)
            sense = 1.0 if moving == bb else -1.0  # crank angle per unit of input
            crank = (jname, moving, ground_marker, sense)
            break
    if crank is None:
        raise ConversionError(
            f"{where}: input {input_name!r} does not turn a body about the ground at a revolute "
            "joint; pylinkage's Crank turns about a Ground point, its angle measured from the "
            "world's x axis (an input between two moving bodies does not convert)"
        )
    crank_joint, crank_body, crank_ground_marker, sense = crank

    # Points: markers joined by revolute joints coincide; each class of them
    # is one pylinkage point. Markers of prismatic joints are not points.
    parent = {n: n for n in marker_names}

    def find(n: str) -> str:
        while parent[n] != n:
            parent[n] = parent[parent[n]]
            n = parent[n]
        return n

    first_joint: Dict[str, str] = {}
    in_prismatic = set()
    prismatics = []
    for jname, kind, a, b in joints:
        if kind == "revolute":
            ra, rb = find(a), find(b)
            if ra != rb:
                parent[rb] = ra
        else:
            in_prismatic.update((a, b))
            prismatics.append((jname, a, b))
    classes: Dict[str, List[str]] = {}
    for n in marker_names:
        classes.setdefault(find(n), []).append(n)
    for jname, kind, a, b in joints:
        if kind == "revolute":
            first_joint.setdefault(find(a), jname)

    points: List[Dict[str, Any]] = []
    taken: set = set()
    # Joined points first (joint order), then lone markers (marker order).
    roots = [find(a) for j, kind, a, _ in joints if kind == "revolute"]
    seen = set()
    for root in roots + [find(n) for n in marker_names]:
        if root in seen:
            continue
        seen.add(root)
        members = classes[root]
        joined = root in first_joint
        if not joined and members[0] in in_prismatic:
            continue
        short = {n.split(".", 1)[1] for n in members}
        if len(short) == 1 and next(iter(short)) not in taken:
            pname = next(iter(short))
        elif joined and first_joint[root] not in taken:
            pname = first_joint[root]
        else:
            pname = members[0]
        pname = _unique(pname, taken)
        points.append(
            {
                "name": pname,
                "markers": members,
                "bodies": sorted({bi[body_of(n)] for n in members}),
                "at": (float(X[mi[members[0]], 0]), float(X[mi[members[0]], 1])),
                "component": None,
            }
        )
    point_of = {n: p for p in points for n in p["markers"]}
    body_points: Dict[int, List[Dict[str, Any]]] = {k: [] for k in range(len(bodies))}
    for p in points:
        for b in p["bodies"]:
            body_points[b].append(p)

    components: List[Any] = []

    def place(p: Dict[str, Any], comp: Any) -> None:
        p["component"] = comp
        components.append(comp)

    # Ground points.
    for p in points:
        if any(fixed[b] for b in p["bodies"]):
            place(p, Ground(p["at"][0], p["at"][1], name=p["name"]))

    # The crank: from its ground pin to its first other point.
    anchor = point_of.get(crank_ground_marker)
    others = [p for p in body_points[crank_body] if p is not anchor and _dist(p["at"], anchor["at"]) > tol_len]
    if not others:
        raise ConversionError(
            f"{where}: the crank {bodies[crank_body]!r} (driven at joint {crank_joint!r}) carries no "
            "point but its pivot, so pylinkage's Crank has no output"
        )
    out = others[0]
    step_deg = 1.0
    sw = m.sweep
    if sw:
        for entry in sw["inputs"]:
            if entry["input"] == input_name and sw["steps"] > 1 and entry["to"] != entry["from"]:
                step_deg = (entry["to"] - entry["from"]) / (sw["steps"] - 1)
    ox, oy = out["at"][0] - anchor["at"][0], out["at"][1] - anchor["at"][1]
    place(
        out,
        Crank(
            anchor["component"],
            radius=math.hypot(ox, oy),
            angular_velocity=sense * math.radians(step_deg),
            initial_angle=math.atan2(oy, ox),
            name=out["name"],
        ),
    )

    # Slider blocks: the side of a prismatic joint that carries one point
    # (the pin); the other side is the guide. A guide on the ground makes
    # an RRP dyad; a guide on a moving body, a pin in a slot (rule 4).
    blocks: Dict[int, Tuple[str, str, int]] = {}
    for jname, a, b in prismatics:
        ba, bb = bi[body_of(a)], bi[body_of(b)]
        if fixed[ba] and fixed[bb]:
            continue  # two still bodies: both are ground to pylinkage
        if fixed[ba] or fixed[bb]:
            block, guide = (bb, ba) if fixed[ba] else (ba, bb)
        else:
            # Both move: the block is the side with a single point.
            block, guide = (bb, ba) if len(body_points[bb]) == 1 else (ba, bb)
        if block in blocks:
            raise ConversionError(
                f"{where}: body {bodies[block]!r} slides on two prismatic joints "
                f"({blocks[block][0]!r}, {jname!r}); to_pylinkage converts a block on one guide"
            )
        if len(body_points[block]) != 1:
            raise ConversionError(
                f"{where}: slider block {bodies[block]!r} of prismatic joint {jname!r} carries "
                f"{len(body_points[block])} points; to_pylinkage converts a block pinned to one link "
                "at one point (pylinkage's RRPDyad, or a pin in a slot through a pivot)"
            )
        blocks[block] = (jname, b if block == bb else a, guide)

    def known(p: Dict[str, Any]) -> bool:
        return p["component"] is not None

    def located(b: int) -> bool:
        if fixed[b]:
            return True
        kp = [p for p in body_points[b] if known(p)]
        if b in blocks:
            return len(kp) == len(body_points[b])
        return any(_dist(p["at"], q["at"]) > tol_len for p in kp for q in kp)

    def placed_on(b: int, exclude: Dict[str, Any]) -> List[Dict[str, Any]]:
        return [p for p in body_points[b] if known(p) and p is not exclude]

    progress = True
    while progress and not all(known(p) for p in points):
        progress = False
        # 1. The rest of a placed body: each point at its distance and angle
        #    from two placed points of the body.
        for b in range(len(bodies)):
            if fixed[b] or b in blocks or not located(b):
                continue
            kp = placed_on(b, None)
            k1, k2 = max(((p, q) for p in kp for q in kp), key=lambda pq: _dist(pq[0]["at"], pq[1]["at"]))
            for p in body_points[b]:
                if known(p):
                    continue
                base = math.atan2(k2["at"][1] - k1["at"][1], k2["at"][0] - k1["at"][0])
                dx, dy = p["at"][0] - k1["at"][0], p["at"][1] - k1["at"][1]
                place(
                    p,
                    FixedDyad(
                        k1["component"],
                        k2["component"],
                        distance=math.hypot(dx, dy),
                        angle=math.atan2(dy, dx) - base,
                        name=p["name"],
                    ),
                )
                progress = True
        if progress:
            continue
        for p in points:
            if known(p):
                continue
            # 2. RRR: two bodies through p, each pinned at a placed point.
            arms = []
            for b in p["bodies"]:
                if located(b) or b in blocks:
                    continue
                for q in placed_on(b, p):
                    arms.append((b, q))
            pair = next(
                (
                    (u, v)
                    for i, u in enumerate(arms)
                    for v in arms[i + 1 :]
                    if u[0] != v[0] and u[1] is not v[1] and _dist(u[1]["at"], v[1]["at"]) > tol_len
                ),
                None,
            )
            if pair is not None:
                (_, q1), (_, q2) = pair
                place(
                    p,
                    RRRDyad(
                        q1["component"],
                        q2["component"],
                        distance1=_dist(q1["at"], p["at"]),
                        distance2=_dist(q2["at"], p["at"]),
                        x=p["at"][0],
                        y=p["at"][1],
                        name=p["name"],
                    ),
                )
                progress = True
                continue
            # 3. RRP: a slider block through p on a ground guide, and a body
            #    through p pinned at a placed point.
            block = next((b for b in p["bodies"] if b in blocks and fixed[blocks[b][2]]), None)
            arm = next((q for b, q in arms if b != block), None)
            if block is None or arm is None:
                continue
            jname, slider_marker, _ = blocks[block]
            u = _slide_direction(marks[:, mi[slider_marker], :], tol_len)
            if u is None:
                raise ConversionError(
                    f"{where}: the slider of prismatic joint {jname!r} does not move within 60 "
                    "degrees of the input, so to_pylinkage cannot tell its direction"
                )
            l1 = Ground(p["at"][0], p["at"][1], name=_unique(f"{jname}_line1", taken))
            l2 = Ground(p["at"][0] + u[0] * size, p["at"][1] + u[1] * size, name=_unique(f"{jname}_line2", taken))
            components[:0] = [l1, l2]  # ground points first, as pylinkage lists them
            place(
                p,
                RRPDyad(
                    arm["component"],
                    l1,
                    l2,
                    distance=_dist(arm["at"], p["at"]),
                    x=p["at"][0],
                    y=p["at"][1],
                    name=p["name"],
                ),
            )
            progress = True
        if progress:
            continue
        # 4. A pin in a slot: a body pinned at one placed point k1, whose
        #    slot holds a block pinned at another placed point k2. When the
        #    slot runs through k1 the body always points at k2, so each of
        #    its points is pylinkage's FixedDyad(k1, k2); that is checked on
        #    the probe frames rather than read from the slot's direction
        #    (which the Python API does not give).
        for block, (jname, _, guide) in blocks.items():
            if fixed[guide] or located(guide) or not located(block):
                continue
            k2 = body_points[block][0]
            on_guide = placed_on(guide, k2)
            if len(on_guide) != 1 or _dist(on_guide[0]["at"], k2["at"]) <= tol_len:
                continue
            k1 = on_guide[0]
            fixed_dyads = []
            for p in body_points[guide]:
                if known(p):
                    continue
                dyad = _fixed_dyad_if_rigid(p, k1, k2, marks, mi, tol_len)
                if dyad is None:
                    break
                fixed_dyads.append((p, dyad))
            else:
                for p, (distance, angle) in fixed_dyads:
                    place(p, FixedDyad(k1["component"], k2["component"], distance=distance, angle=angle, name=p["name"]))
                    progress = True

    missing = [p for p in points if not known(p)]
    if missing:
        stuck = sorted({bodies[b] for p in missing for b in p["bodies"] if not located(b)})
        raise ConversionError(
            f"{where}: points {', '.join(repr(p['name']) for p in missing)} (bodies "
            f"{', '.join(map(repr, stuck))}) cannot be reached from the ground and the crank one "
            "pylinkage dyad at a time (RRR: two links meeting at a pin; RRP: a link and a slider "
            "on a ground guide): the mechanism needs a triad, a guide on a moving link or "
            "another input, which pylinkage's Linkage does not solve"
        )
    return Linkage(components, name=m.name)


def _fixed_dyad_if_rigid(
    p: Dict[str, Any], k1: Dict[str, Any], k2: Dict[str, Any], marks: np.ndarray, mi: Dict[str, int], tol: float
) -> Optional[Tuple[float, float]]:
    """p's (distance, angle) from k1 relative to the line k1 -> k2, as a
    FixedDyad holds it, if p keeps them in every probe frame; else None."""
    dx, dy = p["at"][0] - k1["at"][0], p["at"][1] - k1["at"][1]
    distance = math.hypot(dx, dy)
    angle = math.atan2(dy, dx) - math.atan2(k2["at"][1] - k1["at"][1], k2["at"][0] - k1["at"][0])
    a = marks[:, mi[k1["markers"][0]], :]
    b = marks[:, mi[k2["markers"][0]], :]
    q = marks[:, mi[p["markers"][0]], :]
    base = np.arctan2(b[:, 1] - a[:, 1], b[:, 0] - a[:, 0]) + angle
    expect = a + distance * np.stack([np.cos(base), np.sin(base)], axis=1)
    if np.max(np.linalg.norm(expect - q, axis=1)) > tol:
        return None
    return distance, angle


def _dist(a: Sequence[float], b: Sequence[float]) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def _slide_direction(path: np.ndarray, tol: float) -> Optional[Tuple[float, float]]:
    """The unit direction a marker moves along (from its frames), or None
    if it does not move."""
    disp = path - path[0]
    norms = np.linalg.norm(disp, axis=1)
    k = int(np.argmax(norms))
    if norms[k] <= tol:
        return None
    return (float(disp[k, 0] / norms[k]), float(disp[k, 1] / norms[k]))
