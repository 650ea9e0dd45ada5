"""The joint-torque controller: a :class:`~cerebx.stages.base.Stage` with one input shape, and its small
per-step records.

A :class:`Controller` maps the desired joint state and the newest delayed joint measurement to a joint
torque stamped with its application time (or to the named command signals its schema declares). It is a
brain-side stage like any other (one ``save_state`` signature, one contract checker); its :meth:`step`
hands the tick to :meth:`Controller.control` as a :class:`ControlInput`. Controllers with other inputs or
outputs subclass :class:`~cerebx.stages.base.Stage` directly.
"""

from __future__ import annotations

from abc import abstractmethod
from dataclasses import dataclass
from typing import Any

import numpy as np

from cerebx.signals import Frame
from cerebx.stages.base import Stage


@dataclass(frozen=True)
class SensorMsg:
    """Robot-to-controller message: joint state measured at ``stamp_s``."""

    stamp_s: float
    q: np.ndarray
    qd: np.ndarray


@dataclass(frozen=True)
class TorqueMsg:
    """Controller-to-robot message: torque meant to be applied at ``stamp_s``.

    Parameters
    ----------
    stamp_s : float
        When the torque is meant to be applied, s.
    tau : numpy.ndarray (n_joints,)
        Joint torques, N·m.
    """

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

    A controller that pairs a delayed measurement with the desired sample of the measurement's own stamp
    keeps the recent desired samples itself (as the SNN and ANN do).

    Parameters
    ----------
    tick : int
        The control step's index.
    t_s : float
        The controller's current time, s.
    q_des, qd_des : numpy.ndarray (n_joints,)
        The desired state at ``t_s`` (rad, rad/s).
    sensor : SensorMsg or None
        The newest sensor message that has arrived through the R2C link (None before the first one).
    """

    tick: int
    t_s: float
    q_des: np.ndarray
    qd_des: np.ndarray
    sensor: SensorMsg | None


class Controller(Stage):
    """A brain-side stage that computes joint torques from the desired joint state and the newest sensor
    message; subclasses implement :meth:`reset` and :meth:`control`.

    It reads ``ref.q`` and ``ref.qd`` and writes ``joint.torque`` (or what its schema's ``io`` declares: the
    build sets ``name``, ``reads`` and ``writes`` from the schema). Stateful controllers also implement
    :meth:`~cerebx.stages.base.Stage.save_state` (returning True once written) and
    :meth:`~cerebx.stages.base.Stage.load_state`.

    Attributes
    ----------
    n_joints : int
        Joints the controller commands.
    """

    n_joints: int
    _sensed: Any = None  # the sensor message last converted to a SensorMsg, and that SensorMsg
    _sensor: SensorMsg | None = None

    @abstractmethod
    def reset(self, rng: np.random.Generator) -> None:
        """Prepare for a run (called once, before the first step)."""

    @abstractmethod
    def control(self, inp: ControlInput) -> TorqueMsg | CommandMsg:
        """One control step.

        Parameters
        ----------
        inp : ControlInput
            The tick, its time, the desired joint state and the newest sensor message that has arrived.

        Returns
        -------
        TorqueMsg or CommandMsg
            A joint torque, or the named signals the controller's schema declares, stamped with the time
            they are meant to be applied at.
        """

    def step(self, frame: Frame) -> None:
        """The tick as a :class:`ControlInput` to :meth:`control`, its output written into ``frame``."""
        sensed = frame.sensed
        if sensed is not self._sensed:  # a new sensor message arrived: convert it once
            self._sensed = sensed
            self._sensor = None if sensed is None else SensorMsg(sensed.stamp_s, sensed["joint.q"], sensed["joint.qd"])
        sig = frame.signals
        cmd = self.control(ControlInput(frame.tick, frame.t_s, sig["ref.q"], sig["ref.qd"], self._sensor))
        frame.stamp_s = cmd.stamp_s
        if isinstance(cmd, CommandMsg):
            for name, value in cmd.values.items():
                self.emit(frame, name, value)
        else:
            self.emit(frame, "joint.torque", cmd.tau)
