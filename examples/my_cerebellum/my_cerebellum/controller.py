"""The model's code: a joint-torque controller with a learned state that ``init_from`` can start from."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from cerebx.api import (
    BuildContext,
    ControlInput,
    Controller,
    StateMismatchError,
    TorqueMsg,
    load_state_npz,
    save_state_npz,
)
from my_cerebellum.schema import AdaptiveFilterConfig

STEP_S = 0.002


class AdaptiveFilter(Controller):
    def __init__(self, cfg: AdaptiveFilterConfig, ctx: BuildContext | None = None):
        self.cfg = cfg
        self.n_joints = cfg.n_joints
        tau = np.geomspace(cfg.tau_min_ms, cfg.tau_max_ms, cfg.filters) / 1000.0
        self.decay = np.exp(-STEP_S / tau)  # one step of each low-pass filter
        self.w = np.zeros((cfg.n_joints, 2 * cfg.filters + 1))
        self.reset(np.random.default_rng(0))

    def reset(self, rng: np.random.Generator) -> None:
        self.x = np.zeros((self.n_joints, 2, self.cfg.filters))  # filter states of q_d and qd_d
        self.history: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}  # tick -> (g, q_d, qd_d)

    def _granules(self, q_des: np.ndarray, qd_des: np.ndarray) -> np.ndarray:
        drive = np.stack([q_des, qd_des], axis=1)[:, :, None]
        self.x = self.decay * self.x + (1.0 - self.decay) * drive
        return np.concatenate([self.x.reshape(self.n_joints, -1), np.ones((self.n_joints, 1))], axis=1)

    def control(self, inp: ControlInput) -> TorqueMsg:
        g = self._granules(inp.q_des, inp.qd_des)
        self.history[inp.tick] = (g, inp.q_des, inp.qd_des)
        self.history.pop(inp.tick - 1000, None)
        s = inp.sensor
        if s is not None and (past := self.history.get(int(round(s.stamp_s / STEP_S)))) is not None:
            g_then, q_des, qd_des = past  # the error belongs to the state the arm was asked for then
            error = self.cfg.k_pos * (q_des - s.q) + self.cfg.k_vel * (qd_des - s.qd)
            self.w += self.cfg.rate * STEP_S * error[:, None] * g_then
        tau = np.clip((self.w * g).sum(axis=1), -self.cfg.tau_max_Nm, self.cfg.tau_max_Nm)
        return TorqueMsg(inp.t_s, tau)

    def save_state(self, path: Path) -> bool:
        save_state_npz(path, {"kind": self.cfg.kind, "n_joints": self.n_joints, "filters": self.cfg.filters},
                       weights=self.w)
        return True

    def load_state(self, path: Path) -> None:
        data, meta = load_state_npz(path, self.cfg.kind)
        if data["weights"].shape != self.w.shape:
            raise StateMismatchError(f"{path}: weights of shape {data['weights'].shape}, need {self.w.shape}")
        self.w = data["weights"].copy()

    def describe(self) -> dict[str, Any]:
        return {"filters": self.cfg.filters, "weights": int(self.w.size)}
