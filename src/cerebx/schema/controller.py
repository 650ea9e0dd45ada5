"""Controller schemas: the contract every controller kind's schema follows, the baselines (PD, the
stiff position servo, the velocity PID), encoder input ranges, and the composite controller whose parts'
outputs add up. Learning controllers (cerebellum models) keep their schema beside their code (e.g.
``controllers/snn/schema.py``). The robot-side torque filters and the supervisor are stages
(``schema/stages.py``)."""

from __future__ import annotations

from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import Field, model_validator

from cerebx import registry
from cerebx.registry import Plugin
from cerebx.schema.base import NonNegFloat, PositiveFloat, Strict
from cerebx.signals import Signal, StageIO, torque_controller_io

VELOCITY_ERROR = "pid.velocity_error"
"""The velocity PID's error signal, for parts that learn from it."""


class ControllerConfig(Strict):
    """Base of every controller schema (a brain-side part of the loop).

    A kind overrides what differs from a joint-torque controller without learned state:

    - :meth:`io`: the signals it reads and writes;
    - :meth:`cross_check`: problems that involve other parts of the experiment;
    - :meth:`complete`: values that depend on the rest of the experiment, filled in before validation;
    - :meth:`state_problems`: why a saved state cannot start it (``init_from``);
    - :attr:`added_without_effect`: fields added after runs were recorded, with the value that does
      what those runs did, so an older run still counts as the same experiment.
    """

    added_without_effect: ClassVar[dict[str, Any]] = {}

    def cross_check(self, exp: Any) -> list[str]:
        """Problems that involve other parts of the experiment (one ``path: message`` line each)."""
        return []

    def io(self, n_joints: int) -> StageIO:
        """The signals this controller reads and writes (default: a joint-torque controller)."""
        return torque_controller_io(n_joints)

    @classmethod
    def complete(cls, experiment: dict[str, Any]) -> dict[str, Any]:
        """The experiment (plain data, not yet validated) with this controller's context-dependent values
        filled in; the default changes nothing."""
        return experiment

    def state_problems(self, meta: dict[str, Any], exp: Any) -> str | None:
        """Why a learned state with metadata ``meta`` cannot start this controller in ``exp``, or None.
        The default accepts states saved by the same kind (or states that name no kind)."""
        saved = meta.get("kind")
        return None if saved in (None, self.kind) else f"was saved by a {saved!r} controller"  # type: ignore[attr-defined]


class PDController(ControllerConfig):
    """tau = kp (q_d - q) + kd (qd_d - qd), saturated at +-tau_max (docs/models.md#pd)."""

    kind: Literal["pd"] = "pd"
    kp: tuple[float, ...] = (45.0, 50.0, 17.0, 50.0, 22.0, 27.0)
    kd: tuple[float, ...] = (15.0, 5.0, 3.0, 4.0, 2.5, 3.0)
    tau_max_Nm: tuple[PositiveFloat, ...] = (12.0, 19.5, 3.75, 10.5, 3.0, 3.75)

    @model_validator(mode="after")
    def _lengths(self) -> PDController:
        if not len(self.kp) == len(self.kd) == len(self.tau_max_Nm):
            raise ValueError("kp, kd and tau_max_Nm need the same number of joints")
        return self

    @property
    def n_joints(self) -> int:
        return len(self.kp)


class PositionController(ControllerConfig):
    """Stiff position servo with gravity compensation (stands in for Baxter's factory controller)."""

    kind: Literal["position"] = "position"
    kp: tuple[float, ...] = (700.0, 1000.0, 450.0, 550.0, 100.0, 90.0)
    kd: tuple[float, ...] = (25.0, 40.0, 10.0, 12.0, 2.0, 2.0)
    gravity_compensation: bool = True
    velocity_feedforward: bool = Field(
        True, description="track the desired velocity; off = position-only commands (damping toward rest)"
    )
    tau_max_Nm: tuple[PositiveFloat, ...] = (50.0, 100.0, 50.0, 50.0, 15.0, 15.0)

    @property
    def n_joints(self) -> int:
        return len(self.kp)

class PIDVelocity(ControllerConfig):
    """tau = K_P e + K_I int e dt + K_D de/dt on the velocity error e = qdot_r - qdot (+ the signal
    ``correction_signal`` names, e.g. a learned velocity correction written by an earlier part), run at
    ``rate_hz`` and held between updates. Also writes e as ``pid.velocity_error``."""

    kind: Literal["pid_velocity"] = "pid_velocity"
    kp: tuple[float, ...] = Field((2.9, 2.3, 2.35), description="K_P, N·m per rad/s")
    ki: tuple[float, ...] = Field((1.94, 1.9, 1.9), description="K_I, N·m per rad")
    kd: tuple[float, ...] = Field((0.005, 0.0001, 0.0004), description="K_D, N·m per rad/s^2")
    rate_hz: PositiveFloat = Field(50.0, description="update rate; the torque is held between updates")
    correction_signal: str | None = Field(
        None, description="a signal added to the velocity error (written by an earlier part); null: none")

    @model_validator(mode="after")
    def _lengths(self) -> PIDVelocity:
        if not len(self.kp) == len(self.ki) == len(self.kd):
            raise ValueError("kp, ki and kd need the same number of joints")
        return self

    @property
    def n_joints(self) -> int:
        return len(self.kp)

    def cross_check(self, exp: Any) -> list[str]:
        return periodic_part_problems("kp", self.n_joints, self.rate_hz, exp)

    def io(self, n_joints: int) -> StageIO:
        reads = ("ref.qd",) + ((self.correction_signal,) if self.correction_signal else ())
        return StageIO(reads, (Signal("joint.torque", n_joints, "N·m"), Signal(VELOCITY_ERROR, n_joints, "rad/s")))


def periodic_part_problems(joints_field: str, n_joints: int, rate_hz: float, exp: Any) -> list[str]:
    """Problems of a part that updates ``n_joints`` joints at ``rate_hz``: it must drive the plant's joints,
    and its rate must be the loop rate divided by a whole number.

    Parameters
    ----------
    joints_field : str
        The config field that sets the joints (named in the problem).
    n_joints : int
        Joints the part drives.
    rate_hz : float
        The part's update rate, Hz.
    exp : ExperimentConfig
        The experiment (its plant and ``control_dt_ms``).

    Returns
    -------
    list of str
        One line per problem ("field: problem"); empty when none.
    """
    out = []
    if n_joints != exp.plant.n_joints:
        out.append(f"{joints_field}: {n_joints} joints, plant {exp.plant.kind} has {exp.plant.n_joints}")
    n = 1000.0 / (rate_hz * exp.control_dt_ms)
    if abs(n - round(n)) > 1e-9 or round(n) < 1:
        out.append(f"rate_hz: {rate_hz:g} Hz is not the loop rate divided by a whole number")
    return out


def muscle_command_signals(n_joints: int) -> tuple[Signal, Signal]:
    """The agonist and antagonist commands of an antagonist muscle pair per joint, each in [0, 1]."""
    return (Signal("muscle.ag", n_joints, "1", 0.0, 1.0), Signal("muscle.at", n_joints, "1", 0.0, 1.0))


class GivenRanges(Strict):
    """Encoder ranges per joint for each of the four MF signals (the original launch files:
    docs/provenance.md#original-mf-ranges)."""

    kind: Literal["given"] = "given"
    q_min: tuple[float, ...]
    q_max: tuple[float, ...]
    qd_des_min: tuple[float, ...]
    qd_des_max: tuple[float, ...]
    qd_min: tuple[float, ...]
    qd_max: tuple[float, ...]

    @model_validator(mode="after")
    def _non_empty(self) -> GivenRanges:
        for lo_name, hi_name in (("q_min", "q_max"), ("qd_des_min", "qd_des_max"), ("qd_min", "qd_max")):
            lo, hi = getattr(self, lo_name), getattr(self, hi_name)
            if len(lo) != len(hi):
                raise ValueError(f"{lo_name} and {hi_name} need the same length")
            bad = [j for j, (a, b) in enumerate(zip(lo, hi)) if not a < b]
            if bad:
                raise ValueError(f"{lo_name} must be below {hi_name} (empty range at joint {bad[0]})")
        return self

    def bounds(self, n_joints: int, task: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi), each (n_joints, 4) for q_d, q, qd_d, qd: as configured (q_d and q share the
        position range, as in the original)."""
        if min(len(self.q_min), len(self.qd_min), len(self.qd_des_min)) < n_joints:
            raise ValueError(f"controller ranges: given ranges cover fewer than the {n_joints} controlled joints")
        qlo, qhi = np.asarray(self.q_min, float), np.asarray(self.q_max, float)
        lo = np.stack([qlo, qlo, np.asarray(self.qd_des_min, float), np.asarray(self.qd_min, float)], axis=1)
        hi = np.stack([qhi, qhi, np.asarray(self.qd_des_max, float), np.asarray(self.qd_max, float)], axis=1)
        return lo[:n_joints], hi[:n_joints]


class TaskRanges(Strict):
    """Encoder ranges from the task's desired trajectory, widened by ``margin`` of the span."""

    kind: Literal["from_task"] = "from_task"
    margin: NonNegFloat = 0.1
    velocity_margin: NonNegFloat = 0.1

    def bounds(self, n_joints: int, task: Any = None) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi), each (n_joints, 4) for q_d, q, qd_d, qd: the task's desired envelope widened by
        ``margin`` (positions) and ``velocity_margin`` (velocities) of its span; actual and desired
        share the range."""
        if task is None:
            raise ValueError("controller ranges: 'from_task' needs a task to derive the encoder ranges")
        q_min, q_max, qd_min, qd_max = (np.asarray(a, dtype=float)[:n_joints] for a in task.envelope())
        qlo, qhi = _widen(q_min, q_max, self.margin)
        vlo, vhi = _widen(qd_min, qd_max, self.velocity_margin)
        return np.stack([qlo, qlo, vlo, vlo], axis=1), np.stack([qhi, qhi, vhi, vhi], axis=1)


def _widen(a: np.ndarray, b: np.ndarray, margin: float) -> tuple[np.ndarray, np.ndarray]:
    span = np.maximum(b - a, 1e-3)
    return a - margin * span, b + margin * span


class CompositeController(ControllerConfig):
    """Several brain-side parts run in order each tick; signals written by more than one part add up
    (e.g. a feed-forward torque plus a corrective one). Each part keeps its own learned state."""

    kind: Literal["composite"] = "composite"
    parts: list[Plugin("controller")] = Field(min_length=1, description="controller parts, in order")

    @classmethod
    def complete(cls, experiment: dict[str, Any]) -> dict[str, Any]:
        """Each part's own ``complete`` with the part in the controller's place; what a part's hook changes
        outside the controller (e.g. the robot stages) is not taken over: set it in the experiment."""
        ctrl = experiment.get("controller")
        parts = ctrl.get("parts") if isinstance(ctrl, dict) else None
        if not isinstance(parts, list):
            return experiment
        done = []
        for part in parts:
            kind = part.get("kind") if isinstance(part, dict) else None
            if isinstance(kind, str) and kind in registry.controllers and kind != "composite":
                part = registry.controllers[kind].schema.complete({**experiment, "controller": part})["controller"]
            done.append(part)
        return {**experiment, "controller": {**ctrl, "parts": done}}

    def cross_check(self, exp: Any) -> list[str]:
        return [f"controller.parts.{i}.{line}" for i, p in enumerate(self.parts) for line in p.cross_check(exp)]

    def io(self, n_joints: int) -> StageIO:
        """Reads what a part reads before an earlier part wrote it; writes every part's outputs."""
        written: dict[str, Any] = {}
        reads: list[str] = []
        for part in self.parts:
            pio = part.io(n_joints)
            reads += [r for r in pio.reads if r not in written and r not in reads]
            written.update({s.name: s for s in pio.writes})
        return StageIO(tuple(reads), tuple(written.values()))
