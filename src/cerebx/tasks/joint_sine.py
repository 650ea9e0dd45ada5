"""Joint-space sinusoids: q_j(t) = offset_j + A_j sin(2 pi t / T + phi_j)."""

from __future__ import annotations

import numpy as np

from cerebx.builders import BuildContext
from cerebx.schema.task import JointSineTask
from cerebx.tasks.base import Task, TrialReference


class JointSine(Task):
    control_dt_s = 0.002

    def __init__(self, cfg: JointSineTask, ctx: BuildContext | None = None):
        self.cfg = cfg
        self.period_s = cfg.period_s
        t = np.arange(self.steps_per_trial) * self.control_dt_s
        w = 2 * np.pi / cfg.period_s
        off, amp, ph = (np.asarray(v, float) for v in (cfg.offset_rad, cfg.amplitude_rad, cfg.phase_rad))
        phase = w * t[:, None] + ph
        self._ref = TrialReference(q=off + amp * np.sin(phase), qd=amp * w * np.cos(phase), label="joint_sine")

    def trial(self, index: int, rng: np.random.Generator) -> TrialReference:
        return self._ref

    def start_position(self) -> np.ndarray:
        return self._ref.q[0].copy()
