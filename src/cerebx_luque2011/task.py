"""The eight-like joint trajectory of Luque et al. 2011 (Eq. 1) with its exact velocity and acceleration."""

from __future__ import annotations

import numpy as np

from cerebx.api import BuildContext, Task, TrialReference
from cerebx_luque2011.schema import LuqueEightTask


def luque_eight(cfg: LuqueEightTask, t_s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """q, qd, qdd at times ``t_s``, each (len(t_s), 3)."""
    w = 2 * np.pi / cfg.period_s
    amp = np.array([cfg.amplitude1_rad, cfg.amplitude2_rad, cfg.amplitude2_rad])
    phase = w * np.asarray(t_s, float)[:, None] + np.array([0.0, 1.0, 2.0]) * cfg.theta_rad
    s, c = np.sin(phase), np.cos(phase)
    return np.asarray(cfg.offset_rad) + amp * s, amp * w * c, -amp * w * w * s


class LuqueEight(Task):
    control_dt_s = 0.002

    def __init__(self, cfg: LuqueEightTask, ctx: BuildContext | None = None):
        self.cfg = cfg
        self.period_s = cfg.period_s
        q, qd, qdd = luque_eight(cfg, np.arange(self.steps_per_trial) * self.control_dt_s)
        self._ref = TrialReference(q=q, qd=qd, label="luque_eight", extra={"qdd": qdd})

    def trial(self, index: int, rng: np.random.Generator) -> TrialReference:
        return self._ref

    def start_position(self) -> np.ndarray:
        return self._ref.q[0].copy()
