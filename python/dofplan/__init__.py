"""dofplan for Python: mechanism geometry by compiled plans.

Load a planar or spatial mechanism file, check it, read its plan, and run
its inputs through the plan into NumPy arrays::

    import dofplan
    m = dofplan.load("mechanisms/fourbar.toml")
    print(m.check().mobility)          # what `dofplan check` reports
    r = m.simulate()                   # the file's [sweep]
    path = r.marker("coupler.P")       # frames x 2
    r.poses.shape                      # (frames, bodies, 3): angle, x, y

Every number comes from the same Rust functions the `dofplan` command
line calls: the frames, the breaks and the error messages are the CLI's.
Errors are :class:`MechanismError` (a file that does not load, with its
diagnostics) and :class:`PlanError` (a mechanism without a plan), both
subclasses of :class:`DofplanError`.
"""

from __future__ import annotations

import functools
import json
import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _dofplan
from ._dofplan import DofplanError, MechanismError, PlanError, __version__
from .builder import Builder

__all__ = [
    "Assembled",
    "Builder",
    "Check",
    "DofplanError",
    "Mechanism",
    "MechanismError",
    "Plan",
    "PlanError",
    "Result",
    "assemble",
    "assemble_text",
    "from_dict",
    "from_pmks",
    "from_pylinkage",
    "load",
    "loads",
    "pmks_to_toml",
    "synth",
    "Synthesis",
    "to_pylinkage",
    "__version__",
]


def load(path: Union[str, "os.PathLike[str]"]) -> "Mechanism":
    """Loads a mechanism file: TOML, or JSON when its name ends in ``.json``.

    Raises :class:`MechanismError` when the file does not load; its message
    is the one ``dofplan check`` prints and ``.diagnostics`` lists each
    error as a dict (``file``, ``line``, ``column``, ``message``, ``help``...).
    """
    return Mechanism(_dofplan.load(path))


def loads(text: str, format: str = "toml", name: str = "<string>") -> "Mechanism":
    """Loads a mechanism from text; ``format`` is ``"toml"`` or ``"json"``,
    ``name`` the file name errors show."""
    return Mechanism(_dofplan.loads(text, format, name))


def from_dict(d: Mapping[str, Any], name: str = "<dict>") -> "Mechanism":
    """Loads a mechanism from a dict shaped like a mechanism file (the JSON
    form of ``docs/guide/mechanism-files.md``). Errors name the path in the
    dict (``joints.A.markers[1]``)."""
    try:
        text = json.dumps(d, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise MechanismError(f"{name}: error: the dict is not a mechanism file's data: {e}") from None
    return loads(text, "json", name)


def from_pmks(
    text: str,
    inputs: Optional[Sequence[Tuple[int, int]]] = None,
    name: str = "imported",
) -> "Mechanism":
    """Reads a Pyslvs (PMKS) expression, ``M[J[R, P[x, y], L[ground, L1]],
    ...]``, optionally followed by its input pairs (``((0, 1),)``), as
    ``dofplan import`` does: each point a marker on the links it lists,
    R points revolute joints, P points prismatic joints, RP points a slider
    block; each input pair ``(base, drive)`` an angle input. ``inputs``
    replaces the pairs written in the text. The mechanism file's text is
    :func:`pmks_to_toml`'s; what cannot be expressed raises
    :class:`MechanismError` pointing into the expression."""
    toml, _ = _dofplan.pmks_to_toml(text, None if inputs is None else [tuple(p) for p in inputs], name)
    return loads(toml, "toml", f"{name}.toml")


def pmks_to_toml(
    text: str,
    inputs: Optional[Sequence[Tuple[int, int]]] = None,
    name: str = "imported",
) -> str:
    """The mechanism file (TOML) :func:`from_pmks` loads, with a header
    saying where each point went and how Pyslvs's angles map to the
    inputs."""
    toml, _ = _dofplan.pmks_to_toml(text, None if inputs is None else [tuple(p) for p in inputs], name)
    return toml


class Assembled:
    """What :func:`assemble` gives: ``text`` (the file with the assembled
    coordinates, comments and key order kept), ``report`` (the table of
    moves ``dofplan assemble`` prints), ``unchanged`` (nothing moved), and
    ``mechanism`` (the text loaded)."""

    def __init__(self, text: str, report: str, unchanged: bool, format: str, name: str) -> None:
        self.text, self.report, self.unchanged = text, report, unchanged
        self._format, self._name = format, name

    @property
    def mechanism(self) -> "Mechanism":
        return loads(self.text, self._format, self._name)

    def __repr__(self) -> str:
        return f"<dofplan.Assembled {self._name}: {'nothing moved' if self.unchanged else 'moved'}>"


def assemble_text(text: str, format: str = "toml", name: str = "<string>") -> Assembled:
    """``dofplan assemble`` on a mechanism's text, of either dimension: its
    drawing moved the least that closes every joint (a drawing whose joints
    do not hold, which :func:`loads` refuses). Errors other than open joints
    (and joints in conflict: no pose closes them) raise
    :class:`MechanismError`."""
    out, report, unchanged = _dofplan.assemble_text(text, format, name)
    return Assembled(out, report, unchanged, format, name)


def assemble(path: Union[str, "os.PathLike[str]"]) -> Assembled:
    """:func:`assemble_text` on a file (JSON when its name ends in
    ``.json``). The file is not written: ``Assembled.text`` is."""
    p = os.fspath(path)
    fmt = "json" if p.lower().endswith(".json") else "toml"
    try:
        with open(p, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise MechanismError(f"{p}: error: cannot read the file: {e}") from None
    return assemble_text(text, fmt, p)


class Synthesis:
    """What :func:`synth` found: ``result`` is ``dofplan synth --json``'s
    document (``error`` with ``sum_sq``, ``rms``, ``max``; ``evaluations``,
    ``seconds``, ``parameters``, ``constraints``, ``solutions``...), ``text``
    the best solution's file (the mechanism's own text with the new
    coordinates, comments and key order kept), ``mechanism`` that file
    loaded."""

    def __init__(self, result: Dict[str, Any], text: str, format: str, name: str) -> None:
        self.result, self.text = result, text
        self._format, self._name = format, name

    @property
    def error(self) -> Dict[str, float]:
        return self.result["error"]

    @property
    def parameters(self) -> Dict[str, float]:
        return self.result["parameters"]

    @property
    def mechanism(self) -> "Mechanism":
        return loads(self.text, self._format, self._name)

    def __repr__(self) -> str:
        return f"<dofplan.Synthesis rms={self.error.get('rms')}>"


def _csv(rows: Any, columns: Sequence[int], what: str) -> str:
    a = np.asarray(rows, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] not in columns:
        want = " or ".join(str(c) for c in columns)
        raise ValueError(f"{what} targets are rows of {want} numbers, not an array of shape {a.shape}")
    return "\n".join(",".join(repr(float(x)) for x in row) for row in a) + "\n"


def synth(
    mechanism: "Mechanism",
    *,
    path: Any = None,
    function: Any = None,
    motion: Any = None,
    marker: Optional[str] = None,
    output: Optional[str] = None,
    body: Optional[str] = None,
    timing: Optional[str] = None,
    input: Optional[str] = None,
    vary: Optional[Sequence[str]] = None,
    bounds: Optional[Sequence[float]] = None,
    point_bounds: Optional[Mapping[str, Sequence[float]]] = None,
    full_turn: bool = False,
    min_transmission: Optional[float] = None,
    max_ratio: Optional[float] = None,
    seed: int = 1,
    time_limit: float = 10.0,
    target: Optional[float] = None,
    population: Optional[int] = None,
    evaluations: Optional[int] = None,
) -> Synthesis:
    """``dofplan synth`` from Python: new dimensions for ``mechanism``.

    One goal, its targets an array (the columns of the CLI's target files):
    ``path`` (x, y or x, y, z: free timing; input, x, y[, z]: given) with
    ``marker``; ``function`` (input, output) with ``output`` (a joint);
    ``motion`` (x, y, angle; with an input column first for given timing;
    in space x, y, z and the orientation) with ``body``. ``timing`` is
    "given", "free" or None (as the columns say). The options are the
    CLI's: ``vary`` (parameter or point names; default all), ``bounds``
    (x0, y0, x1, y1 for every varied point; with z in space),
    ``point_bounds`` (by point), ``full_turn``, ``min_transmission``
    (degrees), ``max_ratio``, ``seed``, ``time_limit`` (seconds),
    ``target`` (stop at this sum of squares), ``population``,
    ``evaluations``. Every solution is verified from its written file. A
    problem the search cannot take raises :class:`DofplanError` with the
    CLI's message. Ctrl-C stops the search at its next generation
    (``KeyboardInterrupt``).
    """
    goals = [(k, v) for k, v in (("path", path), ("function", function), ("motion", motion)) if v is not None]
    if len(goals) != 1:
        raise ValueError("give one goal: path=, function= or motion=")
    kind, rows = goals[0]
    d = mechanism.dimension
    columns = {
        "path": (d, d + 1),
        "function": (2,),
        "motion": (3, 4) if d == 2 else (6, 7),
    }[kind]
    if timing not in (None, "given", "free"):
        raise ValueError(f'timing is "given" or "free", not {timing!r}')
    goal = {
        "kind": kind,
        "targets": _csv(rows, columns, kind),
        "marker": marker,
        "output": output,
        "body": body,
        "given": None if timing is None else timing == "given",
        "input": input,
        "vary": None if vary is None else list(vary),
        "bounds": None if bounds is None else [float(x) for x in bounds],
        "point_bounds": [(k, [float(x) for x in v]) for k, v in (point_bounds or {}).items()],
        "full_turn": bool(full_turn),
        "min_transmission": min_transmission,
        "max_ratio": max_ratio,
        "seed": int(seed),
        "time_limit": float(time_limit),
        "target": target,
        "population": population,
        "evaluations": evaluations,
    }
    text, best = mechanism._m.synth_raw(goal)
    _, fmt = mechanism._m.source()
    return Synthesis(json.loads(text), best, fmt, mechanism.file)


def from_pylinkage(linkage: Any, name: Optional[str] = None) -> "Mechanism":
    """A pylinkage 1.3 ``Linkage`` as a dofplan mechanism (see
    :mod:`dofplan.pylinkage`; pylinkage is imported only here)."""
    from .pylinkage import from_pylinkage as convert

    return convert(linkage, name)


def to_pylinkage(mechanism: "Mechanism") -> Any:
    """A dofplan mechanism as a pylinkage 1.3 ``Linkage``, where pylinkage
    can express it (see :mod:`dofplan.pylinkage`)."""
    from .pylinkage import to_pylinkage as convert

    return convert(mechanism)


class Check:
    """What ``dofplan check`` reports, as attributes.

    The fields are those of ``dofplan check --json`` (``mobility``,
    ``redundant``, ``ranges``... see the guide); ``to_dict()`` gives them
    all, and ``ok`` says whether the check passed.
    """

    def __init__(self, data: Dict[str, Any], ok: bool) -> None:
        self._data = data
        self.ok: bool = ok

    def __getattr__(self, key: str) -> Any:
        try:
            return self._data[key]
        except KeyError:
            raise AttributeError(
                f"the check has no field {key!r}; it has: {', '.join(self._data)}"
            ) from None

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self._data))

    def to_dict(self) -> Dict[str, Any]:
        """Every field, as ``dofplan check --json`` writes them."""
        return json.loads(json.dumps(self._data))

    def __repr__(self) -> str:
        return f"<dofplan.Check ok={self.ok} fields={list(self._data)}>"


class Plan:
    """The plan of a mechanism, explained step by step: ``str(plan)`` is
    what ``dofplan plan`` prints."""

    def __init__(self, text: str) -> None:
        self.text = text

    def steps(self) -> List[str]:
        """The explanation's lines that are steps (numbered)."""
        return [line for line in self.text.splitlines() if line.strip()[:1].isdigit()]

    def __str__(self) -> str:
        return self.text

    def __repr__(self) -> str:
        return f"<dofplan.Plan: {len(self.steps())} steps>"


class Result:
    """The frames of a run, as NumPy arrays.

    - ``poses``: frames x bodies x 3 (planar: angle in degrees from the
      drawing, x, y) or x 7 (spatial: x, y, z and the rotation from the
      drawing as a unit quaternion w, x, y, z with w >= 0).
    - ``markers``: frames x markers x 2 (or 3), every marker's world
      position, in the order of ``marker_names``.
    - ``inputs``: frames x inputs, the inputs of the pose reached (they
      differ from ``requested`` where a frame broke).
    - An "unreached" frame (a sweep that starts out of the mechanism's
      reach, before its first pose) has NaN poses, markers and residual:
      the run has no pose there (the CLI's JSON writes null).
    - ``status``: a code per frame, an index into ``status_names``
      (``solved``, ``limited``, ``searched``, ``unreached``, ``stretched``).
    - ``residual`` (with ``simulate(..., check=True)``, else None): per
      frame, the largest relative residual of every joint, constraint and
      input, from the model (near 1e-15 where a frame is solved).
    """

    def __init__(
        self,
        mechanism: "Mechanism",
        requested: np.ndarray,
        raw: Dict[str, Any],
        policy: str = "limit",
        branch: str = "keep",
    ) -> None:
        self.mechanism = mechanism
        self.requested: np.ndarray = requested
        self._policy, self._branch = policy, branch
        #: The dragged marker, for a :meth:`Mechanism.drag` result (then
        #: ``requested`` and ``inputs`` are its targets, asked and met).
        self.dragged: Optional[str] = raw.get("dragged")
        self.poses: np.ndarray = raw["poses"]
        self.markers: np.ndarray = raw["markers"]
        self.inputs: np.ndarray = raw["inputs"]
        self.status: np.ndarray = raw["status"]
        self.status_names: List[str] = list(raw["status_names"])
        self.residual: Optional[np.ndarray] = raw.get("residual")
        self.marker_names: List[str] = mechanism.markers
        self.body_names: List[str] = mechanism.bodies
        self.input_names: List[str] = (
            mechanism.inputs
            if self.dragged is None
            else [f"{self.dragged}.{c}" for c in "xyz"[: mechanism.dimension]]
        )
        #: With rates (``Mechanism.rates``): every marker's velocity and
        #: acceleration (shaped like ``markers``), every body's angular
        #: velocity and acceleration in radians per unit of time (frames x
        #: bodies, x 3 in space), and per frame a code into
        #: ``rate_status_names`` ("ok", "not solved", "singular" at a dead
        #: point, "not computed"); NaN where a frame has no rates.
        self.velocity: Optional[np.ndarray] = raw.get("velocity")
        self.acceleration: Optional[np.ndarray] = raw.get("acceleration")
        self.omega: Optional[np.ndarray] = raw.get("omega")
        self.alpha: Optional[np.ndarray] = raw.get("alpha")
        self.rate_status: Optional[np.ndarray] = raw.get("rate_status")
        self.rate_status_names: List[str] = list(raw.get("rate_status_names", []))

    def __len__(self) -> int:
        return int(self.poses.shape[0])

    @property
    def solved(self) -> np.ndarray:
        """A boolean per frame: every step met exactly."""
        return self.status == self.status_names.index("solved")

    def status_of(self, frame: int) -> str:
        """The name of a frame's status."""
        return self.status_names[int(self.status[frame])]

    def marker(self, name: str) -> np.ndarray:
        """One marker's path, frames x 2 (or 3); ``name`` is ``body.marker``."""
        try:
            k = self.marker_names.index(name)
        except ValueError:
            raise KeyError(
                f"{self.mechanism.file} has no marker {name!r}; markers are written body.marker, "
                f"e.g. {', '.join(self.marker_names[:4])}"
            ) from None
        return self.markers[:, k, :]

    def body(self, name: str) -> np.ndarray:
        """One body's poses, frames x 3 (or 7)."""
        try:
            k = self.body_names.index(name)
        except ValueError:
            raise KeyError(
                f"{self.mechanism.file} has no body {name!r}; bodies: {', '.join(self.body_names)}"
            ) from None
        return self.poses[:, k, :]

    def plot(self, markers: Optional[Sequence[str]] = None, ax: Any = None) -> Any:
        """Draws marker paths with matplotlib (``pip install dofplan[plot]``):
        the sweep's traced markers by default, x against y (planar) or the
        x-y projection (spatial). Frames that are not solved are left out.
        Returns the axes."""
        try:
            import matplotlib.pyplot as plt
        except ImportError:
            raise ImportError(
                "Result.plot needs matplotlib: pip install matplotlib (or dofplan[plot])"
            ) from None
        if markers is None:
            sweep = self.mechanism.sweep
            markers = sweep["trace"] if sweep and sweep["trace"] else self.marker_names[-1:]
        if ax is None:
            _, ax = plt.subplots()
        ok = self.solved | (self.status == self.status_names.index("stretched"))
        for name in markers:
            p = self.marker(name)
            ax.plot(np.where(ok, p[:, 0], np.nan), np.where(ok, p[:, 1], np.nan), label=name)
        ax.set_aspect("equal")
        ax.legend()
        ax.set_title(self.mechanism.name)
        return ax

    def svg(self) -> str:
        """The frames drawn as ``dofplan simulate --svg`` draws them (traced
        markers, faint poses, breaks marked)."""
        if self.dragged is not None:
            raise NotImplementedError(
                "a drag's frames are drawn by the CLI: dofplan drag FILE --marker M --to X,Y --svg OUT.svg"
            )
        return self.mechanism._m.svg_frames(self.requested, self._policy, self._branch)

    def _repr_svg_(self) -> Optional[str]:
        return None if self.dragged is not None else self.svg()

    def __repr__(self) -> str:
        counts = {n: int((self.status == k).sum()) for k, n in enumerate(self.status_names)}
        shown = ", ".join(f"{v} {k}" for k, v in counts.items() if v)
        return f"<dofplan.Result of {self.mechanism.name}: {len(self)} frames ({shown})>"


class Mechanism:
    """A mechanism loaded from a file, text or dict.

    Names: ``bodies``, ``markers`` (``body.marker``), ``joints``,
    ``inputs`` (and ``input_kinds``: "angle" in degrees or "slide"),
    ``sweep`` (the file's ``[sweep]`` as a dict, or None).
    """

    def __init__(self, native: "_dofplan.Mechanism") -> None:
        self._m = native

    @property
    def name(self) -> str:
        return self._m.name

    @property
    def dimension(self) -> int:
        """2 (planar) or 3 (spatial)."""
        return self._m.dimension

    @property
    def file(self) -> str:
        """The file name errors use."""
        return self._m.file

    @functools.cached_property
    def bodies(self) -> List[str]:
        return self._m.bodies

    @functools.cached_property
    def markers(self) -> List[str]:
        return self._m.markers

    @functools.cached_property
    def joints(self) -> List[str]:
        return self._m.joints

    @functools.cached_property
    def joint_markers(self) -> List[tuple]:
        """Every joint as (name, kind, first marker, second marker)."""
        return self._m.joint_markers

    @functools.cached_property
    def inputs(self) -> List[str]:
        return self._m.inputs

    @functools.cached_property
    def input_kinds(self) -> List[str]:
        return self._m.input_kinds

    @property
    def sweep(self) -> Optional[Dict[str, Any]]:
        return self._m.sweep_dict

    def check(self) -> Check:
        """What ``dofplan check`` reports: mobility by both counts, redundant
        joints, idle freedoms, assembly ranges, Grashof..."""
        text, ok = self._m.check_json()
        return Check(json.loads(text), ok)

    def plan(self) -> Plan:
        """The plan explained (``dofplan plan``). Raises :class:`PlanError`
        when the mechanism has none."""
        return Plan(self._m.plan_text())

    def emit(self) -> str:
        """The generated Rust module (``dofplan emit``)."""
        return self._m.emit()

    def sweep_inputs(self, steps: Optional[int] = None) -> np.ndarray:
        """The inputs of every frame of the file's ``[sweep]``, frames x
        inputs (``steps`` frames if given)."""
        return self._m.sweep_inputs(steps)

    def simulate(
        self,
        inputs: Any = None,
        *,
        steps: Optional[int] = None,
        policy: str = "limit",
        branch: str = "keep",
        parallel: bool = True,
        check: bool = False,
        _drive: Optional[tuple] = None,
    ) -> Result:
        """Runs frames through the plan, one after the other from the drawing.

        ``inputs``: the input values of every frame, shape (frames,) for a
        mechanism of one input or (frames, inputs), in the file's units
        (degrees for angles); None runs the file's ``[sweep]`` (``steps``
        frames if given). ``policy`` is what a frame past a limit does
        ("limit" holds the last pose, "search" goes to the break point,
        "stretch" relaxes steps) and ``branch`` "keep" (the drawing's
        branch) or "nearest"; both as in ``dofplan simulate``. The
        interpreter lock is released while frames are solved; a long run
        (4096 frames or more) of a planar plan without a numeric cluster,
        under the default policies, is solved on every core, with the same
        frames to the bit (``parallel=False`` keeps it on one). ``check``
        adds each frame's residual (``Result.residual``), checked from the
        model: it costs more than the frame.
        """
        n = len(self.inputs)
        if inputs is None:
            requested = self.sweep_inputs(steps)
        else:
            if steps is not None:
                raise ValueError("give inputs or steps, not both (steps sets the file's sweep's frames)")
            requested = np.asarray(inputs, dtype=np.float64)
            if requested.ndim == 1:
                if n != 1:
                    raise ValueError(
                        f"{self.file} has {n} inputs ({', '.join(self.inputs)}): "
                        f"give inputs of shape (frames, {n})"
                    )
                requested = requested.reshape(-1, 1)
            elif requested.ndim != 2:
                raise ValueError(f"inputs must be of shape (frames,) or (frames, {n}), not {requested.shape}")
            requested = np.ascontiguousarray(requested)
        if _drive is None:
            raw = self._m.simulate_raw(requested, policy, branch, None, None, parallel, check)
        else:
            raw = self._m.simulate_raw(requested, policy, branch, _drive[0], _drive[1], parallel, check)
        return Result(self, requested, raw, policy, branch)

    def rates(
        self,
        inputs: Any = None,
        *,
        rate: Any,
        acceleration: Any = 0.0,
        steps: Optional[int] = None,
        policy: str = "limit",
        branch: str = "keep",
    ) -> Result:
        """:meth:`simulate` with every solved frame's velocities and
        accelerations (``Result.velocity``, ``acceleration``, ``omega``,
        ``alpha``), exact: derived through the plan, as ``dofplan analyze``
        does.

        ``rate``: the inputs' rates, one per input (a number for a mechanism
        of one input), in radians per unit of time for an angle and length
        units per unit of time for a slide (``dofplan analyze --rate``'s
        units); ``acceleration`` likewise (default 0). Velocities are then
        in length units per unit of time.
        """
        n = len(self.inputs)
        rates = self._per_input("rate", rate, n)
        accelerations = self._per_input("acceleration", acceleration, n, broadcast=True)
        return self.simulate(inputs, steps=steps, policy=policy, branch=branch, _drive=(rates, accelerations))

    def _per_input(self, what: str, value: Any, n: int, broadcast: bool = False) -> List[float]:
        v = np.asarray(value, dtype=np.float64)
        if v.ndim == 0 and (n == 1 or broadcast):
            return [float(v)] * n
        if v.shape != (n,):
            raise ValueError(
                f"{self.file} has {n} inputs ({', '.join(self.inputs)}): give one {what} per input"
            )
        return [float(x) for x in v]

    def drag(self, marker: str, targets: Any, *, policy: str = "stretch") -> Result:
        """Pins ``marker`` (``body.marker``) to each target in turn, the
        inputs released, as ``dofplan drag`` does: ``targets`` is frames x 2
        (x 3 in space), or one point. Each frame moves the mechanism the
        least that puts the marker on its target (Newton-Raphson with the
        SVD pseudo-inverse); a target out of reach is come as close to as
        the joints allow ("stretch", the default, as ``dofplan drag``), held
        at the last target met ("limit") or gone toward ("search").
        ``result.inputs`` are the targets met."""
        t = np.asarray(targets, dtype=np.float64)
        if t.ndim == 1:
            t = t.reshape(1, -1)
        if t.ndim != 2 or t.shape[1] != self.dimension:
            raise ValueError(f"targets must be of shape (frames, {self.dimension}), not {t.shape}")
        t = np.ascontiguousarray(t)
        raw = dict(self._m.drag_raw(marker, t, policy))
        raw["dragged"] = marker
        return Result(self, t, raw, policy, "keep")

    def analyze(self, rate: float = 1.0, steps: Optional[int] = None) -> Dict[str, Any]:
        """``dofplan analyze --json`` on the file's sweep (``steps`` frames if
        given), its first input at ``rate`` (radians or length units per unit
        of time): every frame's marker velocities and accelerations, body
        rates, and each four-bar loop's transmission angle, as a dict."""
        return json.loads(self._m.analyze_json(rate, steps))

    def source(self) -> Tuple[str, str]:
        """The mechanism's file text and its format ("toml" or "json"): the
        text it was loaded from, or a candidate's rewritten file (write it
        to a file to keep the candidate)."""
        text, fmt = self._m.source()
        return text, fmt

    @functools.cached_property
    def parameters(self) -> Dict[str, float]:
        """The design parameters and their drawn values, in order:
        ``NAME.x``, ``NAME.y`` (``.z`` in space) per point that moves as one
        (a joint's name, or ``body.marker`` for a marker in no joint), as
        ``dofplan synth`` and ``analyze --sensitivity`` name them. A
        mechanism without a plan has none (:class:`DofplanError`)."""
        names, drawn = _dofplan.parameters(self._m)
        return dict(zip(names, drawn))

    def with_parameters(self, values: Any) -> "Mechanism":
        """The candidate drawn at new parameter values: a mapping of some
        parameters (the rest stay as drawn) or one value per parameter in
        :attr:`parameters`' order. A mechanism like any loaded one, its text
        this file's with the moved points rewritten to the last bit
        (comments and key order kept; :meth:`source`). Raises
        :class:`DofplanError` where the new drawing has no plan, ``KeyError``
        for a name that is not a parameter."""
        if isinstance(values, Mapping):
            unknown = [k for k in values if k not in self.parameters]
            if unknown:
                raise KeyError(f"{', '.join(unknown)}: not design parameters of {self.name} (they are {', '.join(self.parameters)})")
            row = [float(values.get(k, v)) for k, v in self.parameters.items()]
        else:
            row = [float(v) for v in np.asarray(values, dtype=np.float64).ravel()]
        return Mechanism(_dofplan.with_parameters(self._m, row))

    def forces(
        self, rate: Optional[float] = None, steps: Optional[int] = None, acceleration: Optional[float] = None
    ) -> Dict[str, Any]:
        """``dofplan analyze --forces --json``: each input's force or torque
        (``frames[k]["input_force"]``: input name -> value, None where the
        frame is not solved or at a dead point) and each joint's reaction
        (``frames[k]["reactions"]``: joint -> [fx, fy], or [fx, fy, fz] in a
        spatial file) under the file's masses, ``[gravity]`` and ``[loads]``;
        held still at each pose (statics), or with ``rate`` running at that
        rate (kinetostatics), speeding up at ``acceleration`` if given (it
        needs a ``rate``; ``rate=0`` starts from rest)."""
        return json.loads(self._m.forces_json(rate, steps, acceleration))

    def sensitivity(
        self,
        tolerance: Optional[float] = None,
        monte_carlo: Optional[int] = None,
        seed: int = 1,
        steps: Optional[int] = None,
    ) -> Dict[str, Any]:
        """``dofplan analyze --sensitivity --json``: each traced marker's
        exact derivatives with respect to every design parameter over the
        sweep, ranked; with ``tolerance`` the worst-case first-order
        deviation, and with ``monte_carlo`` N perturbed candidates' spread
        (seeded by ``seed``; 1 as in the CLI)."""
        return json.loads(self._m.sensitivity_json(tolerance, monte_carlo, seed, steps))

    def __reduce__(self) -> Any:
        # Pickled as its text (multiprocessing, Ray, Dask send mechanisms
        # this way): loaded again on the other side, checks included.
        text, fmt = self._m.source()
        return (loads, (text, fmt, self.file))

    def frame(self, inputs: Any) -> Tuple[np.ndarray, str]:
        """One frame from the live pose, as a slider in an editor moves the
        mechanism: every marker's world position (markers x 2, or x 3 in
        space, in ``markers`` order) and the frame's status ("solved",
        "limited"...). Each call starts from the last one's pose (the
        drawing at first, and after :meth:`reset`); a frame past a limit
        holds it. ``inputs`` is a number for one input, else one value per
        input. The quick way to ask for single poses, one at a time."""
        if isinstance(inputs, (int, float)):
            return self._m.frame([float(inputs)])
        return self._m.frame([float(v) for v in inputs])

    def reset(self) -> None:
        """Returns :meth:`frame`'s live pose to the drawing."""
        self._m.reset()

    def marker(self, name: str, result: Result) -> np.ndarray:
        """One marker's path in a result (``result.marker(name)``)."""
        return result.marker(name)

    def _repr_svg_(self) -> str:
        return self._m.svg()

    def svg(self) -> str:
        """The drawing as SVG, as ``dofplan simulate --svg`` draws it at the
        drawn pose."""
        return self._m.svg()

    def __repr__(self) -> str:
        return repr(self._m)
