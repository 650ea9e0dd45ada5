"""Point-to-point swings with a minimum-jerk profile, s(u) = 10 u^3 - 15 u^4 + 6 u^5 (u: fraction of the move)."""

from __future__ import annotations

import numpy as np

from cerebx.api import BuildContext, Task, TrialReference
from my_lab.schema import SwingTask


def min_jerk(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Position (0 to 1) and its derivative with respect to u, for u clipped to [0, 1]."""
    u = np.clip(u, 0.0, 1.0)
    return 10 * u**3 - 15 * u**4 + 6 * u**5, 30 * u**2 - 60 * u**3 + 30 * u**4


class Swing(Task):
    control_dt_s = 0.002

    def __init__(self, cfg: SwingTask, ctx: BuildContext | None = None):
        self.cfg = cfg
        self.period_s = cfg.period_s
        self.rest = np.asarray(cfg.rest_rad, float)
        self.refs = [self._swing(i, np.asarray(target, float)) for i, target in enumerate(cfg.targets_rad)]

    def _swing(self, i: int, target: np.ndarray) -> TrialReference:
        """Out to ``target``, hold, back to rest, hold: one trial, one row per 2 ms step."""
        move = self.cfg.move_s
        hold = (self.period_s - 2 * move) / 2
        t = np.arange(self.steps_per_trial) * self.control_dt_s
        out, out_rate = min_jerk(t / move)
        back, back_rate = min_jerk((t - move - hold) / move)
        shape, rate = out - back, (out_rate - back_rate) / move  # 0 -> 1 -> 0, and its time derivative
        span = target - self.rest
        return TrialReference(q=self.rest + shape[:, None] * span, qd=rate[:, None] * span, label=f"target {i}")

    def trial(self, index: int, rng: np.random.Generator) -> TrialReference:
        return self.refs[rng.integers(len(self.refs))]  # the run's seeded generator picks the target

    def start_position(self) -> np.ndarray:
        return self.rest.copy()

    def envelope(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Over every target, not only the first trial's (input encoders size their ranges from it)."""
        q = np.concatenate([r.q for r in self.refs])
        qd = np.concatenate([r.qd for r in self.refs])
        return q.min(0), q.max(0), qd.min(0), qd.max(0)
