"""Design studies as Ray tasks (`dofplan.ray`) on a real Ray: a local
instance with two CPUs, and a two-node cluster on this machine
(`ray.cluster_utils.Cluster`) so the work crosses node boundaries. Each
study gives the single-process answer (`dofplan.study`) to the bit; a
worker killed in the middle of a study loses nothing and counts nothing
twice.

Ray is an optional extra: without it these tests are skipped, unless
DOFPLAN_REQUIRE_RAY is set (`.ci/run` sets it), where a missing Ray is a
failure."""

import os
import signal
import threading
import time

import numpy as np
import pytest

if os.environ.get("DOFPLAN_REQUIRE_RAY"):
    import ray
else:
    ray = pytest.importorskip("ray")

import dofplan
import dofplan.ray as dray
from dofplan import study

from test_cli_agreement import MECHANISMS

FOURBAR = MECHANISMS / "fourbar.toml"


def fourbar():
    return dofplan.load(FOURBAR)


def path_error(m):
    targets = m.simulate(steps=37).marker("coupler.P")[::4] + [0.02, -0.01]
    return study.PathError("coupler.P", targets)


def samples():
    return study.random({"D.x": (3.6, 4.4), "D.y": (-0.3, 0.3), "coupler.P.y": (3.0, 4.0)}, 24, seed=11)


RESTART_OPTIONS = dict(vary=["D", "coupler.P"], evaluations=400, time_limit=60.0, marker="coupler.P")


def restart_targets(m):
    return m.simulate([0.0, 60.0, 120.0, 180.0, 240.0, 300.0]).marker("coupler.P") + [0.05, 0.0]


def same_sweep(a, b):
    assert len(a) == len(b) == len(a.values)
    assert np.array_equal(a.values, b.values)
    assert np.array_equal(a.scores, b.scores, equal_nan=True) and a.errors == b.errors


@pytest.fixture(scope="class")
def local_ray():
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    yield
    ray.shutdown()


@pytest.fixture(scope="class")
def two_nodes():
    from ray.cluster_utils import Cluster

    cluster = Cluster(initialize_head=True, head_node_args={"num_cpus": 1, "include_dashboard": False})
    cluster.add_node(num_cpus=1)
    cluster.wait_for_nodes()
    ray.init(address=cluster.address, log_to_driver=False)
    # A worker started on each node before the studies: a task dealt to a
    # node then runs there at once rather than waiting on a process start.
    from ray.util.scheduling_strategies import NodeAffinitySchedulingStrategy

    started = [
        ray.remote(lambda: None).options(scheduling_strategy=NodeAffinitySchedulingStrategy(n["NodeID"], soft=False)).remote()
        for n in ray.nodes()
    ]
    ray.get(started, timeout=120)
    yield cluster
    ray.shutdown()
    cluster.shutdown()


@pytest.mark.usefixtures("local_ray")
class TestLocal:
    def test_a_sweep_is_the_single_process_one(self):
        m = fourbar()
        score = path_error(m)
        expected = study.sweep(m, samples(), score, steps=73)
        got = dray.sweep(m, samples(), score, steps=73)
        same_sweep(got, expected)
        assert got.best == expected.best and got.errors.count(None) == 24
        assert ray.available_resources().get("CPU", 0) <= 2

    def test_a_tolerance_study_is_the_single_process_one(self):
        m = fourbar()
        expected = study.tolerance(m, 0.01, 40, seed=4, steps=37)
        got = dray.tolerance(m, 0.01, 40, seed=4, steps=37, chunk_size=3)
        assert np.array_equal(got.deviations, expected.deviations)
        assert got.to_dict() == expected.to_dict()

    def test_restarts_are_the_single_process_ones(self):
        m = fourbar()
        options = dict(path=restart_targets(m), **RESTART_OPTIONS)
        expected = study.restarts(m, [1, 2, 3, 4], **options)
        got = dray.restarts(m, [1, 2, 3, 4], **options)
        assert got.seeds == expected.seeds and np.array_equal(got.errors, expected.errors)
        assert [r.text for r in got.runs] == [r.text for r in expected.runs]

    def test_a_worker_killed_mid_study_loses_nothing(self, tmp_path):
        m = fourbar()
        score = path_error(m)
        expected = study.sweep(m, samples(), score, steps=73)
        started, calls = tmp_path / "workers", tmp_path / "calls"
        started.mkdir()
        calls.mkdir()

        def slow(r, where=str(started), calls=str(calls), score=score):
            # Each worker says it is working (its pid), then works slowly
            # enough for the test to kill it mid-task; every call is counted.
            import uuid

            open(os.path.join(where, str(os.getpid())), "a").close()
            open(os.path.join(calls, uuid.uuid4().hex), "a").close()
            time.sleep(0.05)
            return score(r)

        done = {}
        study_thread = threading.Thread(
            target=lambda: done.setdefault("sweep", dray.sweep(m, samples(), slow, steps=73, chunk_size=2))
        )
        study_thread.start()
        deadline = time.monotonic() + 120
        while not any(started.iterdir()):
            assert time.monotonic() < deadline, "no worker started"
            time.sleep(0.005)
        victim = int(next(started.iterdir()).name)
        assert victim != os.getpid()
        os.kill(victim, signal.SIGKILL)
        study_thread.join(timeout=300)
        assert not study_thread.is_alive(), "the study did not finish"
        # The killed worker is gone, its task ran again elsewhere, and every
        # candidate's result is there once, as the single process has it.
        with pytest.raises(ProcessLookupError):
            os.kill(victim, 0)
        same_sweep(done["sweep"], expected)
        assert len(list(started.iterdir())) >= 2
        # The killed task's candidates were scored again: more calls than
        # candidates, one result each.
        assert len(list(calls.iterdir())) > len(expected)


@pytest.mark.usefixtures("two_nodes")
class TestTwoNodes:
    def test_a_sweep_crosses_nodes_and_is_the_single_process_one(self, tmp_path):
        m = fourbar()
        score = path_error(m)
        expected = study.sweep(m, samples(), score, steps=73)
        nodes = tmp_path / "nodes"
        nodes.mkdir()

        def scored_where(r, where=str(nodes), score=score):
            import ray as r_

            open(os.path.join(where, r_.get_runtime_context().get_node_id()), "a").close()
            time.sleep(0.02)
            return score(r)

        # "SPREAD" deals the twelve tasks across both nodes; Ray's default
        # may keep them all on the head while the other node starts its
        # first worker, which is Ray's choice, not a fault of the sweep.
        got = dray.sweep(m, samples(), scored_where, steps=73, chunk_size=2, scheduling_strategy="SPREAD")
        same_sweep(got, expected)
        assert len(ray.nodes()) == 2
        assert len(list(nodes.iterdir())) == 2, "every task ran on one node"

    def test_a_tolerance_study_and_restarts_across_nodes(self):
        m = fourbar()
        expected = study.tolerance(m, 0.01, 40, seed=4, steps=37)
        got = dray.tolerance(m, 0.01, 40, seed=4, steps=37, chunk_size=5)
        assert np.array_equal(got.deviations, expected.deviations) and got.to_dict() == expected.to_dict()
        options = dict(path=restart_targets(m), **RESTART_OPTIONS)
        a = study.restarts(m, [5, 6], **options)
        b = dray.restarts(m, [5, 6], **options)
        assert b.seeds == a.seeds and [r.text for r in b.runs] == [r.text for r in a.runs]


def test_the_ray_example_runs():
    # The guide's recipe, as a user runs it (its own local Ray).
    import subprocess
    import sys

    example = MECHANISMS.parent / "python" / "examples" / "ray_study.py"
    done = subprocess.run([sys.executable, str(example)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("best of 400: {'D.x'") and lines[1].startswith("tolerance 0.01: largest")
    assert lines[2].startswith("synthesis: best rms")
