"""Stiff PD position servo with model-based gravity feed-forward (Baxter's factory controller stand-in)."""

from __future__ import annotations

from typing import Any

import numpy as np

from cerebx.builders import BuildContext
from cerebx.controllers.base import ControlInput, Controller, TorqueMsg


class PositionServo(Controller):
    """tau = sat(kp (q_d - q) + kd (v qd_d - qd) + g(q)), v = 1 with velocity feed-forward, else 0.

    g(q) comes from the plant's ``gravity_torque(q)`` (the MuJoCo model, including an attached payload,
    minus what the plant compensates itself); plants without that method get no feed-forward.
    Before the first sensor message arrives the output is zero.
    """

    def __init__(self, cfg: Any, ctx: BuildContext | None = None):
        self.cfg = cfg
        self.n_joints = len(cfg.kp)
        self._kp = np.asarray(cfg.kp, dtype=float)
        self._kd = np.asarray(cfg.kd, dtype=float)
        self._tau_max = np.asarray(cfg.tau_max_Nm, dtype=float)
        plant = getattr(ctx, "plant", None) if ctx is not None else None
        gravity = getattr(plant, "gravity_torque", None)
        self._qd_gain = 1.0 if cfg.velocity_feedforward else 0.0
        self._gravity = gravity if (cfg.gravity_compensation and callable(gravity)) else None

    def reset(self, rng: np.random.Generator) -> None:
        pass

    def control(self, inp: ControlInput) -> TorqueMsg:
        if inp.sensor is None:
            return TorqueMsg(stamp_s=inp.t_s, tau=np.zeros(self.n_joints))
        q, qd = inp.sensor.q, inp.sensor.qd
        tau = self._kp * (inp.q_des - q) + self._kd * (self._qd_gain * inp.qd_des - qd)
        if self._gravity is not None:
            tau += self._gravity(q)
        np.minimum(np.maximum(tau, -self._tau_max, out=tau), self._tau_max, out=tau)
        return TorqueMsg(stamp_s=inp.t_s, tau=tau)

    def describe(self) -> dict[str, Any]:
        return {"kp": list(self._kp), "kd": list(self._kd), "gravity_feedforward": self._gravity is not None}
