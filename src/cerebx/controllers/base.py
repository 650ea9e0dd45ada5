"""The joint-torque controller contract and its small per-step records.

A :class:`Controller` maps the desired joint state and the newest delayed joint measurement to a
joint torque stamped with its application time. The loop runs it as a brain-side stage
(``stages/controllers.py``); controllers with other inputs or outputs are stages themselves.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from cerebx.recording.recorder import Recorder


@dataclass(frozen=True)
class SensorMsg:
    """Robot-to-controller message: joint state measured at ``stamp_s``."""

    stamp_s: float
    q: np.ndarray
    qd: np.ndarray


@dataclass(frozen=True)
class TorqueMsg:
    """Controller-to-robot message: torque meant to be applied at ``stamp_s``."""

    stamp_s: float
    tau: np.ndarray


@dataclass(frozen=True)
class CommandMsg:
    """Controller-to-robot message of named signals other than the joint torque (e.g. the muscle
    commands ``muscle.ag``/``muscle.at``), meant to be applied at ``stamp_s``."""

    stamp_s: float
    values: dict[str, np.ndarray]


@dataclass(frozen=True)
class ControlInput:
    """What a controller sees at one control step.

    ``t_s`` is the controller's current time; ``q_des``/``qd_des`` the desired state at ``t_s``;
    ``sensor`` the newest sensor message that has arrived through the R2C link (None before
    the first one arrives). A controller that pairs a delayed measurement with the desired sample
    of the measurement's own stamp keeps the recent desired samples itself (as the SNN and ANN do).
    """

    tick: int
    t_s: float
    q_des: np.ndarray
    qd_des: np.ndarray
    sensor: SensorMsg | None


class Controller(ABC):
    """Produces torque commands. Stateful controllers also save and load their learned state."""

    n_joints: int

    @abstractmethod
    def reset(self, rng: np.random.Generator) -> None:
        """Prepare for a run (called once, before the first step)."""

    @abstractmethod
    def step(self, inp: ControlInput) -> TorqueMsg | CommandMsg:
        """One 2 ms control step: a joint torque, or the named signals the controller's schema declares."""

    def end_trial(self, trial: int) -> Mapping[str, float]:
        """Called after each trial; may return scalars to record (e.g. weight summaries), or a
        :class:`~cerebx.signals.Deferred` that has them a little later."""
        return {}

    def attach_recorder(self, recorder: Recorder) -> None:
        """Register extra MCAP channels (spikes, weights) before the run starts."""

    def save_state(self, path: Path) -> None:
        """Write the learned state; stateless controllers write nothing."""

    def load_state(self, path: Path) -> None:
        """Restore a state written by :meth:`save_state` (clear error on mismatch)."""

    def describe(self) -> dict[str, Any]:
        """Static facts for the run summary (sizes, gains)."""
        return {}
