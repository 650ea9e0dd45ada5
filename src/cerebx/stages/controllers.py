"""Controllers as brain-side stages.

A joint-torque :class:`~cerebx.controllers.base.Controller` (PD, position servo, SNN, ANN) runs
behind :class:`TorqueControllerStage`: it reads the task's desired state and the newest sensor
message that has arrived, and writes ``joint.torque`` stamped with its application time (or, when
it returns a :class:`~cerebx.controllers.base.CommandMsg`, the signals named there: the SNN's
``muscle.ag``/``muscle.at``). A
:class:`Composite` runs several parts in order on the same tick; outputs with the same name add up
(feedback + feed-forward corrective torque), and each part keeps its own learned state.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from cerebx import runfiles
from cerebx.controllers.base import CommandMsg, ControlInput, Controller, SensorMsg
from cerebx.signals import Frame, Signal, torque_controller_io
from cerebx.stages.base import Stage


class TorqueControllerStage(Stage):
    """Runs a :class:`Controller` on the brain side."""

    def __init__(self, controller: Controller, kind: str, n_joints: int):
        self.controller = controller
        self.name = kind
        io = torque_controller_io(n_joints)
        self.reads, self.writes = io.reads, io.writes
        self._sensed: Any = None
        self._sensor: SensorMsg | None = None

    def reset(self, rng: np.random.Generator) -> None:
        self.controller.reset(rng)

    def step(self, frame: Frame) -> None:
        sensed = frame.sensed
        if sensed is not self._sensed:  # a new sensor message arrived: convert it once
            self._sensed = sensed
            self._sensor = None if sensed is None else SensorMsg(sensed.stamp_s, sensed["joint.q"], sensed["joint.qd"])
        sig = frame.signals
        cmd = self.controller.step(ControlInput(frame.tick, frame.t_s, sig["ref.q"], sig["ref.qd"], self._sensor))
        frame.stamp_s = cmd.stamp_s
        if isinstance(cmd, CommandMsg):
            for name, value in cmd.values.items():
                self.emit(frame, name, value)
        else:
            self.emit(frame, "joint.torque", cmd.tau)

    def end_trial(self, trial: int) -> dict[str, float]:
        return self.controller.end_trial(trial)

    def attach_recorder(self, recorder: Any) -> None:
        self.controller.attach_recorder(recorder)

    def save_state(self, path: Path) -> bool:
        self.controller.save_state(path)
        return Path(path).exists()

    def load_state(self, path: Path) -> None:
        self.controller.load_state(path)

    def describe(self) -> dict[str, Any]:
        return self.controller.describe()


class Composite(Stage):
    """Parts run in order; a signal written by more than one part is their sum."""

    name = "composite"

    def __init__(self, parts: list[Stage]):
        self.parts = parts
        written: dict[str, Signal] = {}
        reads: list[str] = []
        for part in parts:
            reads += [r for r in part.reads if r not in written and r not in reads]
            part.adds = frozenset(part.adds | {s.name for s in part.writes if s.name in written})
            written.update({s.name: s for s in part.writes})
        self.reads = tuple(reads)
        self.writes = tuple(written.values())

    def reset(self, rng: np.random.Generator) -> None:
        for i, part in enumerate(self.parts):
            part.reset(np.random.default_rng(rng.integers(2**63)) if i else rng)

    def step(self, frame: Frame) -> None:
        for part in self.parts:
            part.step(frame)

    def record(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        for part in self.parts:
            out.update(part.record())
        return out

    def end_trial(self, trial: int) -> dict[str, float]:
        out: dict[str, float] = {}
        for i, part in enumerate(self.parts):
            out.update({f"{i}.{k}" if len(self.parts) > 1 else k: v for k, v in part.end_trial(trial).items()})
        return out

    def attach_recorder(self, recorder: Any) -> None:
        for part in self.parts:
            part.attach_recorder(recorder)

    @staticmethod
    def part_path(path: Path, i: int) -> Path:
        """Where part ``i`` keeps its state beside the run's state file."""
        path = Path(path)
        return path.with_name(runfiles.part_state(path.name, i))

    def save_state(self, path: Path) -> bool:
        saved = [part.save_state(self.part_path(path, i)) for i, part in enumerate(self.parts)]
        if not any(saved):
            return False
        np.savez(path, parts=np.array(saved))
        return True

    def load_state(self, path: Path) -> None:
        for i, part in enumerate(self.parts):
            p = self.part_path(path, i)
            if p.exists():
                part.load_state(p)

    def describe(self) -> dict[str, Any]:
        return {"parts": [{"kind": p.name, **p.describe()} for p in self.parts]}
