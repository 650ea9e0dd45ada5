"""The kernels' cost profile (``cerebx bench``'s per-step table): it times without changing a result."""

from __future__ import annotations

import time

import numpy as np
import pytest

from cerebx.bench import bench_network
from cerebx.loop.timing import _BusyCore, closed_loop_rt
from cerebx.snn.kernels import PROF_PARTS
from cerebx.snn.network import Network
from cerebx.snn.presets import network


def _inputs(steps: int, n_mf: int, seed: int) -> list[np.ndarray]:
    """Bursts of a few random MFs a step (each fibre at most once) for 16 ms, then 64 ms without input: GCs
    activate out of index order, come back to rest and get compacted."""
    rng = np.random.default_rng(seed)
    return [np.sort(rng.choice(n_mf, size=int(rng.integers(0, 12)) if k % 40 < 8 else 0,
                               replace=False)).astype(np.int32) for k in range(steps)]


def test_a_profiled_network_steps_exactly_like_an_unprofiled_one():
    cfg = network(fibers=5, per_joint=10)
    plain, timed = (Network(cfg, parallel=False, compact_min=1000, lumped=False) for _ in range(2))
    inputs = _inputs(300, plain.index("mf").stop, seed=2)
    timed.start_profile()
    t0 = time.perf_counter()
    spikes_timed = [timed.step(x).idx.copy() for x in inputs]
    wall = time.perf_counter() - t0
    spikes_plain = [plain.step(x).idx.copy() for x in inputs]
    unlisted = Network(cfg, parallel=False, compact_min=10**9)  # every GC integrated, no list to compact
    spikes_unlisted = [unlisted.step(x).idx.copy() for x in inputs]
    lumped = Network(cfg, parallel=False, compact_min=1000)  # GCs with equal state stepped once (snn/lumping.py)
    lumped.start_profile()
    spikes_lumped = [lumped.step(x).idx.copy() for x in inputs]
    assert sum(len(s) for s in spikes_plain) > 100
    assert plain.pop_ep[plain.topo.index["gc"]] > 3  # the GC list was compacted (sorted and merged) repeatedly
    assert all(np.array_equal(a, b) for a, b in zip(spikes_plain, spikes_timed))
    assert all(np.array_equal(a, b) for a, b in zip(spikes_plain, spikes_unlisted))
    assert all(np.array_equal(a, b) for a, b in zip(spikes_plain, spikes_lumped))
    for key, value in plain.state_arrays().items():
        np.testing.assert_array_equal(timed.state_arrays()[key], value, err_msg=key)
        np.testing.assert_array_equal(unlisted.state_arrays()[key], value, err_msg=key)
        np.testing.assert_array_equal(lumped.state_arrays()[key], value, err_msg=key)
    prof = timed.profile()
    assert set(prof) == {"integrate.gc", "integrate.pc", "integrate.dcn", *PROF_PARTS}
    assert all(prof[k] > 0 for k in ("integrate.gc", "integrate.pc", "integrate.dcn", "delivery", "bookkeeping"))
    assert prof["outputs"] == 0.0  # decoding is the controller's chunk kernel's
    assert sum(prof.values()) < wall
    assert plain.profile() == {}


@pytest.mark.integration
def test_the_closed_loop_reports_each_part_per_step():
    out = closed_loop_rt(["+task=circle", "+experiment=small_snn"], seconds=0.5, warmup_s=0.5, parts=True)
    parts = out["per_step_us"]
    assert {"plant", "brain", "loop"} <= set(parts["main"])
    assert parts["main_total"] == pytest.approx(sum(parts["main"].values()), abs=0.1)
    net = parts["network"]
    assert {"integrate.gc", "integrate.dcn", "delivery", "plasticity", "bookkeeping", "outputs"} <= set(net)
    assert all(v > 0 for k, v in net.items() if k != "thread_other")
    assert parts["network_busy"] == pytest.approx(sum(net.values()), abs=0.1)
    assert 0 < parts["network_cpu"] < parts["process_cpu"]
    # untimed CPU per step by thread: the network runs on its own thread beside the loop's
    cpu = out["cpu_us_per_step"]
    assert cpu["main_thread"] > 0 and cpu["other_threads"] > 0
    total = 1e6 / out["cpu_rt_factor"] * 0.002  # the process's CPU per 2 ms step
    assert cpu["main_thread"] + cpu["other_threads"] == pytest.approx(total, rel=0.02)


@pytest.mark.integration
def test_a_loop_without_a_network_thread_spends_its_cpu_on_the_main_thread():
    out = closed_loop_rt(["+task=circle", "controller=pd"], seconds=0.5, warmup_s=0.5)
    cpu = out["cpu_us_per_step"]
    assert cpu["main_thread"] > 0 and cpu["other_threads"] < 0.2 * cpu["main_thread"]


def test_the_network_bench_splits_a_step_into_parts():
    out = bench_network(network(fibers=5, per_joint=10), seconds=0.2, warmup=0.1)
    parts = out["per_step_us"]
    assert {"integrate.gc", "integrate.pc", "integrate.dcn", *PROF_PARTS, "total"} == set(parts)
    assert 0 < sum(v for k, v in parts.items() if k != "total") < parts["total"]
    assert out["listed_neurons"] == {}  # 3,750 GCs: below the size from which a population keeps a list


@pytest.mark.integration
def _python_loops(seconds: float) -> int:
    n, t0 = 0, time.perf_counter()
    while time.perf_counter() - t0 < seconds:
        n += 1
    return n


def test_the_busy_core_works_without_holding_the_interpreter_lock():
    # the busy thread streams its floats while this thread runs Python about as freely as without it (a thread
    # that held the lock would leave this one ~1/6 of the time: 5 ms switches against its ~20 ms calls)
    busy = _BusyCore()  # compiles or loads its kernel
    alone = _python_loops(0.3)
    with busy:
        beside = _python_loops(0.3)
    assert busy.calls >= 1
    assert beside > 0.25 * alone  # also when another process takes the other core (two threads on one: ~0.5)
    assert not busy._thread.is_alive()  # stopped when the block ends


def test_a_loop_is_timed_alone_and_beside_a_busy_core_in_turns():
    pd = ["+task=circle", "controller=pd"]
    busy = closed_loop_rt(pd, seconds=0.1, warmup_s=0.1, beside_busy=3)["beside_busy_core"]
    assert busy["rounds"] == 3
    assert busy["ratio_min"] <= busy["ratio_median"] <= busy["ratio_max"]
    assert 0.2 < busy["ratio_median"] < 2.0  # slower beside it on a host whose cores share, else as fast
    assert busy["rt_factor_alone_median"] > 0 and busy["rt_factor_beside_busy_median"] > 0


def test_two_loops_timed_in_turns_give_their_speed_ratio():
    pd = ["+task=circle", "controller=pd"]
    same = closed_loop_rt(pd, seconds=0.1, warmup_s=0.1, versus=pd, rounds=5)["versus"]
    assert same["rounds"] == 5 and same["overrides"] == pd
    assert same["ratio_min"] <= same["ratio_median"] <= same["ratio_max"]
    assert 0.5 < same["ratio_median"] < 2.0  # a loop against itself: as fast, up to the host's noise
    assert same["rt_factor_median"] > 0 and same["versus_rt_factor_median"] > 0
    # a loop that steps its physics 5 times as often (0.1 ms against 0.5 ms; ~0.4 of PD's speed measured) is the
    # slower one: the ratio is this loop's speed over the other's, not the inverse
    finer = closed_loop_rt([*pd, "plant.physics_dt_ms=0.1"], seconds=0.1, warmup_s=0.1, versus=pd, rounds=5)
    assert finer["versus"]["ratio_median"] < min(0.75, same["ratio_median"])
