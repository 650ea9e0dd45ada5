"""Closed-loop speed: simulated seconds per wall second for a composed experiment."""

from __future__ import annotations

import time
from pathlib import Path
from typing import Any

from cerebx.build import build_components
from cerebx.config import load
from cerebx.loop.loop import ClosedLoop
from cerebx.recording.recorder import Recorder


def closed_loop_rt(overrides: list[str], seconds: float = 4.0, warmup_s: float = 1.0,
                   record_to: Path | None = None) -> dict[str, Any]:
    """Run ``overrides`` for ``warmup_s`` (compilation, first-touch), then time ``seconds`` more: simulated
    seconds per wall second (``rt_factor``) and per CPU second of the process, all threads (``cpu_rt_factor``).

    With ``record_to`` the MCAP recording is on (as in a real run); otherwise it is off, which
    measures plant + controller + loop alone.
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
        t1, c1 = time.perf_counter(), time.process_time()
        for i in range(warm_trials, warm_trials + timed_trials):
            loop.run_trial(i)
        wall, cpu = time.perf_counter() - t1, time.process_time() - c1
    finally:
        if rec is not None:
            loop.settle()
            rec.close()
    sim = timed_trials * steps_per_trial * dt
    return {"overrides": overrides, "build_s": round(build_s, 3), "sim_seconds": sim,
            "wall_seconds": round(wall, 3), "rt_factor": round(sim / wall, 2),
            "cpu_seconds": round(cpu, 3), "cpu_rt_factor": round(sim / cpu, 2),
            "us_per_step": round(wall / (timed_trials * steps_per_trial) * 1e6, 1),
            "recording": record_to is not None}
