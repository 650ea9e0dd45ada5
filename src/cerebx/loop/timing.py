"""Closed-loop speed: simulated seconds per wall second for a composed experiment, and where a control step's time
goes (:func:`per_step_parts`)."""

from __future__ import annotations

import statistics
import time
from pathlib import Path
from typing import Any

from cerebx import phase_clock
from cerebx.build import build_components
from cerebx.config import load
from cerebx.loop.instrument import instrument
from cerebx.loop.loop import ClosedLoop
from cerebx.recording.recorder import Recorder


def closed_loop_rt(overrides: list[str], seconds: float = 4.0, warmup_s: float = 1.0,
                   record_to: Path | None = None, parts: bool = False,
                   versus: list[str] | None = None, rounds: int = 8) -> dict[str, Any]:
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
    leaves far steadier than two factors taken minutes apart.
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
        if versus is not None:
            turns = _in_turns(loop, warm_trials + timed_trials * (2 if parts else 1), versus, rounds, warm_trials)
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
            **({"versus": turns} if versus is not None else {})}


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
    ratios, this_rt, other_rt = [], [], []
    for r in range(rounds):
        t0 = time.perf_counter()
        other.run_trial(warm_trials + r)
        t1 = time.perf_counter()
        loop.run_trial(first + r)
        t2 = time.perf_counter()
        this_rt.append(sim_this / (t2 - t1))
        other_rt.append(sim_other / (t1 - t0))
        ratios.append(this_rt[-1] / other_rt[-1])
    return {"overrides": overrides, "rounds": rounds, "ratio_median": round(statistics.median(ratios), 3),
            "ratio_min": round(min(ratios), 3), "ratio_max": round(max(ratios), 3),
            "rt_factor_median": round(statistics.median(this_rt), 2),
            "versus_rt_factor_median": round(statistics.median(other_rt), 2)}


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
