"""Closed-loop speed: simulated seconds per wall second for a composed experiment, and where a control step's time
goes (:func:`per_step_parts`)."""

from __future__ import annotations

import statistics
import threading
import time
from pathlib import Path
from typing import Any

import numpy as np
from numba import njit

from cerebx import phase_clock
from cerebx.build import build_components
from cerebx.config import load
from cerebx.loop.instrument import instrument
from cerebx.loop.loop import ClosedLoop
from cerebx.recording.recorder import Recorder


def closed_loop_rt(overrides: list[str], seconds: float = 4.0, warmup_s: float = 1.0,
                   record_to: Path | None = None, parts: bool = False,
                   versus: list[str] | None = None, rounds: int = 8, beside_busy: int = 0) -> dict[str, Any]:
    """Run ``overrides`` for ``warmup_s`` (compilation, first-touch), then time ``seconds`` more: simulated
    seconds per wall second (``rt_factor``) and per CPU second of the process, all threads (``cpu_rt_factor``);
    ``cpu_us_per_step``: the CPU time per control step of the loop's own thread and of every other thread (a
    spiking network's thread and numba's workers), from the same untimed trials (no per-phase timers).

    With ``record_to`` the MCAP recording is on (as in a real run); otherwise it is off, which
    measures plant + controller + loop alone. With ``parts`` as many trials again follow, timed part by part
    (:func:`per_step_parts`; the factors above come from the untimed trials). With ``versus`` (the overrides of
    another loop, e.g. the same plant and task with PD) that loop is built in this process too and ``rounds``
    trials of each are then timed in turns, one of this loop after one of the other: ``versus`` in the result
    (:func:`_in_turns`) gives their speed ratio pair by pair, which a host whose speed drifts within seconds
    leaves far steadier than two factors taken minutes apart. With ``beside_busy`` rounds, this loop's trials are
    timed alone and beside a busy core in turns (:func:`beside_busy_core`).
    """
    exp, _ = load(overrides)
    t0 = time.perf_counter()
    ctx = build_components(exp)
    build_s = time.perf_counter() - t0
    rec = Recorder(record_to, joint_names=ctx.plant.joint_names) if record_to is not None else None
    loop = ClosedLoop(ctx, rec)
    loop.start()
    steps_per_trial = ctx.task.steps_per_trial
    dt = loop.dt_s
    # run whole trials: the loop's unit of work; warm-up first
    warm_trials = max(1, round(warmup_s / (steps_per_trial * dt)))
    timed_trials = max(1, round(seconds / (steps_per_trial * dt)))
    try:
        for i in range(warm_trials):
            loop.run_trial(i)
        t1, c1, m1 = time.perf_counter(), time.process_time(), time.thread_time()
        for i in range(warm_trials, warm_trials + timed_trials):
            loop.run_trial(i)
        wall, cpu, main_cpu = time.perf_counter() - t1, time.process_time() - c1, time.thread_time() - m1
        if parts:
            first = warm_trials + timed_trials
            table = per_step_parts(loop, range(first, first + timed_trials), steps_per_trial)
        next_trial = warm_trials + timed_trials * (2 if parts else 1)
        if versus is not None:
            turns = _in_turns(loop, next_trial, versus, rounds, warm_trials)
            next_trial += rounds
        if beside_busy:
            busy = beside_busy_core(loop, next_trial, beside_busy)
    finally:
        if rec is not None:
            loop.settle()
            rec.close()
    steps = timed_trials * steps_per_trial
    sim = steps * dt
    return {"overrides": overrides, "build_s": round(build_s, 3), "sim_seconds": sim,
            "wall_seconds": round(wall, 3), "rt_factor": round(sim / wall, 2),
            "cpu_seconds": round(cpu, 3), "cpu_rt_factor": round(sim / cpu, 2),
            "us_per_step": round(wall / steps * 1e6, 1),
            "cpu_us_per_step": {"main_thread": round(main_cpu / steps * 1e6, 1),
                                "other_threads": round((cpu - main_cpu) / steps * 1e6, 1)},
            "recording": record_to is not None, **({"per_step_us": table} if parts else {}),
            **({"versus": turns} if versus is not None else {}),
            **({"beside_busy_core": busy} if beside_busy else {})}


BUSY_FLOATS = 1 << 20
"""The busy core's array: 4 MB of float32, streamed over and over (the state a network thread sweeps every step is a
few MB: neuron variables, not the synaptic weights that only spikes touch)."""


@njit(cache=True, nogil=True, boundscheck=False)
def _stream(a, passes):  # pragma: no cover - numba
    """``passes`` passes of a multiply-add over ``a`` (~0.1 ms each on a 2-core VM), without the interpreter lock."""
    for _ in range(passes):
        for i in range(a.shape[0]):
            a[i] = a[i] * np.float32(0.999) + np.float32(1e-3)


BUSY_PASSES = 200


class _BusyCore:
    """A thread that streams over :data:`BUSY_FLOATS` floats in compiled code, without the interpreter lock, until
    stopped: what a spiking network's thread does to the loop's thread beside it, without the hand-overs."""

    def __init__(self) -> None:
        self._a = np.ones(BUSY_FLOATS, np.float32)
        _stream(self._a[:8], 1)  # compiled (or loaded) before any timing
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="cerebx-busy", daemon=True)
        self.calls = 0  # compiled calls done (BUSY_PASSES passes each)

    def _run(self) -> None:
        while not self._stop.is_set():  # ~20 ms a call: the thread needs the interpreter lock rarely
            _stream(self._a, BUSY_PASSES)
            self.calls += 1

    def __enter__(self) -> _BusyCore:
        self._thread.start()
        time.sleep(0.01)  # running before the timed trial starts
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join()


def beside_busy_core(loop: ClosedLoop, first: int, rounds: int) -> dict[str, Any]:
    """Trials of ``loop`` (from trial ``first`` on) timed alone and beside a busy core (:class:`_BusyCore`), one of
    each in turn, ``rounds`` times: per round, the speed beside the busy core over the speed alone; medians over
    the rounds. On a host whose cores share their execution units or memory path, a loop whose other thread is busy
    (a spiking network's) runs slower than the same work alone: the ratio says by how much on this host, the
    ceiling of a closed loop's speed against a loop with nothing beside it (``versus``)."""
    sim = loop.ctx.task.steps_per_trial * loop.dt_s
    alone_rt, busy_rt = [], []
    for r in range(rounds):
        t0 = time.perf_counter()
        loop.run_trial(first + 2 * r)
        t1 = time.perf_counter()
        with _BusyCore():
            t2 = time.perf_counter()
            loop.run_trial(first + 2 * r + 1)
            t3 = time.perf_counter()
        alone_rt.append(sim / (t1 - t0))
        busy_rt.append(sim / (t3 - t2))
    return {"rounds": rounds, **_ratio_summary(busy_rt, alone_rt, "rt_factor_beside_busy_median",
                                               "rt_factor_alone_median")}


def _ratio_summary(this_rt: list[float], other_rt: list[float], this_key: str, other_key: str) -> dict[str, float]:
    """Per-round speed ratios ``this_rt[r] / other_rt[r]``: their median and range, and each side's median factor."""
    ratios = [a / b for a, b in zip(this_rt, other_rt)]
    return {"ratio_median": round(statistics.median(ratios), 3), "ratio_min": round(min(ratios), 3),
            "ratio_max": round(max(ratios), 3), this_key: round(statistics.median(this_rt), 2),
            other_key: round(statistics.median(other_rt), 2)}


def _in_turns(loop: ClosedLoop, first: int, overrides: list[str], rounds: int, warm_trials: int) -> dict[str, Any]:
    """Trials of ``loop`` (from trial ``first`` on) and of the loop ``overrides`` compose, one of each in turn,
    ``rounds`` times, after ``warm_trials`` untimed ones of the other: per round, this loop's real-time factor
    over the other's (its speed as a fraction of the other's), and both factors; medians over the rounds."""
    other = ClosedLoop(build_components(load(overrides)[0]), None)
    other.start()
    for i in range(warm_trials):
        other.run_trial(i)
    sim_this = loop.ctx.task.steps_per_trial * loop.dt_s
    sim_other = other.ctx.task.steps_per_trial * other.dt_s
    this_rt, other_rt = [], []
    for r in range(rounds):
        t0 = time.perf_counter()
        other.run_trial(warm_trials + r)
        t1 = time.perf_counter()
        loop.run_trial(first + r)
        t2 = time.perf_counter()
        this_rt.append(sim_this / (t2 - t1))
        other_rt.append(sim_other / (t1 - t0))
    return {"overrides": overrides, "rounds": rounds,
            **_ratio_summary(this_rt, other_rt, "rt_factor_median", "versus_rt_factor_median")}


def per_step_parts(loop: ClosedLoop, trials: range, steps_per_trial: int) -> dict[str, Any]:
    """Run ``trials`` with every part timed (after one more, untimed, when a network's kernels are timed);
    microseconds per control step of each. ``main``: the loop's thread by phase (``loop/instrument.py``: plant,
    brain and robot stages, recording, end of trial, the loop's own work, and ``wait`` for the network thread),
    summing to ``main_total``. ``network``: a spiking network's
    kernels by part (each population's integration, spike delivery, plasticity, bookkeeping, the chunk's
    outputs; ``snn/kernels.py``), and ``thread_other`` the rest of its thread's busy time (the chunk's hand-over
    in Python), summing to ``network_busy``, the network thread's wall time per step (the loop's own thread
    when the network is not pipelined: then its parts are inside ``brain``). CPU time, which a loaded host changes
    much less than wall time: ``process_cpu`` (every thread) and ``network_cpu`` (the network thread's chunks)."""
    clock = phase_clock.PhaseClock("loop")
    instrument(loop, clock)
    net = getattr(loop.ctx.controller, "net", None)  # a spiking controller's network
    net = net if hasattr(net, "start_profile") else None
    if net is not None:  # an untimed first trial with the profile on (kept: the timed trials stay those they were)
        net.start_profile()
        loop.run_trial(trials[0])
        loop.settle()
        trials = range(trials.start + 1, trials.stop + 1)
        net.start_profile()
    phase_clock.activate(clock)
    cpu0 = time.process_time()
    try:
        for i in trials:
            loop.run_trial(i)
        loop.settle()
    finally:
        phase_clock.activate(None)
    cpu = time.process_time() - cpu0
    steps = len(trials) * steps_per_trial
    report = clock.report()
    us = 1e6 / steps
    main = {k: round(v * us, 2) for k, v in report["wall_s"].items()}
    out: dict[str, Any] = {"steps": steps, "main": main, "main_total": round(sum(report["wall_s"].values()) * us, 2),
                           "process_cpu": round(cpu * us, 2)}
    if net is not None:
        kernels = {k: round(v * us, 2) for k, v in net.profile().items()}
        busy = report["background"].get("network", {}).get("wall_s", 0.0) * us
        if busy:  # pipelined: the chunks' wall time on the network thread
            kernels["thread_other"] = round(busy - sum(kernels.values()), 2)
        out["network"] = kernels
        out["network_busy"] = round(busy or sum(kernels.values()), 2)
        if busy:
            out["network_cpu"] = round(report["background"]["network"]["cpu_s"] * us, 2)
        net.prof = None
    return out
