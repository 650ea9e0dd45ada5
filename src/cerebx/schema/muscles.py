"""Muscle schemas: the Ekeberg antagonist muscle pair per joint (docs/models.md#ekeberg)
and the brain-side ``muscle_rest`` controller that gives the muscles no active command."""

from __future__ import annotations

from typing import ClassVar, Literal

from pydantic import Field, model_validator

from cerebx.schema.base import NonNegFloat
from cerebx.schema.controller import ControllerConfig, muscle_command_signals
from cerebx.schema.stages import StageConfig
from cerebx.signals import Signal, StageIO


class EkebergConfig(StageConfig):
    """One Ekeberg antagonist muscle pair per joint:

    tau_j = alpha_j (M_ag - M_at) + beta_j [(M_ag + c_j) + (M_at + c_j) + gamma_j] (Q_r,j - Q_j) + delta_j Qd_j

    with c_j = ``cocontraction`` x ``cocontraction_base``_j. M_ag and M_at (in [0, 1]) come through the
    link; the joint state is the robot's own reading, with no delay. Defaults: docs/models.md#ekeberg."""

    sides: ClassVar[tuple[str, ...]] = ("robot",)
    kind: Literal["ekeberg"] = "ekeberg"
    alpha_Nm: tuple[float, ...] = Field(
        (30.0, 40.0, 30.0, 30.0, 10.0, 10.0), description="muscle gain: active torque at M_ag - M_at = 1 (N·m)")
    beta_Nm_per_rad: tuple[NonNegFloat, ...] = Field(
        (1.0, 1.0, 1.0, 1.0, 1.0, 1.0), description="stiffness gain: N·m/rad per unit of summed activation")
    gamma: tuple[NonNegFloat, ...] = Field(
        (3.0, 3.0, 3.0, 3.0, 3.0, 3.0), description="tonic stiffness (activation units, added to M_ag + M_at)")
    delta_Nms_per_rad: tuple[float, ...] = Field(
        (-1.0, -1.0, -1.0, -1.0, -1.0, -1.0), description="damping coefficient (negative opposes motion)")
    rest_pose_rad: tuple[float, ...] = Field(
        (0.0, 0.22, 0.0, 1.34, 0.0, 0.0), description="resting position Q_r per joint")
    cocontraction_base: tuple[NonNegFloat, ...] = Field(
        (1.5, 1.5, 1.5, 1.5, 0.5, 0.5), description="the baseline (x1) cocontraction c per joint")
    cocontraction: NonNegFloat = Field(
        1.0, description="multiplier k of the baseline: c_j = k x cocontraction_base_j")

    @model_validator(mode="after")
    def _rows(self) -> EkebergConfig:
        rows = {name: len(getattr(self, name)) for name in ("alpha_Nm", "beta_Nm_per_rad", "gamma", "delta_Nms_per_rad",
                                                             "rest_pose_rad", "cocontraction_base")}
        if len(set(rows.values())) > 1:
            raise ValueError("rows need one value per joint each, got "
                             + ", ".join(f"{name} {n}" for name, n in rows.items()))
        return self

    def io(self, n_joints: int) -> StageIO:
        return StageIO(("muscle.ag", "muscle.at", "joint.q", "joint.qd"), (Signal("joint.torque", n_joints, "N·m"),))


class MuscleRestController(ControllerConfig):
    """No active muscle component: writes M_ag = M_at = 0 every step, so only the
    muscles' passive stiffness and damping hold the arm."""

    kind: Literal["muscle_rest"] = "muscle_rest"

    def io(self, n_joints: int) -> StageIO:
        return StageIO((), muscle_command_signals(n_joints))
