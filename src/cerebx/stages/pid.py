"""The velocity PID (``pid_velocity``) as a brain-side stage: tau = K_P e + K_I int e + K_D de/dt on the
velocity error, updated at ``rate_hz`` and held between updates."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from cerebx.builders import BuildContext
from cerebx.errors import StateMismatchError
from cerebx.persistence.state import load_state_npz, save_state_npz
from cerebx.schema.controller import VELOCITY_ERROR, PIDVelocity
from cerebx.signals import Frame
from cerebx.stages.base import Stage


def updates_every(rate_hz: float, ctx: BuildContext) -> int:
    """Control ticks between two updates of a part running at ``rate_hz``.

    Parameters
    ----------
    rate_hz : float
        The part's update rate, Hz.
    ctx : BuildContext
        The build context (its config's ``control_dt_ms``).
    """
    return max(1, int(round(1000.0 / (rate_hz * ctx.cfg.control_dt_ms))))


class PIDVelocityStage(Stage):
    """PID on the velocity error e = qdot_r - qdot (+ the configured correction signal)."""

    def __init__(self, cfg: PIDVelocity, ctx: BuildContext):
        self.cfg = cfg
        self.kp, self.ki, self.kd = (np.asarray(v, float) for v in (cfg.kp, cfg.ki, cfg.kd))
        self.every = updates_every(cfg.rate_hz, ctx)
        self.dt_s = self.every * ctx.cfg.control_dt_ms / 1000.0
        n = len(self.kp)
        self.tau, self.e, self.integral, self.prev_e = np.zeros(n), np.zeros(n), np.zeros(n), None

    def reset(self, rng: np.random.Generator) -> None:
        self.tau[:], self.e[:], self.integral[:], self.prev_e = 0.0, 0.0, 0.0, None

    def step(self, frame: Frame) -> None:
        sig = frame.signals
        if frame.tick % self.every == 0 and "joint.qd" in sig:
            e = sig["ref.qd"] - sig["joint.qd"]
            if self.cfg.correction_signal:
                e = e + sig[self.cfg.correction_signal]
            self.integral += e * self.dt_s
            de = np.zeros_like(e) if self.prev_e is None else (e - self.prev_e) / self.dt_s
            self.prev_e = e
            self.e = e
            self.tau = self.kp * e + self.ki * self.integral + self.kd * de
        self.emit(frame, "joint.torque", self.tau.copy())
        self.emit(frame, VELOCITY_ERROR, self.e.copy())

    def save_state(self, path: Path) -> bool:
        save_state_npz(path, {"kind": self.cfg.kind}, integral=self.integral)
        return True

    def load_state(self, path: Path) -> None:
        data, meta = load_state_npz(path, self.cfg.kind)
        if meta.get("kind") != self.cfg.kind or data["integral"].shape != self.integral.shape:
            raise StateMismatchError(f"{path}: not a {self.cfg.kind} state of {len(self.integral)} joints")
        self.integral = data["integral"].copy()

    def describe(self) -> dict[str, Any]:
        return {"kp": list(self.cfg.kp), "ki": list(self.cfg.ki), "kd": list(self.cfg.kd), "rate_hz": self.cfg.rate_hz}


def build_pid(cfg: PIDVelocity, ctx: BuildContext) -> PIDVelocityStage:
    return PIDVelocityStage(cfg, ctx)
