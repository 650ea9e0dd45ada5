"""Plant schemas."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from cerebx.schema.base import NonNegFloat, PhysicsStepMs, PlantSchema, PositiveFloat, Strict
from cerebx.signals import Signal


class Planar2Config(PlantSchema):
    """Planar two-link arm in a vertical plane (shoulder, elbow), torque-driven; for fast tests."""

    kind: Literal["planar2"] = "planar2"
    physics_dt_ms: PhysicsStepMs = 0.5
    link_length_m: tuple[PositiveFloat, PositiveFloat] = (0.3, 0.3)
    link_mass_kg: tuple[PositiveFloat, PositiveFloat] = (1.5, 1.0)
    damping_Nms_per_rad: NonNegFloat = 0.1
    armature_kgm2: NonNegFloat = 0.01
    torque_limit_Nm: tuple[PositiveFloat, PositiveFloat] = (30.0, 20.0)
    gravity: bool = Field(True, description="gravity acts in the arm's plane")
    sensor_noise_rad: NonNegFloat = 0.0

    @property
    def n_joints(self) -> int:
        return 2


class SEAConfig(Strict):
    """Series elastic actuators (Spong flexible-joint model): each actuator drives a rotor joint with
    inertia ``rotor_inertia_kgm2`` that is coupled to its link joint by a torsional spring-damper.
    No published Baxter SEA stiffness exists (docs/provenance.md#baxter-springs); the defaults are assumptions."""

    enabled: bool = True
    stiffness_Nm_per_rad: tuple[PositiveFloat, ...] = Field(
        (1500.0, 1500.0, 1000.0, 1000.0, 400.0, 400.0), description="spring stiffness per joint"
    )
    damping_Nms_per_rad: tuple[NonNegFloat, ...] = Field(
        (5.0, 5.0, 3.0, 3.0, 1.0, 1.0), description="damping across the spring per joint"
    )
    rotor_inertia_kgm2: tuple[PositiveFloat, ...] = Field(
        (0.05, 0.05, 0.02, 0.02, 0.005, 0.005), description="reflected motor rotor inertia per joint"
    )

    @model_validator(mode="after")
    def _six(self) -> SEAConfig:
        for name in ("stiffness_Nm_per_rad", "damping_Nms_per_rad", "rotor_inertia_kgm2"):
            if len(getattr(self, name)) != 6:
                raise ValueError(f"sea.{name} needs 6 values (s0, s1, e0, e1, w0, w1)")
        return self


class S1SpringConfig(Strict):
    """Passive gravity-opposing spring assist on s1 (nonlinear; parameters are assumptions).

    Torque on s1: tau = -(k1 z + k2 z^2 + k3 z^3) with z = q_s1 - rest_rad (a MuJoCo polynomial joint
    spring). The defaults carry about half of the gravity torque of the stretched-out arm
    (about 26 N·m near s1 = 0) and stay gravity-opposing (tau <= 0) over the whole s1 range.
    """

    enabled: bool = True
    stiffness_Nm_per_rad: NonNegFloat = Field(0.0, description="linear coefficient k1")
    quadratic_Nm_per_rad2: float = Field(15.5, description="quadratic coefficient k2")
    cubic_Nm_per_rad3: float = Field(-4.5, description="cubic coefficient k3")
    rest_rad: float = Field(-2.147, description="s1 angle where the spring is slack (the upper stop)")


class BaxterConfig(PlantSchema):
    """Compliant Baxter left arm (six controlled joints, w2 held at 0)."""

    kind: Literal["baxter"] = "baxter"
    physics_dt_ms: PhysicsStepMs = 0.5
    integrator: Literal["euler", "implicitfast", "rk4"] = Field(
        "euler", description="MuJoCo integrator (Euler treats joint damping implicitly)"
    )
    gravity_compensation: bool = Field(
        False,
        description="off for torque control, as in the original; on = MuJoCo body gravcomp on every arm link",
    )
    torque_limit_Nm: tuple[PositiveFloat, ...] = Field(
        (50.0, 100.0, 50.0, 50.0, 15.0, 15.0),
        description="actuator saturation per joint (s1: 50 xacro, 100 flat URDF)",
    )
    damping_Nms_per_rad: tuple[NonNegFloat, ...] = Field(
        (0.7, 0.7, 0.7, 0.7, 0.7, 0.7), description="joint damping"
    )
    frictionloss_Nm: tuple[NonNegFloat, ...] = Field(
        (0.0, 0.0, 0.0, 0.0, 0.0, 0.0), description="dry friction"
    )
    armature_kgm2: tuple[NonNegFloat, ...] = Field(
        (0.0, 0.0, 0.0, 0.0, 0.01, 0.01),
        description="link-joint armature (stabilises the tiny wrist inertias)",
    )
    sea: SEAConfig = SEAConfig(enabled=False)
    s1_spring: S1SpringConfig = S1SpringConfig(enabled=False)
    sensor_noise_rad: NonNegFloat = Field(
        0.0, description="std of Gaussian noise on measured joint positions"
    )
    sensor_noise_rad_per_s: NonNegFloat = Field(
        0.0, description="std of Gaussian noise on measured joint velocities"
    )
    gripper_mass_kg: NonNegFloat = Field(
        0.0, description="lumped mass at the gripper base (hand z + 0.025 m)"
    )
    torque_lag_ms: NonNegFloat = Field(
        0.0, description="time constant of a first-order lag between the commanded and the produced joint "
        "torque (motor current loop); 0 = none"
    )

    @model_validator(mode="after")
    def _six(self) -> BaxterConfig:
        for name in ("torque_limit_Nm", "damping_Nms_per_rad", "frictionloss_Nm", "armature_kgm2"):
            if len(getattr(self, name)) != 6:
                raise ValueError(f"{name} needs 6 values (s0, s1, e0, e1, w0, w1)")
        return self

    @property
    def n_joints(self) -> int:
        return 6


MUSCLES_UPPER_LIMB = ("deltoid", "biceps_long", "biceps_short", "brachialis", "triceps_long", "triceps_lateral",
                      "triceps_medial")
"""The upper limb's muscles in command/sensor order."""


class UpperLimbConfig(PlantSchema):
    """Human arm, shoulder and elbow flexion-extension in a vertical plane, 7 Hill-type muscles on
    spatial tendons (OpenSim Arm26, Holzbaur et al. 2005, + MoBL-ARMS anterior deltoid).
    Commanded with the muscles' neural excitations; MuJoCo integrates the activation dynamics
    (docs/models.md#activation-dynamics)."""

    kind: Literal["upper_limb"] = "upper_limb"
    physics_dt_ms: PhysicsStepMs = 0.5
    joint_damping_Nms_per_rad: NonNegFloat = Field(
        0.5, description="viscous joint damping (constructed: Arm26 has none, the MyoConverter conversion 0.05; "
        "0.5 damps the 30 ms-delayed stretch-reflex loop)")
    activation_time_constants_s: tuple[PositiveFloat, PositiveFloat] = Field(
        (0.01, 0.04), description="t_act, t_deact of the activation dynamics (Eq. 4.5; Arm26's Thelen values)")
    gravity: bool = Field(True, description="gravity acts in the arm's plane")

    @property
    def n_joints(self) -> int:
        return 2

    def sensor_signals(self) -> dict:
        n = len(MUSCLES_UPPER_LIMB)
        return {**super().sensor_signals(), "muscle.length": Signal("muscle.length", n, "mm"),
                "muscle.velocity": Signal("muscle.velocity", n, "mm/s")}

    def command_signals(self) -> dict:
        return {"muscle.activation": Signal("muscle.activation", len(MUSCLES_UPPER_LIMB), "", 0.0, 1.0)}
