"""Named signals: what a plant senses and is commanded with, what a stage reads and writes.

A :class:`Signal` declares one named array (shape, unit, bounds), like a dm_env spec. A
:class:`Message` carries named arrays with the time stamp they were made for; it is what crosses the
link between the brain side and the robot side. A :class:`Frame` is one side's working set during
one tick: the signals that arrived, the plant's readings and what earlier stages wrote.

Names are dotted nouns: ``joint.q`` (rad), ``joint.qd`` (rad/s), ``joint.torque`` (N·m),
``muscle.activation`` (0-1), ``muscle.length`` (mm), ``ref.q``/``ref.qd`` (the task's desired state).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Signal:
    """One named array: ``size`` values in ``unit``, each within [low, high].

    Parameters
    ----------
    name : str
        A dotted noun (``joint.q``, ``muscle.activation``).
    size : int
        Values.
    unit : str
        Their unit (``rad``, ``N·m``).
    low, high : float or tuple of float
        Bounds, one for all values or one per value.
    """

    name: str
    size: int
    unit: str = ""
    low: float | tuple[float, ...] = -math.inf
    high: float | tuple[float, ...] = math.inf

    def __str__(self) -> str:
        return f"{self.name}[{self.size}]"

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        lo = np.broadcast_to(np.asarray(self.low, float), (self.size,))
        hi = np.broadcast_to(np.asarray(self.high, float), (self.size,))
        return lo, hi


def joint_signals(n: int, tau_max: np.ndarray | None = None) -> dict[str, Signal]:
    """The joint-space signals of an ``n``-joint torque-controlled plant: ``joint.q``, ``joint.qd``,
    ``joint.torque``.

    Parameters
    ----------
    n : int
        Joints.
    tau_max : array (n,), optional
        Torque limits, N·m (the torque's bounds; unbounded when None).
    """
    hi = math.inf if tau_max is None else tuple(float(t) for t in tau_max)
    lo = -math.inf if tau_max is None else tuple(-float(t) for t in tau_max)
    return {"joint.q": Signal("joint.q", n, "rad"), "joint.qd": Signal("joint.qd", n, "rad/s"),
            "joint.torque": Signal("joint.torque", n, "N·m", lo, hi)}


@dataclass(frozen=True)
class StageIO:
    """What a stage reads, writes, and adds to (a written signal that is summed with the present value).

    Parameters
    ----------
    reads : tuple of str
        The signals it needs, by name.
    writes : tuple of Signal
        The signals it produces.
    adds : frozenset of str
        Those of ``writes`` added to the present value instead of replacing it.
    """

    reads: tuple[str, ...] = ()
    writes: tuple[Signal, ...] = ()
    adds: frozenset[str] = frozenset()


def torque_controller_io(n_joints: int) -> StageIO:
    """A joint-torque controller: desired joint state in, ``joint.torque`` out (the measured joint state
    it also uses arrives through the link and may be absent in the first ticks)."""
    return StageIO(("ref.q", "ref.qd"), (Signal("joint.torque", n_joints, "N·m"),))


class Message:
    """Named arrays stamped with the time they are meant for (sensor: measured at; command: apply at)."""

    __slots__ = ("stamp_s", "values")

    def __init__(self, stamp_s: float, values: dict[str, np.ndarray]):
        self.stamp_s = stamp_s
        self.values = values

    def __getitem__(self, name: str) -> np.ndarray:
        return self.values[name]

    def __repr__(self) -> str:
        return f"Message({self.stamp_s:.4f} s, {sorted(self.values)})"


class Frame:
    """One side's signals during one tick. Stages read ``signals`` and write their outputs into it.

    On the brain side ``sensed`` is the newest sensor message that has arrived through the link
    (None before the first) and its values are also in ``signals``; ``stamp_s`` is the time the
    outgoing command is meant for (the tick's own time unless a stage stamps it later).

    Parameters
    ----------
    tick : int
        The tick's index.
    t_s : float
        Its time, s.
    signals : dict of str to numpy.ndarray
        The signals so far, by name (``joint.q``, ``ref.q``, ...).
    sensed : Message, optional
        The newest sensor message that has arrived (brain side).
    """

    __slots__ = ("tick", "t_s", "stamp_s", "signals", "sensed")

    def __init__(self, tick: int, t_s: float, signals: dict[str, np.ndarray], sensed: Message | None = None):
        self.tick, self.t_s, self.stamp_s = tick, t_s, t_s
        self.signals = signals
        self.sensed = sensed


class Deferred(Mapping[str, float]):
    """What a stage's or controller's ``end_trial`` returns when its values are ready only a little later (a
    spiking network still simulating the steps it ran ahead of the loop: its statistics wait for them, the loop
    need not).

    It is a mapping like the dict it stands for. Reading it before it is :attr:`ready` calls ``settle``, which
    must make it ready (e.g. collect what the network is computing); the closed loop instead writes the
    trial's ``/weights`` once it is ready, with the time stamp of the trial's end."""

    __slots__ = ("_values", "_settle")

    def __init__(self, settle: Callable[[], None]):
        self._values: dict[str, float] | None = None
        self._settle: Callable[[], None] | None = settle

    def set(self, values: dict[str, float]) -> None:
        self._values, self._settle = values, None

    @property
    def ready(self) -> bool:
        return self._values is not None

    def _get(self) -> dict[str, float]:
        if self._values is None and self._settle is not None:
            self._settle()
        if self._values is None:
            raise RuntimeError("a trial's end-of-trial values were never set")
        return self._values

    def __getitem__(self, key: str) -> float:
        return self._get()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._get())

    def __len__(self) -> int:
        return len(self._get())
