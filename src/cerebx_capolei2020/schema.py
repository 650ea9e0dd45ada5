"""Schemas of the plant and task of Capolei et al. (2020): the iCub wrist holding a table with a ball,
and the wrist oscillation."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from cerebx.api.schema import NonNegFloat, PhysicsStepMs, PlantSchema, PositiveFloat, Strict


class ICubWristConfig(PlantSchema):
    """iCub right wrist (prosup, yaw, pitch) holding a table with a free ball (Capolei 2020); MJCF in
    ``icub_wrist.xml`` beside this file. Efforts and damping from the NRP iCub model; armature constructed."""

    kind: Literal["icub_wrist"] = "icub_wrist"
    physics_dt_ms: PhysicsStepMs = 0.5
    torque_limit_Nm: tuple[PositiveFloat, PositiveFloat, PositiveFloat] = Field(
        (0.45, 0.65, 0.65), description="effort limits prosup, yaw, pitch (NRP iCub model)")
    damping_Nms_per_rad: NonNegFloat = Field(1.0, description="joint damping (NRP iCub model)")
    armature_kgm2: NonNegFloat = Field(0.03, description="reflected rotor inertia per joint (constructed)")
    sample_rate_hz: PositiveFloat = Field(50.0, le=500.0, description="encoder sampling rate; readings are "
                                          "held between samples (the paper's f_samp)")
    sensor_noise: NonNegFloat = Field(0.0, description="a: U(-a, a) added to each sampled position (rad) and "
                                      "velocity (rad/s); the paper's case B uses 0.1")
    ball: bool = Field(True, description="a free ball rolls on the table")
    ball_drop_height_m: NonNegFloat = Field(0.1, description="the ball starts at rest this high above the "
                                            "table centre at reset")
    ball_drop_jitter_m: NonNegFloat = Field(0.03, description="the drop point is drawn from U(-j, j) in x and y "
                                            "about the table centre (constructed: makes seeds differ)")
    ball_reset: bool = Field(True, description="drop the ball again when it falls off the table")
    ball_lost_below_m: PositiveFloat = Field(0.1, description="the ball counts as fallen this far below the table")

    @property
    def n_joints(self) -> int:
        return 3


class WristOscillationTask(Strict):
    """Capolei et al. 2020 Eq. 1-2: q_r = A sin(2 pi f t + phi), qdot_r = 2 pi f A cos(2 pi f t + phi);
    one trial is one period 1/f."""

    kind: Literal["wrist_oscillation"] = "wrist_oscillation"
    frequency_hz: PositiveFloat = Field(0.25, description="f")
    amplitude_rad: tuple[float, ...] = Field((0.1727, 0.1363, 0.0345), description="A per joint (prosup, yaw, pitch)")
    phase_rad: tuple[float, ...] = Field((1.5707963267948966, 1.5707963267948966, 0.0), description="phi per joint")

    @model_validator(mode="after")
    def _same_length(self) -> WristOscillationTask:
        if len(self.amplitude_rad) != len(self.phase_rad):
            raise ValueError("amplitude_rad and phase_rad need one value per joint each")
        return self

    @property
    def period_s(self) -> float:
        return 1.0 / self.frequency_hz

    @property
    def n_joints(self) -> int:
        return len(self.amplitude_rad)
