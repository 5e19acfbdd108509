"""Design studies: many candidates of one mechanism, each a new drawing of
its design parameters (``NAME.x``, ``NAME.y``[, ``NAME.z``] per point, as
``dofplan synth`` names them), run and scored.

Three studies, each cut into chunks of candidates that run independently:

- :func:`sweep`: a grid (:func:`grid`) or random samples (:func:`random`)
  over named parameters, every candidate simulated and scored by your
  function or a built-in error (:class:`PathError`);
- :func:`tolerance`: the Monte-Carlo tolerance study of ``dofplan analyze
  --tolerance T --monte-carlo N --seed S`` (the same candidates and, to the
  bit, the same numbers), with every candidate's deviation kept;
- :func:`restarts`: :func:`dofplan.synth` from several seeds, best first.

Here the chunks run one after another in this process. :mod:`dofplan.ray`
runs the same chunks as Ray tasks on a machine's cores or a cluster, and
gives the same answer: candidates are drawn once, before any chunk runs,
and gathered back in their order.
"""

from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from . import _dofplan

# How chunks are run: a function and one argument tuple per chunk in, the
# chunks' results out, in order. This module's is a plain loop.
Runner = Callable[[Callable[..., Any], List[Tuple[Any, ...]]], List[Any]]


def _in_process(fn: Callable[..., Any], chunks: List[Tuple[Any, ...]]) -> List[Any]:
    return [fn(*c) for c in chunks]


class Samples:
    """Candidates as values of named design parameters: ``names`` (k of
    them) and ``values``, an array (n, k). The parameters not named keep
    their drawn values."""

    def __init__(self, names: Sequence[str], values: Any) -> None:
        self.names = list(names)
        self.values = np.asarray(values, dtype=np.float64)
        if self.values.ndim != 2 or self.values.shape[1] != len(self.names):
            raise ValueError(f"values must be an array (candidates, {len(self.names)}), not of shape {self.values.shape}")

    def __len__(self) -> int:
        return int(self.values.shape[0])

    def __repr__(self) -> str:
        return f"<dofplan.study.Samples {len(self)} candidates of {', '.join(self.names)}>"


def grid(axes: Mapping[str, Sequence[float]]) -> Samples:
    """Every combination of the values given per parameter, the last
    parameter varying fastest: ``grid({"D.x": [3.5, 4, 4.5], "coupler.P.y":
    np.linspace(3, 4, 5)})`` is 15 candidates."""
    if not axes:
        raise ValueError("name at least one parameter")
    names = list(axes)
    values = [np.asarray(axes[n], dtype=np.float64).ravel() for n in names]
    if any(v.size == 0 for v in values):
        raise ValueError("every parameter needs at least one value")
    mesh = np.meshgrid(*values, indexing="ij")
    return Samples(names, np.stack([a.ravel() for a in mesh], axis=1))


def random(ranges: Mapping[str, Tuple[float, float]], n: int, seed: int = 0) -> Samples:
    """``n`` candidates with each named parameter uniform in its range
    ``(low, high)``, from NumPy's generator seeded by ``seed``: the same
    seed, the same candidates."""
    if not ranges:
        raise ValueError("name at least one parameter")
    if n < 1:
        raise ValueError(f"n must be at least 1, not {n}")
    names = list(ranges)
    lo = np.array([float(ranges[k][0]) for k in names])
    hi = np.array([float(ranges[k][1]) for k in names])
    if np.any(hi < lo):
        bad = [k for k, a, b in zip(names, lo, hi) if b < a]
        raise ValueError(f"a range is (low, high): {', '.join(bad)} has low above high")
    rng = np.random.default_rng(seed)
    return Samples(names, rng.uniform(lo, hi, size=(n, len(names))))


class PathError:
    """A built-in score: how far a marker's path misses target points, as
    the sum of squared distances. ``timing="free"``: each target to the
    nearest frame's position (the frames sample the path); ``"given"``:
    target ``i`` to frame ``i`` (as many targets as frames). A frame that
    does not solve is skipped under free timing and makes the score
    infinite under given timing; so does a path with no solved frame."""

    def __init__(self, marker: str, targets: Any, timing: str = "free") -> None:
        if timing not in ("free", "given"):
            raise ValueError(f'timing is "free" or "given", not {timing!r}')
        self.marker, self.timing = marker, timing
        self.targets = np.asarray(targets, dtype=np.float64)
        if self.targets.ndim != 2 or self.targets.shape[1] not in (2, 3):
            raise ValueError(f"targets must be an array (points, 2) or (points, 3), not of shape {self.targets.shape}")

    def __call__(self, result: Any) -> float:
        path = result.marker(self.marker)
        if path.shape[1] != self.targets.shape[1]:
            raise ValueError(f"{self.marker} moves in {path.shape[1]} dimensions, the targets have {self.targets.shape[1]}")
        if self.timing == "given":
            if path.shape[0] != self.targets.shape[0]:
                raise ValueError(f"given timing needs one frame per target: {path.shape[0]} frames, {self.targets.shape[0]} targets")
            d = ((path - self.targets) ** 2).sum(axis=1)
            return float(d.sum()) if np.all(np.isfinite(d)) else float("inf")
        solved = path[np.all(np.isfinite(path), axis=1)]
        if solved.shape[0] == 0:
            return float("inf")
        d = ((self.targets[:, None, :] - solved[None, :, :]) ** 2).sum(axis=2)
        return float(d.min(axis=1).sum())

    def __repr__(self) -> str:
        return f"<dofplan.study.PathError {self.marker}, {len(self.targets)} targets, {self.timing} timing>"


class Sweep:
    """What :func:`sweep` found, candidate by candidate in the samples'
    order: ``names`` and ``values`` (the samples), ``scores`` (NaN where
    the candidate could not be made), ``errors`` (None, or why the
    candidate could not be made: its drawing has no plan, say)."""

    def __init__(self, mechanism: Any, samples: Samples, scores: np.ndarray, errors: List[Optional[str]]) -> None:
        self._mechanism = mechanism
        self.names, self.values = samples.names, samples.values
        self.scores, self.errors = scores, errors

    @property
    def best(self) -> int:
        """The index of the lowest score (ties: the first)."""
        if np.all(np.isnan(self.scores)):
            raise ValueError("no candidate could be made: see errors")
        return int(np.nanargmin(self.scores))

    def parameters(self, i: int) -> Dict[str, float]:
        """Candidate ``i``'s named parameters."""
        return {n: float(v) for n, v in zip(self.names, self.values[i])}

    def mechanism(self, i: int) -> Any:
        """Candidate ``i`` as a mechanism (its file: :meth:`Mechanism.source`)."""
        return self._mechanism.with_parameters(self.parameters(i))

    def __len__(self) -> int:
        return len(self.scores)

    def __repr__(self) -> str:
        failed = sum(e is not None for e in self.errors)
        return f"<dofplan.study.Sweep {len(self)} candidates, {failed} failed>"


def _chunks(n: int, size: int) -> List[Tuple[int, int]]:
    return [(i, min(i + size, n)) for i in range(0, n, size)]


def _full_rows(mechanism: Any, samples: Samples) -> np.ndarray:
    """Every candidate as a row of all design parameters (the unnamed ones
    at their drawn values), or a KeyError naming what is not a parameter."""
    drawn = mechanism.parameters
    unknown = [n for n in samples.names if n not in drawn]
    if unknown:
        raise KeyError(f"{', '.join(unknown)}: not design parameters of {mechanism.name} (they are {', '.join(drawn)})")
    rows = np.tile(np.array(list(drawn.values())), (len(samples), 1))
    order = list(drawn)
    for j, n in enumerate(samples.names):
        rows[:, order.index(n)] = samples.values[:, j]
    return rows


def _sweep_chunk(
    mechanism: Any, rows: np.ndarray, inputs: Any, steps: Optional[int], score: Callable[[Any], float]
) -> List[Tuple[float, Optional[str]]]:
    """Scores a chunk's candidates, one after another."""
    from . import DofplanError

    out: List[Tuple[float, Optional[str]]] = []
    for row in rows:
        try:
            c = mechanism.with_parameters(row)
            r = c.simulate(inputs) if inputs is not None else c.simulate(steps=steps)
        except DofplanError as e:
            out.append((float("nan"), str(e)))
            continue
        out.append((float(score(r)), None))
    return out


def sweep(
    mechanism: Any,
    samples: Samples,
    score: Callable[[Any], float],
    inputs: Any = None,
    *,
    steps: Optional[int] = None,
    chunk_size: int = 16,
    _runner: Runner = _in_process,
) -> Sweep:
    """Runs every candidate of ``samples``: drawn at its values, simulated
    over ``inputs`` (as :meth:`Mechanism.simulate` takes them; else the
    file's sweep, ``steps`` frames if given) and scored by ``score`` (the
    result in, a number out; :class:`PathError` is built in). A candidate
    that cannot be made (no plan, say) scores NaN and says why in
    ``errors``; an exception from ``score`` stops the study."""
    if chunk_size < 1:
        raise ValueError(f"chunk_size must be at least 1, not {chunk_size}")
    rows = _full_rows(mechanism, samples)
    chunks = [(mechanism, rows[a:b], inputs, steps, score) for a, b in _chunks(len(rows), chunk_size)]
    found = [x for part in _runner(_sweep_chunk, chunks) for x in part]
    scores = np.array([s for s, _ in found], dtype=np.float64)
    return Sweep(mechanism, samples, scores, [e for _, e in found])


class Tolerance:
    """What :func:`tolerance` found: ``candidates`` (n, parameters) with
    ``names``; ``deviations`` (n, traced markers), each candidate's largest
    distance from the drawing's path per traced marker (``markers``), NaN
    for a candidate that could not be planned or broke where the drawing
    does not; and the summary ``analyze --tolerance --monte-carlo`` prints:
    ``failed``, ``largest`` and ``mean`` (marker name -> length)."""

    def __init__(self, names: List[str], candidates: np.ndarray, markers: List[str], deviations: np.ndarray, seed: int) -> None:
        self.names, self.candidates, self.markers = names, candidates, markers
        self.deviations, self.seed = deviations, seed
        n, failed, largest, mean = _dofplan.spread(deviations)
        self.failed = int(failed)
        self.largest = {m: float(v) for m, v in zip(markers, largest)}
        self.mean = {m: float(v) for m, v in zip(markers, mean)}

    def to_dict(self) -> Dict[str, Any]:
        """The ``monte_carlo`` section of ``analyze --sensitivity --json``."""
        return {
            "candidates": len(self.candidates),
            "failed": self.failed,
            "seed": self.seed,
            "markers": {m: {"largest": self.largest[m], "mean": self.mean[m]} for m in self.markers},
        }

    def __repr__(self) -> str:
        return f"<dofplan.study.Tolerance {len(self.candidates)} candidates, {self.failed} failed, largest {self.largest}>"


def _tolerance_chunk(mechanism: Any, rows: np.ndarray, steps: Optional[int], parallel: bool) -> Tuple[List[str], np.ndarray]:
    names, d = _dofplan.deviations(mechanism._m, rows, steps, parallel)
    return names, d


def tolerance(
    mechanism: Any,
    tolerance: float,
    samples: int,
    seed: int = 1,
    *,
    steps: Optional[int] = None,
    chunk_size: int = 64,
    _runner: Runner = _in_process,
    _parallel: bool = True,
) -> Tolerance:
    """The Monte-Carlo tolerance study of ``dofplan analyze --sensitivity
    --tolerance T --monte-carlo N --seed S``: ``samples`` candidates with every
    design parameter uniform within ``±tolerance`` of the drawing, run over
    the file's sweep (``steps`` frames if given); how far each traced
    marker strays from the drawing's path. The same seed gives the same
    candidates and the same numbers as the CLI, however the candidates are
    split into chunks."""
    if samples < 1:
        raise ValueError(f"samples must be at least 1, not {samples}")
    if chunk_size < 1:
        raise ValueError(f"chunk_size must be at least 1, not {chunk_size}")
    rows = _dofplan.tolerance_draws(mechanism._m, samples, float(tolerance), seed)
    names = list(mechanism.parameters)
    chunks = [(mechanism, rows[a:b], steps, _parallel) for a, b in _chunks(samples, chunk_size)]
    parts = _runner(_tolerance_chunk, chunks)
    markers = parts[0][0]
    return Tolerance(names, rows, markers, np.concatenate([d for _, d in parts]), seed)


class Restarts:
    """What :func:`restarts` found: ``runs``, one :class:`dofplan.Synthesis`
    per seed, best first; ``seeds`` in the same order; ``errors`` their
    sums of squares."""

    def __init__(self, seeds: List[int], runs: List[Any]) -> None:
        order = sorted(range(len(runs)), key=lambda i: (runs[i].error["sum_sq"], i))
        self.seeds = [seeds[i] for i in order]
        self.runs = [runs[i] for i in order]
        self.errors = np.array([r.error["sum_sq"] for r in self.runs], dtype=np.float64)

    @property
    def best(self) -> Any:
        """The best run's :class:`dofplan.Synthesis`."""
        return self.runs[0]

    def __repr__(self) -> str:
        return f"<dofplan.study.Restarts {len(self.runs)} runs, best sum of squares {self.errors[0]:.6g} (seed {self.seeds[0]})>"


def _synth_one(mechanism: Any, seed: int, options: Dict[str, Any]) -> Any:
    from . import synth

    return synth(mechanism, seed=seed, **options)


def restarts(mechanism: Any, seeds: Sequence[int], _runner: Runner = _in_process, **options: Any) -> Restarts:
    """:func:`dofplan.synth` on ``mechanism`` once per seed, with the same
    ``options`` (its keywords: the goal, ``vary``, ``bounds``, ...), best
    first. Give ``evaluations`` for runs that repeat to the bit on any
    machine: a ``time_limit`` stops each where that machine's speed takes
    it."""
    seeds = [int(s) for s in seeds]
    if not seeds:
        raise ValueError("give at least one seed")
    if "seed" in options:
        raise ValueError("give the seeds as seeds=[...], not seed=")
    return Restarts(seeds, _runner(_synth_one, [(mechanism, s, options) for s in seeds]))
