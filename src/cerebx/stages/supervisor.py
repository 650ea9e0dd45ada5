"""The safety supervisor: a watchdog PD that acts only while a joint is outside its bounds
(docs/models.md#supervisor)."""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from cerebx.builders import BuildContext
from cerebx.schema.stages import SupervisorConfig
from cerebx.signals import Frame
from cerebx.stages.base import Stage


@numba.njit(cache=True, boundscheck=False)
def _correct(q, qd, lo, hi, kp, kd, ramp, s, tau):  # pragma: no cover - numba
    """The rule joint by joint, ``s`` and ``tau`` written in place: the same operations in the same order as
    the array form ``where(outside, kp (bound - q) - s kd qd, 0)``, so the same doubles."""
    for j in range(kp.size):
        if q[j] < lo[j]:
            bound = lo[j]
        elif q[j] > hi[j]:
            bound = hi[j]
        else:
            s[j] = 0.0
            tau[j] = 0.0
            continue
        s[j] = min(s[j] + ramp, 1.0)
        tau[j] = kp[j] * (bound - q[j]) - s[j] * kd[j] * qd[j]


class Supervisor(Stage):
    """Adds kp (bound - q) - s kd qd to ``joint.torque`` for joints outside [lo, hi]; s ramps to 1."""

    name = "supervisor"

    def __init__(self, cfg: SupervisorConfig, lo: np.ndarray, hi: np.ndarray):
        self.kp, self.kd = np.asarray(cfg.kp, float), np.asarray(cfg.kd, float)
        self.ramp = cfg.ramp_per_step
        self.lo, self.hi = lo - cfg.margin_rad, hi + cfg.margin_rad
        self.s = np.zeros_like(self.kp)
        io = cfg.io(len(self.kp))
        self.reads, self.writes, self.adds = io.reads, io.writes, io.adds
        self.tau = np.zeros_like(self.kp)

    def correction(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """The correction for this tick (a new array), the ramp advanced. One compiled call: as array
        operations the rule cost the loop ~6 us a tick."""
        if q.shape != self.kp.shape or qd.shape != self.kp.shape:
            raise ValueError(f"supervisor: {len(self.kp)} joints, got q {q.shape} and qd {qd.shape}")
        tau = np.empty(self.kp.shape)
        _correct(q, qd, self.lo, self.hi, self.kp, self.kd, self.ramp, self.s, tau)
        return tau

    def reset(self, rng: np.random.Generator) -> None:
        self.s = np.zeros_like(self.kp)

    def step(self, frame: Frame) -> None:
        sig = frame.signals
        self.tau = self.correction(sig["joint.q"], sig["joint.qd"])
        self.emit(frame, "joint.torque", self.tau)

    def record(self) -> dict[str, Any]:
        return {"tau_supervisor": self.tau}


def build_supervisor(cfg: SupervisorConfig, ctx: BuildContext) -> Supervisor:
    """Bounds: the controller's MF position ranges (``encoder``, when it has them) or the plant's limits."""
    lo, hi = ctx.plant.joint_limits()
    bounds = getattr(ctx.controller, "position_bounds", None)
    if cfg.bounds == "encoder" and callable(bounds):
        lo, hi = bounds()
    return Supervisor(cfg, np.asarray(lo, float), np.asarray(hi, float))
