"""Mechanisms written in code: a :class:`Builder` collects bodies, markers,
joints, inputs and a sweep, and ``build()`` loads them as a mechanism file
would be loaded (the same checks, the same errors, naming the entry).

::

    b = dofplan.Builder("fourbar")
    b.ground(A=(0, 0), D=(4, 0))
    b.body("crank", A=(0, 0), B=(1, 1))
    b.body("coupler", B=(1, 1), C=(4.5, 2.5), P=(3, 3.5))
    b.body("rocker", C=(4.5, 2.5), D=(4, 0))
    b.revolute("A", "ground.A", "crank.A").revolute("B", "crank.B", "coupler.B")
    b.revolute("C", "coupler.C", "rocker.C").revolute("D", "rocker.D", "ground.D")
    b.crank("theta", joint="A")             # an angle input, as pylinkage's Crank
    b.sweep("theta", 0, 360, steps=361, trace=["coupler.P"])
    m = b.build()

Coordinates are those of the drawn pose (the pose at input 0), as in a
file. Names follow the file's rules (no dots or spaces).
"""

from __future__ import annotations

import copy
from typing import Any, Dict, Iterable, Optional, Sequence, Tuple, Union

Point = Sequence[float]
#: A marker: a point, or a point and a direction ``((x, y), (dx, dy))``
#: (prismatic joints and line constraints need the direction).
MarkerSpec = Union[Point, Tuple[Point, Point]]


def _marker(spec: Any) -> Any:
    """A marker's file form: ``[x, y]`` or ``{at, dir}``."""
    if isinstance(spec, dict):
        return dict(spec)
    items = list(spec)
    if len(items) == 2 and all(isinstance(v, (list, tuple)) for v in items):
        at, d = items
        return {"at": [float(v) for v in at], "dir": [float(v) for v in d]}
    return [float(v) for v in items]


class Builder:
    """Collects a mechanism entry by entry; :meth:`build` loads it.

    Every method returns the builder, so calls chain. Nothing is checked
    before :meth:`build`, which checks everything at once as ``dofplan
    check`` does and raises :class:`dofplan.MechanismError` naming the
    entries at fault (``joints.A.markers[1]``).
    """

    def __init__(self, name: str, dimension: int = 2) -> None:
        self._d: Dict[str, Any] = {"name": name}
        if dimension != 2:
            self._d["dimension"] = dimension
        self._d["bodies"] = {}
        self._d["joints"] = {}

    def body(self, name: str, *, fixed: bool = False, **markers: MarkerSpec) -> "Builder":
        """A body and its markers, each a point in the drawn pose (or a point
        and a direction)."""
        body: Dict[str, Any] = {"markers": {k: _marker(v) for k, v in markers.items()}}
        if fixed:
            body = {"fixed": True, **body}
        self._d["bodies"][name] = body
        return self

    def ground(self, name: str = "ground", **markers: MarkerSpec) -> "Builder":
        """The fixed body (pylinkage's ground / static points)."""
        return self.body(name, fixed=True, **markers)

    def marker(self, body: str, name: str, at: Point, dir: Optional[Point] = None) -> "Builder":
        """One more marker on a body already added."""
        spec = (at, dir) if dir is not None else at
        self._d["bodies"].setdefault(body, {"markers": {}})["markers"][name] = _marker(spec)
        return self

    def _joint(self, kind: str, name: str, a: str, b: str) -> "Builder":
        self._d["joints"][name] = {"kind": kind, "markers": [a, b]}
        return self

    def revolute(self, name: str, a: str, b: str) -> "Builder":
        """A revolute joint: markers ``a`` and ``b`` (``body.marker``)
        coincide (pylinkage's pivots)."""
        return self._joint("revolute", name, a, b)

    def prismatic(self, name: str, a: str, b: str) -> "Builder":
        """A prismatic joint: ``b`` slides along the direction of ``a`` (which
        carries one), the bodies never turning relative to each other."""
        return self._joint("prismatic", name, a, b)

    def spherical(self, name: str, a: str, b: str) -> "Builder":
        """A spherical joint (spatial mechanisms)."""
        return self._joint("spherical", name, a, b)

    def joint(self, kind: str, name: str, a: str, b: str) -> "Builder":
        """A joint of any kind the file format has (e.g. "universal",
        "cylindrical" in space)."""
        return self._joint(kind, name, a, b)

    def constraint(self, kind: str, name: str, a: str, b: str) -> "Builder":
        """A primitive constraint: "coincident", "in-line" or "offset"."""
        self._d.setdefault("constraints", {})[name] = {"kind": kind, "markers": [a, b]}
        return self

    def input(self, name: str, *, joint: str, kind: str = "angle") -> "Builder":
        """An input driving a joint: "angle" (degrees, on a revolute joint)
        or "slide" (length, on a prismatic joint)."""
        self._d.setdefault("inputs", {})[name] = {"kind": kind, "joint": joint}
        return self

    def crank(self, name: str, *, joint: str) -> "Builder":
        """An angle input on a revolute joint (pylinkage's Crank)."""
        return self.input(name, joint=joint, kind="angle")

    def sweep(
        self,
        input: str,
        start: float,
        stop: float,
        *,
        steps: int = 361,
        trace: Iterable[str] = (),
    ) -> "Builder":
        """The sweep ``simulate()`` runs by default: ``steps`` values of
        ``input`` from ``start`` to ``stop``, tracing markers ``trace``."""
        self._d["sweep"] = {
            "input": input,
            "from": float(start),
            "to": float(stop),
            "steps": int(steps),
            "trace": list(trace),
        }
        return self

    def to_dict(self) -> Dict[str, Any]:
        """The mechanism as a dict shaped like its JSON file."""
        return copy.deepcopy(self._d)

    def to_toml(self) -> str:
        """The mechanism as a TOML file's text (as ``dofplan`` reads it)."""
        return _toml(self._d)

    def build(self) -> "Mechanism":
        """Loads the mechanism (:func:`dofplan.from_dict`)."""
        from . import from_dict

        return from_dict(self._d, name=f"<builder {self._d['name']}>")


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {v!r} to TOML")


def _key(k: str) -> str:
    bare = k and all(c.isalnum() or c in "_-" for c in k)
    return k if bare else _value(k)


def _toml(d: Dict[str, Any]) -> str:
    lines = []
    for k, v in d.items():
        if not isinstance(v, dict):
            lines.append(f"{_key(k)} = {_value(v)}")
    for section in ("bodies", "joints", "constraints", "inputs"):
        for name, entry in d.get(section, {}).items():
            lines.append(f"\n[{section}.{_key(name)}]")
            lines.extend(f"{_key(k)} = {_value(v)}" for k, v in entry.items())
    if "sweep" in d:
        lines.append("\n[sweep]")
        lines.extend(f"{_key(k)} = {_value(v)}" for k, v in d["sweep"].items())
    return "\n".join(lines) + "\n"
