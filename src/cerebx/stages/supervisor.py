"""The safety supervisor: a watchdog PD that acts only while a joint is outside its bounds
(docs/models.md#supervisor)."""

from __future__ import annotations

from typing import Any

import numpy as np

from cerebx.schema.stages import SupervisorConfig
from cerebx.signals import Frame
from cerebx.stages.base import Stage


class Supervisor(Stage):
    """Adds kp (bound - q) - s kd qd to ``joint.torque`` for joints outside [lo, hi]; s ramps to 1."""

    name = "supervisor"

    def __init__(self, cfg: SupervisorConfig, lo: np.ndarray, hi: np.ndarray):
        self.kp, self.kd = np.asarray(cfg.kp), np.asarray(cfg.kd)
        self.ramp = cfg.ramp_per_step
        self.lo, self.hi = lo - cfg.margin_rad, hi + cfg.margin_rad
        self.s = np.zeros_like(self.kp)
        io = cfg.io(len(self.kp))
        self.reads, self.writes, self.adds = io.reads, io.writes, io.adds
        self.tau = np.zeros_like(self.kp)

    def correction(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        below, above = q < self.lo, q > self.hi
        outside = below | above
        if not outside.any():  # every joint inside its bounds, as on most ticks: what the full rule gives
            self.s = np.zeros(self.kp.shape)
            return np.zeros(self.kp.shape)
        self.s = np.where(outside, np.minimum(self.s + self.ramp, 1.0), 0.0)
        bound = np.where(below, self.lo, self.hi)
        return np.where(outside, self.kp * (bound - q) - self.s * self.kd * qd, 0.0)

    def reset(self, rng: np.random.Generator) -> None:
        self.s = np.zeros_like(self.kp)

    def step(self, frame: Frame) -> None:
        sig = frame.signals
        self.tau = self.correction(sig["joint.q"], sig["joint.qd"])
        self.emit(frame, "joint.torque", self.tau)

    def record(self) -> dict[str, Any]:
        return {"tau_supervisor": self.tau}


def build_supervisor(cfg: SupervisorConfig, ctx: Any) -> Supervisor:
    """Bounds: the controller's MF position ranges (``encoder``, when it has them) or the plant's limits."""
    lo, hi = ctx.plant.joint_limits()
    bounds = getattr(ctx.controller, "position_bounds", None)
    if cfg.bounds == "encoder" and callable(bounds):
        lo, hi = bounds()
    return Supervisor(cfg, np.asarray(lo, float), np.asarray(hi, float))
