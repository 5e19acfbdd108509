"""Design studies on Ray: :mod:`dofplan.study`'s sweeps, tolerance studies
and synthesis restarts, their chunks run as Ray tasks on this machine's
cores or on a cluster (``pip install ./python[ray]``).

Connect first, as Ray is always connected: ``ray.init()`` on a laptop
(every core), ``ray.init(address="auto")`` on a cluster's node, or
``ray.init(address="ray://HEAD:10001")`` from outside it. Every node needs
this same ``dofplan`` installed. If Ray is not connected, the first study
starts a local instance (Ray's own default).

The answer is the single-process one (:mod:`dofplan.study`) to the bit:
candidates are drawn before any task runs, each task gets whole candidates
and returns their results, and results are gathered in the candidates'
order. A worker that dies mid-task (a node lost, a process killed) has its
task run again elsewhere (``max_retries`` times), and since a task is only
counted once it returns, nothing is lost or counted twice.

Each task asks for ``num_cpus`` (default 1) cores and runs its candidates
one after another on them; Ray runs as many tasks at once as the cluster
has cores. ``scheduling_strategy`` is given to Ray as it is: Ray's default
fills the calling node first, ``"SPREAD"`` deals tasks across nodes.
"""

from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

import ray as _ray

from . import study as _study
from .study import PathError, Restarts, Samples, Sweep, Tolerance, grid, random

__all__ = ["sweep", "tolerance", "restarts", "grid", "random", "PathError", "Samples", "Sweep", "Tolerance", "Restarts"]


def _runner(num_cpus: float, max_retries: int, scheduling_strategy: Any = None) -> _study.Runner:
    """Runs chunks as Ray tasks: the mechanism and other shared arguments
    put in the object store once, the results gathered in order."""

    def run(fn: Callable[..., Any], chunks: List[Tuple[Any, ...]]) -> List[Any]:
        if not chunks:
            return []
        if not _ray.is_initialized():
            _ray.init()
        options: Dict[str, Any] = dict(num_cpus=num_cpus, max_retries=max_retries, retry_exceptions=False)
        # Ray's default packs tasks onto the calling node while it has room;
        # "SPREAD" (or a placement group's strategy) is the caller's choice.
        if scheduling_strategy is not None:
            options["scheduling_strategy"] = scheduling_strategy
        task = _ray.remote(**options)(fn)
        # The first argument (the mechanism) is the same in every chunk:
        # sent once, not once per task.
        shared = _ray.put(chunks[0][0])
        refs = [task.remote(shared, *c[1:]) for c in chunks]
        return list(_ray.get(refs))

    return run


def _chunk_size(n: int, given: Optional[int], num_cpus: float) -> int:
    """The chunk size given, or about four tasks per core the cluster
    offers: enough to keep every core busy while the slowest finish."""
    if given is not None:
        if given < 1:
            raise ValueError(f"chunk_size must be at least 1, not {given}")
        return given
    if not _ray.is_initialized():
        _ray.init()
    cores = max(1.0, float(_ray.cluster_resources().get("CPU", 1.0)) / num_cpus)
    return max(1, -(-n // int(4 * cores)))


def sweep(
    mechanism: Any,
    samples: Samples,
    score: Callable[[Any], float],
    inputs: Any = None,
    *,
    steps: Optional[int] = None,
    chunk_size: Optional[int] = None,
    num_cpus: float = 1,
    max_retries: int = 3,
    scheduling_strategy: Any = None,
) -> Sweep:
    """:func:`dofplan.study.sweep` as Ray tasks: the same candidates,
    scores and errors, in the same order. ``score`` is sent to the workers
    (cloudpickle: a lambda or a closure will do)."""
    size = _chunk_size(len(samples), chunk_size, num_cpus)
    return _study.sweep(
        mechanism, samples, score, inputs, steps=steps, chunk_size=size, _runner=_runner(num_cpus, max_retries, scheduling_strategy),
    )


def tolerance(
    mechanism: Any,
    tolerance: float,
    samples: int,
    seed: int = 1,
    *,
    steps: Optional[int] = None,
    chunk_size: Optional[int] = None,
    num_cpus: float = 1,
    max_retries: int = 3,
    scheduling_strategy: Any = None,
) -> Tolerance:
    """:func:`dofplan.study.tolerance` as Ray tasks: ``dofplan analyze
    --tolerance T --monte-carlo N --seed S``'s candidates and numbers, to the
    bit."""
    size = _chunk_size(samples, chunk_size, num_cpus)
    return _study.tolerance(
        mechanism,
        tolerance,
        samples,
        seed,
        steps=steps,
        chunk_size=size,
        _runner=_runner(num_cpus, max_retries, scheduling_strategy),
        # Each task has the cores Ray gave it, not the node's.
        _parallel=False,
    )


def restarts(
    mechanism: Any,
    seeds: Sequence[int],
    *,
    num_cpus: float = 1,
    max_retries: int = 3,
    scheduling_strategy: Any = None,
    **options: Any,
) -> Restarts:
    """:func:`dofplan.study.restarts` as Ray tasks, one per seed. Give
    ``evaluations`` (not only a ``time_limit``) for runs that repeat to the
    bit wherever they run."""
    return _study.restarts(
        mechanism, seeds, _runner=_runner(num_cpus, max_retries, scheduling_strategy), **options
    )

