"""Task schemas of the upper limb: a flexion-extension and a circle in the
vertical plane, both with bell-shaped (minimum-jerk) velocity profiles. Every number here is
constructed (chosen to lie well inside the arm's joint range)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from cerebx.schema.base import PositiveFloat, Strict


class FlexionExtensionTask(Strict):
    """Both joints flex from ``start_rad`` to ``end_rad`` in the first half of the trial and extend back in the
    second, each half a minimum-jerk movement (bell-shaped velocity, at rest at both ends). Constructed."""

    kind: Literal["flexion_extension"] = "flexion_extension"
    period_s: PositiveFloat = Field(3.0, description="one trial: out and back")
    start_rad: tuple[float, float] = Field((0.1, 0.3), description="shoulder, elbow at the start (constructed)")
    end_rad: tuple[float, float] = Field((0.8, 1.5), description="shoulder, elbow at full flexion (constructed)")
    n_joints: int = 2


class VerticalCircleTask(Strict):
    """The hand goes once round a circle in the arm's (vertical) plane, the angle along the circle following a
    minimum-jerk profile from 0 to 2 pi (bell-shaped speed, at rest at the start point); joint paths by inverse
    kinematics of the upper limb's planar geometry (elbow flexed). Constructed centre, radius and start."""

    kind: Literal["vertical_circle"] = "vertical_circle"
    period_s: PositiveFloat = Field(3.0, description="one revolution")
    centre_m: tuple[float, float] = Field(
        (0.22, -0.28), description="circle centre from the shoulder: forward, up (m; constructed)")
    radius_m: PositiveFloat = Field(0.07, description="constructed")
    start_angle_rad: float = Field(-1.5707963267948966, description="where on the circle it starts (0 = forward)")
    n_joints: int = 2
