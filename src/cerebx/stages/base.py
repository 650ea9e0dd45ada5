"""The stage contract and the build-time check that neighbouring stages agree on signals."""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from cerebx.signals import Frame, Message, Signal

if TYPE_CHECKING:
    from cerebx.recording.recorder import Recorder

Side = Literal["brain", "robot"]


class Stage(ABC):
    """Maps the signals of one tick to more (or changed) signals, and may keep state.

    ``reads`` names the signals it needs; ``writes`` declares what it produces. A signal it writes
    that is already present is replaced, unless the stage declares it in ``adds`` (then its output
    is added to the present value: combined controllers, the supervisor's correction).
    """

    name: str = "stage"
    reads: tuple[str, ...] = ()
    writes: tuple[Signal, ...] = ()
    adds: frozenset[str] = frozenset()

    def reset(self, rng: np.random.Generator) -> None:
        """Prepare for a run (called once, before the first tick)."""

    @abstractmethod
    def step(self, frame: Frame) -> None:
        """Read from ``frame.signals`` and write this stage's outputs into it."""

    def emit(self, frame: Frame, name: str, value: np.ndarray) -> None:
        """Write ``value`` as signal ``name`` (added to the present value when declared in ``adds``)."""
        signals = frame.signals
        if name in self.adds and name in signals:
            signals[name] = signals[name] + value
        else:
            signals[name] = value

    def record(self) -> dict[str, Any]:
        """Extra fields for this tick's ``/control`` message (e.g. the supervisor's torque)."""
        return {}

    def end_trial(self, trial: int) -> Mapping[str, float]:
        """Called after each trial; may return scalars to record (e.g. weight summaries), or a
        :class:`~cerebx.signals.Deferred` that has them a little later."""
        return {}

    def attach_recorder(self, recorder: Recorder) -> None:
        """Register extra MCAP channels (spikes, weights) before the run starts."""

    def save_state(self, path: Path) -> bool:
        """Write the learned state to ``path``; return False when there is none."""
        return False

    def load_state(self, path: Path) -> None:
        """Restore a state written by :meth:`save_state` (clear error on mismatch)."""

    def describe(self) -> dict[str, Any]:
        """Static facts for the run summary (sizes, gains)."""
        return {}


class Receiver(ABC):
    """First robot-side stage: turns the command messages that arrived this tick (zero or more)
    into the command values to apply now. A receiver with ``safe_stop`` decays its previous output by
    itself when too few commands arrived, and says so in ``starved`` after each tick."""

    name: str = "receiver"
    safe_stop: bool = False
    starved: bool = False

    def __init__(self, signals: tuple[Signal, ...]):
        self.signals = signals

    @abstractmethod
    def receive(self, arrived: list[Message], t_s: float) -> dict[str, np.ndarray]:
        """The command values for this tick."""

    def reset(self, rng: np.random.Generator) -> None:
        """Prepare for a run."""
