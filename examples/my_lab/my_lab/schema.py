"""What a user may set for the lab's plant, stage and task: fields with units, bounds and defaults, checked
before a run. Only declarations live here (no MuJoCo, no numpy), so validating a config stays fast."""

from __future__ import annotations

from typing import ClassVar, Literal

from pydantic import Field, model_validator

from cerebx.api.schema import (
    NonNegFloat,
    PhysicsStepMs,
    PlantSchema,
    PositiveFloat,
    Signal,
    StageConfig,
    StageIO,
    Strict,
)


# --8<-- [start:plant]
class PendulumConfig(PlantSchema):
    """A pendulum driven by a motor at its pivot: a 0.5 m massless rod with a bob at its end, swinging in a
    vertical plane under gravity (q = 0: hanging down; q > 0: the bob swings towards +x). Model: pendulum.xml."""

    kind: Literal["pendulum"] = "pendulum"
    physics_dt_ms: PhysicsStepMs = 0.5
    bob_mass_kg: PositiveFloat = Field(1.0, description="mass of the bob at the end of the rod")
    damping_Nms_per_rad: NonNegFloat = Field(0.05, description="viscous damping at the pivot")
    torque_limit_Nm: tuple[PositiveFloat] = Field((10.0,), description="motor saturation")

    @property
    def n_joints(self) -> int:
        return 1
# --8<-- [end:plant]


# --8<-- [start:stage]
class RateLimitConfig(StageConfig):
    """Limits how fast the joint torque command may change (a motor driver's slew rate): each 2 ms step the
    torque moves towards the command by at most ``max_rate_Nm_per_ms`` x 2 ms. Robot side, after the receiver."""

    sides: ClassVar[tuple[str, ...]] = ("robot",)
    kind: Literal["rate_limit"] = "rate_limit"
    max_rate_Nm_per_ms: PositiveFloat = Field(0.1, description="largest change of the torque per millisecond")

    def io(self, n_joints: int) -> StageIO:
        torque = Signal("joint.torque", n_joints, "N·m")
        return StageIO(reads=("joint.torque",), writes=(torque,))
# --8<-- [end:stage]


# --8<-- [start:task]
class SwingTask(Strict):
    """Point-to-point swings in joint space: each trial moves from ``rest_rad`` to one of ``targets_rad`` (drawn
    per trial from the run's seed) with a minimum-jerk profile, holds, moves back and holds again."""

    kind: Literal["swing"] = "swing"
    period_s: PositiveFloat = Field(2.0, description="one trial: out, hold, back, hold")
    move_s: PositiveFloat = Field(0.6, description="duration of each movement (out, back)")
    rest_rad: tuple[float, ...] = Field((0.0,), description="start and end pose, one angle per joint")
    targets_rad: list[tuple[float, ...]] = Field(
        [(0.6,), (1.0,), (1.4,)], min_length=1, description="poses to swing to, one angle per joint each")

    @model_validator(mode="after")
    def _fits(self) -> SwingTask:
        if 2 * self.move_s >= self.period_s:
            raise ValueError(f"move_s: two movements of {self.move_s} s do not fit in period_s {self.period_s} s")
        if any(len(t) != len(self.rest_rad) for t in self.targets_rad):
            raise ValueError(f"targets_rad: every target needs {len(self.rest_rad)} angle(s), as rest_rad")
        return self

    @property
    def n_joints(self) -> int:
        return len(self.rest_rad)
# --8<-- [end:task]
