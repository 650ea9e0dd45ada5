"""Crude inverse dynamics (Luque et al. 2011, Fig. 3): the torque the arm *without* the object needs for the
desired q, qd, qdd, from MuJoCo's inverse dynamics on a copy of the plant's model (``mj_inverse``: mass
matrix, Coriolis and gravity, joint damping)."""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from cerebx.api import BuildContext, ConfigError, Frame, Stage
from cerebx_luque2011.schema import CrudeInverseDynamics


def inverse_torque(model: mujoco.MjModel, data: mujoco.MjData, q: np.ndarray, qd: np.ndarray,
                   qdd: np.ndarray) -> np.ndarray:
    """Joint torque that gives acceleration ``qdd`` at state (``q``, ``qd``) on ``model``."""
    data.qpos[:] = q
    data.qvel[:] = qd
    data.qacc[:] = qdd
    mujoco.mj_inverse(model, data)
    return data.qfrc_inverse.copy()


class CrudeInverseDynamicsStage(Stage):
    """Writes the feed-forward ``joint.torque`` of the nominal (object-free) arm model."""

    def __init__(self, cfg: CrudeInverseDynamics, ctx: BuildContext):
        nominal = getattr(ctx.plant, "nominal_model", None)
        if not callable(nominal):
            raise ConfigError(f"controller: crude_inverse_dynamics needs a plant with a nominal model; "
                              f"{type(ctx.plant).__name__} has no nominal_model()")
        self.model = nominal()
        self.data = mujoco.MjData(self.model)

    def step(self, frame: Frame) -> None:
        s = frame.signals
        self.emit(frame, "joint.torque", inverse_torque(self.model, self.data, s["ref.q"], s["ref.qd"], s["ref.qdd"]))

    def describe(self) -> dict[str, Any]:
        return {"model": "plant without object", "bodies": int(self.model.nbody)}
