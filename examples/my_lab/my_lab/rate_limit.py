"""The torque rate limiter: a robot-side stage with a little state (the torque it let through last step)."""

from __future__ import annotations

from typing import Any

import numpy as np

from cerebx.api import BuildContext, Frame, Stage
from my_lab.schema import RateLimitConfig


class RateLimiter(Stage):
    def __init__(self, cfg: RateLimitConfig, ctx: BuildContext):
        n = ctx.plant.n_joints
        io = cfg.io(n)
        self.name, self.reads, self.writes = cfg.kind, io.reads, io.writes  # what the loop and checker see
        self.max_step_Nm = cfg.max_rate_Nm_per_ms * ctx.cfg.control_dt_ms
        self.last = np.zeros(n)
        self.cut = np.zeros(n)

    def reset(self, rng: np.random.Generator) -> None:
        self.last = np.zeros_like(self.last)
        self.cut = np.zeros_like(self.cut)

    def step(self, frame: Frame) -> None:
        wanted = frame.signals["joint.torque"]
        tau = self.last + np.clip(wanted - self.last, -self.max_step_Nm, self.max_step_Nm)
        self.cut, self.last = wanted - tau, tau
        self.emit(frame, "joint.torque", tau)  # replaces the command (the schema declares no "adds")

    def record(self) -> dict[str, Any]:
        return {"tau_rate_cut": self.cut}  # a field of every /control message: what the limit held back
