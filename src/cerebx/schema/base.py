"""Shared building blocks for the configuration schemas."""

from __future__ import annotations

from typing import Annotated

from pydantic import AfterValidator, BaseModel, ConfigDict, Field

from cerebx.signals import joint_signals

JOINTS_BAXTER = ("s0", "s1", "e0", "e1", "w0", "w1")


class Strict(BaseModel):
    """Base of every config model: unknown keys are errors and values are immutable."""

    model_config = ConfigDict(extra="forbid", frozen=True, validate_default=True)


CONTROL_DT_MS = 2.0
"""The control step (500 Hz) every loop runs at."""

PositiveFloat = Annotated[float, Field(gt=0)]


def _divides_control_step(ms: float) -> float:
    n = CONTROL_DT_MS / ms
    if abs(n - round(n)) > 1e-9:
        raise ValueError(f"{ms} ms does not divide the {CONTROL_DT_MS} ms control step")
    return ms


PhysicsStepMs = Annotated[float, Field(gt=0, description="MuJoCo timestep; must divide 2 ms"),
                          AfterValidator(_divides_control_step)]
NonNegFloat = Annotated[float, Field(ge=0)]
PerJoint = tuple[float, ...]
"""One value per controlled joint, in joint order; length is checked against the plant."""


class PlantSchema(Strict):
    """Base of plant schemas: the signals a plant of this config senses and is commanded with.
    The defaults are a joint-torque plant; a plant with other signals overrides both."""

    def sensor_signals(self) -> dict:
        s = joint_signals(self.n_joints)  # type: ignore[attr-defined]
        return {"joint.q": s["joint.q"], "joint.qd": s["joint.qd"]}

    def command_signals(self) -> dict:
        limit = getattr(self, "torque_limit_Nm", None)
        return {"joint.torque": joint_signals(self.n_joints, limit)["joint.torque"]}  # type: ignore[attr-defined]
