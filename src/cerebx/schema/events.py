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
