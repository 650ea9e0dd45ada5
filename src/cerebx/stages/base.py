"""The stage contract and the build-time check that neighbouring stages agree on signals."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from cerebx.errors import ConfigError
from cerebx.signals import Frame, Message, Signal, StageIO

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

    def end_trial(self, trial: int) -> dict[str, float]:
        """Called after each trial; may return scalars to record (e.g. weight summaries)."""
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


def reference_signals(exp: Any) -> dict[str, Signal]:
    """What the task gives the brain side: ``ref.q``, ``ref.qd`` and the extra references its schema
    declares in ``extra_reference`` (name -> unit, e.g. ``{"qdd": "rad/s^2"}``)."""
    n = exp.plant.n_joints
    ref = {"ref.q": Signal("ref.q", n, "rad"), "ref.qd": Signal("ref.qd", n, "rad/s")}
    for name, unit in getattr(exp.task, "extra_reference", {}).items():
        ref[f"ref.{name}"] = Signal(f"ref.{name}", n, unit)
    return ref


def _fmt(signals: dict[str, Signal]) -> str:
    return ", ".join(str(s) for s in signals.values()) or "nothing"


def check_chain(side: Side, source: str, available: dict[str, Signal],
                stages: list[tuple[str, StageIO]]) -> dict[str, Signal]:
    """Walk the (label, io) of ``stages`` in order from the signals ``source`` provides; return what
    the chain ends with. A stage that reads a signal nobody before it wrote, or writes one of another
    size, is refused with one line naming both neighbours."""
    have = dict(available)
    prev = source
    for label, io in stages:
        for name in io.reads:
            if name not in have:
                raise ConfigError(f"{label}: reads {name}, but {prev} provides only {_fmt(have)}")
        for sig in io.writes:
            old = have.get(sig.name)
            if old is not None and old.size != sig.size:
                raise ConfigError(f"{label}: writes {sig}, but {prev} provides {old}")
            if sig.name in io.adds and old is None:
                raise ConfigError(f"{label}: adds to {sig.name}, but {prev} provides no {sig.name}")
            have[sig.name] = sig
        prev = label
    return have


@dataclass(frozen=True)
class Wiring:
    """The signal graph of an experiment: what crosses the link and which robot stages follow the receiver
    (the ``spinal`` and ``muscle`` slots first, then the ``robot`` list)."""

    sent: tuple[Signal, ...]
    receiver: Any  # the receiver's config (hold when none is listed)
    robot: tuple[Any, ...]  # the other robot-stage configs, in order


def wire(exp: Any) -> Wiring:
    """Check the experiment's signals from the declarations alone (no part is built): each stage finds
    what it reads, and the robot side ends with the plant's command signals. One ConfigError line on
    the first mismatch."""
    from cerebx import registry
    from cerebx.schema.experiment import BODY_SLOTS

    plant = exp.plant
    n = plant.n_joints
    sensors, commands = plant.sensor_signals(), plant.command_signals()
    ref = reference_signals(exp)
    brain = [(f"controller ({exp.controller.kind})", exp.controller.io(n))]
    brain += [(f"brain stage {i} ({s.kind})", s.io(n)) for i, s in enumerate(exp.brain)]
    have = check_chain("brain", "the task and the link", {**ref, **sensors}, brain)
    written = [s.name for _, io in brain for s in io.writes]

    robot_cfg = list(exp.robot)
    receiver = robot_cfg.pop(0) if robot_cfg and robot_cfg[0].receiver else registry.stages.parse({"kind": "hold"})
    first = 1 if exp.robot and exp.robot[0].receiver else 0
    body = [(slot, getattr(exp, slot, None)) for slot in BODY_SLOTS]
    body = [(slot, s) for slot, s in body if s is not None]
    robot = [(f"{slot} ({s.kind})", s.io(n)) for slot, s in body]
    robot += [(f"robot stage {i + first} ({s.kind})", s.io(n)) for i, s in enumerate(robot_cfg)]
    robot_cfg = [s for _, s in body] + robot_cfg
    needed = set(commands) | {r for _, io in robot for r in io.reads}
    sent = tuple(dict.fromkeys(have[w] for w in written if w in needed and w not in sensors))
    if not sent:
        raise ConfigError(f"controller ({exp.controller.kind}): the brain side writes "
                          f"{', '.join(sorted(set(written))) or 'nothing'}, but neither the robot stages nor "
                          f"plant {plant.kind} ({_fmt(commands)}) use it")
    source = f"the link ({receiver.kind}: {', '.join(str(s) for s in sent)}) and plant {plant.kind}"
    have = check_chain("robot", source, {**{s.name: s for s in sent}, **sensors}, robot)
    last = robot[-1][0] if robot else source
    for name, sig in commands.items():
        got = have.get(name)
        if got is None or got.size != sig.size:
            raise ConfigError(f"plant {plant.kind}: is commanded with {sig}, but {last} provides {_fmt(have)}")
    return Wiring(sent, receiver, tuple(robot_cfg))
