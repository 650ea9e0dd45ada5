"""PD torque control with saturation: tau = kp (q_d - q) + kd (qd_d - qd), |tau| <= tau_max."""

from __future__ import annotations

import numpy as np

from cerebx.builders import BuildContext
from cerebx.controllers.base import ControlInput, Controller, TorqueMsg
from cerebx.schema.controller import PDController


class PD(Controller):
    def __init__(self, cfg: PDController, ctx: BuildContext | None = None):
        self.cfg = cfg
        self.kp, self.kd = np.asarray(cfg.kp, float), np.asarray(cfg.kd, float)
        self.tau_max = np.asarray(cfg.tau_max_Nm, float)
        self._tau_min = -self.tau_max
        self.n_joints = len(self.kp)
        self._zero = np.zeros(self.n_joints)

    def reset(self, rng: np.random.Generator) -> None:
        pass

    def control(self, inp: ControlInput) -> TorqueMsg:
        s = inp.sensor
        if s is None:
            return TorqueMsg(inp.t_s, self._zero)
        tau = self.kp * (inp.q_des - s.q) + self.kd * (inp.qd_des - s.qd)
        np.minimum(np.maximum(tau, self._tau_min, out=tau), self.tau_max, out=tau)  # ufuncs: no clip overhead
        return TorqueMsg(inp.t_s, tau)

    def describe(self) -> dict:
        return {"kp": list(self.cfg.kp), "kd": list(self.cfg.kd), "tau_max_Nm": list(self.cfg.tau_max_Nm)}
