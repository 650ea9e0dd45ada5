"""Realised delays read back from run logs, and the report's delay table (``delays.csv``): per run with a
delay, the controller and delay presets, the realised round trip, MAE and torque variability over the run's
measured trials."""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from cerebx.report.runs import Run, RunSet

DELAY_TRIALS = 10  # trials of /control read per run for its realised delays (10k steps: stationary, fast)


@lru_cache(maxsize=64)
def _read_delays(run_dir: str, t1: float) -> tuple[np.ndarray, np.ndarray]:
    c = Run.load(run_dir).control(["r2c_ms", "c2r_ms"], t1=t1)
    return c["r2c_ms"], c["c2r_ms"]


def delays(run: Run) -> tuple[np.ndarray, np.ndarray]:
    """R2C and C2R delays (ms) of every 2 ms step in the run's first DELAY_TRIALS trials.

    Parameters
    ----------
    run : Run
        A run recorded over a delayed link (its ``/control`` messages carry the delays).
    """
    return _read_delays(str(run.dir), round(max(1, min(run.trials, DELAY_TRIALS)) * run.period_s, 6))


def delay_rows(runs: RunSet) -> list[list[str]]:
    rows = [["task", "controller", "delay", "overrides", "realised round trip (ms)", "MAE mean ± std (rad)",
             "MAE last 10 trials", "torque variability (N·m/ms)", "run"]]
    for r in runs:
        mae = r.mae
        if not mae.size or r.delay == "none" and "delay" not in (r.summary.get("presets") or {}):
            continue
        tv = r.series("torque_variability_per_trial")
        if r.delay == "none":  # no link delay: nothing to read (its log may hold no control step, recording.trials)
            rt = "0.0"
        else:
            r2c, c2r = delays(r)
            rt = f"{np.mean(r2c + c2r):.1f}" if r2c.size else "–"
        delay_overrides = " ".join(o for o in r.summary.get("overrides", []) if o.startswith("delay"))
        rows.append([r.task, r.controller_preset, r.delay_preset, delay_overrides, rt,
                     f"{np.mean(mae):.4f} ± {np.std(mae):.4f}", f"{np.mean(mae[-10:]):.4f}",
                     f"{np.mean(tv):.4f}" if tv.size else "nan", r.name])
    return rows
