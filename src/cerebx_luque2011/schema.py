"""Schemas of the plant, task and feed-forward part of Luque et al. 2011: three joints of a lightweight
arm, the eight-shaped joint trajectory, and the crude inverse dynamics model (the arm without the object).

Numbers from the paper (IEEE TSMC-B 2011) are marked *paper*; numbers it does not give are *constructed*
(chosen here; docs/models.md#luque-eight, docs/provenance.md#lwr-differences)."""

from __future__ import annotations

from typing import ClassVar, Literal

from pydantic import Field

from cerebx.api.schema import (
    ControllerConfig,
    NonNegFloat,
    PhysicsStepMs,
    PlantSchema,
    PositiveFloat,
    Signal,
    StageIO,
    Strict,
)


class LWR3Config(PlantSchema):
    """Three joints (A1, A2, A4) of a KUKA LWR 4+ as a stand-in for the DLR LWR-III of Luque et al. 2011;
    link masses, lengths and inertias from a published URDF (docs/provenance.md#lightweight-arm), the other
    joints fixed at 0. An object can hang at the end of the last segment (``object_mass_kg`` from the start,
    or the ``attach_payload`` event)."""

    kind: Literal["lwr3"] = "lwr3"
    physics_dt_ms: PhysicsStepMs = 0.5
    torque_limit_Nm: tuple[PositiveFloat, PositiveFloat, PositiveFloat] = Field(
        (176.0, 176.0, 100.0),
        description="actuator saturation of A1, A2, A4 (LWR 4+ limits, docs/provenance.md#lwr-kinematics)",
    )
    damping_Nms_per_rad: NonNegFloat = Field(1.0, description="viscous joint damping (the Gazebo URDF's 1.0)")
    stiffness_Nm_per_rad: tuple[NonNegFloat, NonNegFloat, NonNegFloat] = Field(
        (0.0, 0.0, 0.0), description="passive joint springs toward spring_ref_rad (a non-stiff, elastic arm)"
    )
    spring_ref_rad: tuple[float, float, float] = Field((0.0, 0.0, 0.0), description="where the springs are slack")
    object_mass_kg: NonNegFloat = Field(
        0.0, description="mass held at the end of the last segment from the start (paper: 0.5, 1, 1.5 or 2 kg)"
    )
    sensor_noise_rad: NonNegFloat = Field(0.0, description="std of Gaussian noise on measured joint positions")

    @property
    def n_joints(self) -> int:
        return 3


class LuqueEightTask(Strict):
    """Luque et al. 2011 Eq. 1, three joints: q1 = A1 sin(w t) + C1, q2 = A2 sin(w t + theta) + C2,
    q3 = A2 sin(w t + 2 theta) + C3, one trial = one period. The paper gives no constants and writes
    sin(pi t) for a 1 s trial, which does not close; here w = 2 pi / period_s, and the constants are
    constructed so that the LWR hand traces an eight (seen from above, one self-crossing) as in its Fig. 2.
    Also gives the desired acceleration ``ref.qdd`` (for the crude inverse dynamics)."""

    extra_reference: ClassVar[dict[str, str]] = {"qdd": "rad/s^2"}

    kind: Literal["luque_eight"] = "luque_eight"
    period_s: PositiveFloat = Field(1.0, description="one trial (paper: 1 s)")
    amplitude1_rad: float = Field(0.5, description="A1 (constructed)")
    amplitude2_rad: float = Field(0.5, description="A2, shared by q2 and q3 (constructed)")
    theta_rad: float = Field(2.356194490192345, description="theta, phase step between joints (constructed: 3 pi/4)")
    offset_rad: tuple[float, float, float] = Field((0.0, 0.6, 0.6), description="C1, C2, C3 (constructed)")

    @property
    def n_joints(self) -> int:
        return 3


class CrudeInverseDynamics(ControllerConfig):
    """Feed-forward torque from the arm's model *without* the object (MuJoCo inverse dynamics on a
    model copy) for the desired q, qd, qdd; needs a plant that offers ``nominal_model()`` and a task
    that gives ``ref.qdd``."""

    kind: Literal["crude_inverse_dynamics"] = "crude_inverse_dynamics"

    def io(self, n_joints: int) -> StageIO:
        return StageIO(("ref.q", "ref.qd", "ref.qdd"), (Signal("joint.torque", n_joints, "N·m"),))
