"""Plant-event schemas (each registered with a builder in ``plants/events.py``). ``plant_method`` names
the plant method an event needs; a plant supports the event by having it (checked at validation)."""

from __future__ import annotations

from typing import ClassVar, Literal

from cerebx.schema.base import NonNegFloat, PositiveFloat, Strict


class AttachPayload(Strict):
    """Attach a mass at the end-effector; with ``rod_length_m`` it hangs from a rod (conical pendulum)."""

    plant_method: ClassVar[str] = "attach_payload"  # what a plant offers to support it
    kind: Literal["attach_payload"] = "attach_payload"
    mass_kg: PositiveFloat
    rod_length_m: NonNegFloat = 0.0


class DetachPayload(Strict):
    plant_method: ClassVar[str] = "detach_payload"  # what a plant offers to support it
    kind: Literal["detach_payload"] = "detach_payload"


class ElasticBand(Strict):
    """A spring from the end-effector to a world anchor (offset from the start position)."""

    plant_method: ClassVar[str] = "elastic_band"  # what a plant offers to support it
    kind: Literal["elastic_band"] = "elastic_band"
    stiffness_N_per_m: PositiveFloat
    anchor_offset_m: tuple[float, float, float] = (0.0, 0.0, -0.3)
    rest_length_m: NonNegFloat = 0.0


class RemoveBand(Strict):
    plant_method: ClassVar[str] = "remove_band"  # what a plant offers to support it
    kind: Literal["remove_band"] = "remove_band"


class ForcePulse(Strict):
    """A force on a body for a while (e.g. 20 N for 50 ms)."""

    plant_method: ClassVar[str] = "force_pulse"  # what a plant offers to support it
    kind: Literal["force_pulse"] = "force_pulse"
    force_N: tuple[float, float, float]
    duration_ms: PositiveFloat = 50.0
    body: str = "end_effector"


class FingerPush(Strict):
    """A person pushes the end-effector with one finger: a half-sine force
    of peak ``force_N`` over ``duration_ms``."""

    plant_method: ClassVar[str] = "finger_push"  # what a plant offers to support it
    kind: Literal["finger_push"] = "finger_push"
    force_N: tuple[float, float, float] = (0.0, 4.0, 0.0)
    duration_ms: PositiveFloat = 500.0


class Grab(Strict):
    """A person grabs the end-effector through a soft spring and drags it along ``displacement_m``
    (minimum jerk over ``drag_ms``), holds for ``hold_ms``, then lets go."""

    plant_method: ClassVar[str] = "grab"  # what a plant offers to support it
    kind: Literal["grab"] = "grab"
    stiffness_N_per_m: PositiveFloat = 50.0
    displacement_m: tuple[float, float, float] = (0.0, 0.0, 0.15)
    drag_ms: PositiveFloat = 1000.0
    hold_ms: NonNegFloat = 1000.0
