"""Plant events: each event kind is a registered schema whose builder binds it to a plant.

The builder checks, when the run is built, that the plant offers the method the event needs
(``attach_payload``, ``force_pulse``, ...), and returns a function that fires the event. A plant
supports an event by having that method; a plugin adds an event kind by registering a schema and a
builder the same way.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from cerebx.errors import CerebxError


def _method(plant: Any, name: str) -> Callable[..., None]:
    fn = getattr(plant, name, None)
    if not callable(fn):
        raise CerebxError(f"events: plant {type(plant).__name__} does not support event {name!r}")
    return fn


def attach_payload(cfg: Any, plant: Any) -> Callable[[], None]:
    fn = _method(plant, cfg.plant_method)
    return lambda: fn(cfg.mass_kg, cfg.rod_length_m)


def detach_payload(cfg: Any, plant: Any) -> Callable[[], None]:
    return _method(plant, cfg.plant_method)


def elastic_band(cfg: Any, plant: Any) -> Callable[[], None]:
    fn = _method(plant, cfg.plant_method)
    return lambda: fn(cfg.stiffness_N_per_m, np.asarray(cfg.anchor_offset_m, float), cfg.rest_length_m)


def remove_band(cfg: Any, plant: Any) -> Callable[[], None]:
    return _method(plant, cfg.plant_method)


def force_pulse(cfg: Any, plant: Any) -> Callable[[], None]:
    fn = _method(plant, cfg.plant_method)
    return lambda: fn(np.asarray(cfg.force_N, float), cfg.duration_ms, cfg.body)


def finger_push(cfg: Any, plant: Any) -> Callable[[], None]:
    fn = _method(plant, cfg.plant_method)
    return lambda: fn(np.asarray(cfg.force_N, float), cfg.duration_ms)


def grab(cfg: Any, plant: Any) -> Callable[[], None]:
    fn = _method(plant, cfg.plant_method)
    return lambda: fn(cfg.stiffness_N_per_m, np.asarray(cfg.displacement_m, float), cfg.drag_ms, cfg.hold_ms)
