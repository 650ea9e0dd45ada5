"""Delay-study tables (thesis Fig. 3.4 / 3.7 / 3.8) from run logs: per run, the controller and delay
presets, the realised round-trip delay (from the delays recorded in /control), MAE and torque
variability (Eq. 3.14-3.15) over the run's trials."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from cerebx.recording.reader import read_messages


def realised_round_trip_ms(run_dir: Path, max_messages: int = 5000) -> float | None:
    """Mean R2C + C2R delay sampled in the first ``max_messages`` steps."""
    total, n = 0.0, 0
    for _, _, msg in read_messages(run_dir, ["/control"]):
        total += msg.get("r2c_ms", 0.0) + msg.get("c2r_ms", 0.0)
        n += 1
        if n >= max_messages:
            break
    return total / n if n else None


def delay_rows(runs: list[tuple[Path, dict]]) -> list[list[str]]:
    rows = [["task", "controller", "delay", "overrides", "realised round trip (ms)", "MAE mean ± std (rad)",
             "MAE last 10 trials", "torque variability (N·m/ms)", "run"]]
    for d, s in runs:
        mae = s.get("mae_per_trial") or []
        if not mae or s.get("delay") == "none" and "delay" not in (s.get("presets") or {}):
            continue
        p = s.get("presets") or {}
        tv = s.get("torque_variability_per_trial") or [float("nan")]
        rt = realised_round_trip_ms(d)
        delay_overrides = " ".join(o for o in s.get("overrides", []) if o.startswith("delay"))
        rows.append([s["task"], p.get("controller", s["controller"]), p.get("delay", s["delay"]), delay_overrides,
                     "–" if rt is None else f"{rt:.1f}", f"{np.mean(mae):.4f} ± {np.std(mae):.4f}",
                     f"{np.mean(mae[-10:]):.4f}", f"{np.mean(tv):.4f}", d.name])
    return rows
