"""Task schemas. Baxter tasks are Cartesian paths of the left end-effector (docs/models.md#cartesian-tasks), turned into
joint paths by inverse kinematics on the plant model; ``joint_sine`` is a joint-space task for
small plants."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from cerebx.schema.base import PositiveFloat, Strict


class JointSineTask(Strict):
    """Each joint follows offset + amplitude * sin(2 pi t / period + phase)."""

    kind: Literal["joint_sine"] = "joint_sine"
    period_s: PositiveFloat = 2.0
    offset_rad: tuple[float, ...] = (0.0, 0.0)
    amplitude_rad: tuple[float, ...] = (0.5, 0.5)
    phase_rad: tuple[float, ...] = (0.0, 1.5707963267948966)

    @model_validator(mode="after")
    def _same_length(self) -> JointSineTask:
        n = {len(self.offset_rad), len(self.amplitude_rad), len(self.phase_rad)}
        if len(n) != 1:
            raise ValueError("offset_rad, amplitude_rad and phase_rad need one value per joint each")
        return self

    @property
    def n_joints(self) -> int:
        return len(self.offset_rad)


class _CartesianTask(Strict):
    """Common fields of the Cartesian Baxter tasks (docs/models.md#cartesian-tasks)."""

    period_s: PositiveFloat = Field(2.0, description="one trial")
    radius_m: PositiveFloat = Field(0.12, description="circle radius / eight half-height")
    home_q_rad: tuple[float, ...] = Field(
        (-0.75, -0.35, 0.0, 1.35, 0.0, 0.57), description="home pose s0..w1; its end-effector is the centre"
    )
    n_joints: int = 6


class CircleTask(_CartesianTask):
    """Horizontal circle, Eq. 2.19 / 3.7: x = R cos(2 pi t/T + pi), y = R sin(2 pi t/T + pi)."""

    kind: Literal["circle"] = "circle"


class EightTask(_CartesianTask):
    """Horizontal eight, Eq. 2.20 / 3.9: x = (R/2) sin(4 pi t/T), y = R cos(2 pi t/T)."""

    kind: Literal["eight"] = "eight"


class InclinedCircleTask(_CartesianTask):
    """Circle tilted about the y axis, Eq. 3.8."""

    kind: Literal["inclined_circle"] = "inclined_circle"
    tilt_deg: float = 30.0


class CircleEightTask(_CartesianTask):
    """One circle then one eight, 4 s in all."""

    kind: Literal["circle_eight"] = "circle_eight"
    period_s: PositiveFloat = 4.0


class ReachingTask(_CartesianTask):
    """Eight targets on the circle every pi/4; out and back; random order. Each leg follows
    ``profile``: ``min_jerk`` (bell-shaped velocity) or ``ramp_linear`` (the original's "smooth ramp
    then linear segment", docs/provenance.md#original-trajectories: velocity rises over ``ramp_fraction``
    of the leg, then is constant)."""

    kind: Literal["reaching"] = "reaching"
    targets: int = Field(8, gt=0)
    out_s: PositiveFloat = 1.0
    space: Literal["cartesian", "joint"] = Field(
        "cartesian", description="'cartesian': straight hand legs; 'joint': joints interpolated from the "
        "home pose to each target's IK solution (the original's target-reaching files)")
    profile: Literal["min_jerk", "ramp_linear"] = "min_jerk"
    ramp_fraction: float = Field(
        0.4, gt=0.0, le=1.0,
        description="ramp_linear: fraction of each leg over which the velocity rises (constructed: "
        "with space joint, 0.4 gives the original's peak e1 speed, 0.94 rad/s)",
    )

    @model_validator(mode="after")
    def _fits(self) -> ReachingTask:
        if self.out_s >= self.period_s:
            raise ValueError(f"out_s ({self.out_s}) must be shorter than period_s ({self.period_s})")
        return self
