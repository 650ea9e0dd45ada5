"""Capolei et al. 2020 planner (Eq. 1-2): every joint oscillates about 0 at f; one trial = one period."""

from __future__ import annotations

import numpy as np

from cerebx.api import BuildContext, Task, TrialReference
from cerebx_capolei2020.schema import WristOscillationTask


class WristOscillation(Task):
    control_dt_s = 0.002

    def __init__(self, cfg: WristOscillationTask, ctx: BuildContext | None = None):
        self.cfg = cfg
        self.period_s = cfg.period_s
        t = np.arange(self.steps_per_trial) * self.control_dt_s
        amp, ph = np.asarray(cfg.amplitude_rad, float), np.asarray(cfg.phase_rad, float)
        phase = 2 * np.pi * cfg.frequency_hz * t[:, None] + ph
        self._ref = TrialReference(q=amp * np.sin(phase), qd=2 * np.pi * cfg.frequency_hz * amp * np.cos(phase),
                                   label="wrist_oscillation")

    def trial(self, index: int, rng: np.random.Generator) -> TrialReference:
        return self._ref

    def start_position(self) -> np.ndarray:
        return self._ref.q[0].copy()
