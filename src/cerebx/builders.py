"""What a builder is given and what it returns: the build context and one builder protocol per registry group.

A registry entry maps a config ``kind`` to its builder (``registry.py``); :func:`cerebx.build.build_components`
calls the builders in the loop's order, each with the part's validated config and the :class:`BuildContext`
(the whole config, the parts built before it, a generator per component). The protocols below are the
signatures the builders of each group have; a class whose constructor takes the same arguments is a
builder too (``registry.plants.register(MyConfig, "my_lab.arm:MyArm")``).

========== ============================================== =====================================
group      builder                                        returns
========== ============================================== =====================================
task       :class:`TaskBuilder` ``(cfg, ctx)``            a ``Task``
plant      :class:`PlantBuilder` ``(cfg, ctx)``           a ``Plant``
controller :class:`ControllerBuilder` ``(cfg, ctx)``      a ``Stage`` (a ``Controller`` for joint
                                                          torques)
stage      :class:`StageBuilder` ``(cfg, ctx)``;          a ``Stage``; a ``Receiver``
           receivers :class:`ReceiverBuilder`
           ``(cfg, ctx, signals)``
delay      :class:`DelayBuilder` ``(cfg, ctx)``           a delay model (:class:`DelayView`)
event      :class:`EventBuilder` ``(cfg, plant)``         the function that fires the event
encoder    :class:`MossyEncoderBuilder` ``(cfg, lo, hi)``; a mossy or climbing-fibre encoder
           :class:`ClimbingEncoderBuilder`
           ``(cfg, n_joints, fibres_per_joint, kpos,
           kvel, rng)``
link       :class:`LinkBuilder` ``(cfg, role, via_relay)`` a transport
========== ============================================== =====================================

This module is below every folder that writes builders (it imports none of them): the parts a builder
finds in the context are typed by what builders may use of them (:class:`PlantView`, :class:`TaskView`).
"""

from __future__ import annotations

import os
import zlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal, Protocol

import numpy as np

from cerebx.signals import Signal

if TYPE_CHECKING:
    from cerebx.schema.experiment import ExperimentConfig


def component_rng(seed: int, name: str) -> np.random.Generator:
    """An independent generator per component, derived from the one experiment seed.

    Parameters
    ----------
    seed : int
        The experiment's seed.
    name : str
        The component's name (``"plant"``, ``"controller"``, ``"robot.0"``, ...).
    """
    return np.random.default_rng(np.random.SeedSequence([seed, zlib.crc32(name.encode())]))


def cache_dir() -> Path:
    """Where derived artefacts (IK joint paths) are cached; override with CEREBX_CACHE."""
    root = Path(os.environ.get("CEREBX_CACHE", Path.home() / ".cache" / "cerebx"))
    root.mkdir(parents=True, exist_ok=True)
    return root


class PlantView(Protocol):
    """What builders may use of the plant built before them."""

    joint_names: tuple[str, ...]
    control_dt_s: float

    @property
    def n_joints(self) -> int: ...

    def joint_limits(self) -> tuple[np.ndarray, np.ndarray]: ...

    def sensor_signals(self) -> dict[str, Signal]: ...

    def command_signals(self) -> dict[str, Signal]: ...


class TaskView(Protocol):
    """What builders may use of the task built before them."""

    control_dt_s: float

    @property
    def steps_per_trial(self) -> int: ...

    def start_position(self) -> np.ndarray: ...


class DelayView(Protocol):
    """What a delay builder returns: one sampler per direction (robot to controller, controller to robot),
    each with ``next_ms()``."""

    r2c: Any
    c2r: Any


@dataclass
class BuildContext:
    """What builders may use (the whole config, the parts already built, a generator per component) and,
    once :func:`cerebx.build.build_components` is done, every part of the loop.

    Attributes
    ----------
    cfg : ExperimentConfig
        The whole validated experiment.
    plant : PlantView or None
        The plant (built first; None only for builders called outside a loop, e.g. a delay model alone).
    task : TaskView or None
        The task (built second).
    run_dir : Path or None
        The run's folder (None outside a run).
    controller : Any
        The stage the controller group built.
    brain : list
        The brain-side stages, the controller's first.
    link : Any
        The simulated delay channel.
    sent : tuple of Signal
        What the brain side sends over the link.
    receiver : Any
        The first robot-side stage (a ``Receiver``).
    robot : list
        The robot-side stages.
    events : list of (event config, fire)
        The plant events and the functions that fire them.
    """

    cfg: ExperimentConfig
    plant: PlantView | None = None
    task: TaskView | None = None
    run_dir: Path | None = None
    controller: Any = None
    brain: list[Any] = field(default_factory=list)
    link: Any = None
    sent: tuple[Signal, ...] = ()
    receiver: Any = None
    robot: list[Any] = field(default_factory=list)
    events: list[tuple[Any, Callable[[], None]]] = field(default_factory=list)

    def rng(self, name: str) -> np.random.Generator:
        """The generator of component ``name`` (see :func:`component_rng`)."""
        return component_rng(self.cfg.seed, name)

    @property
    def cache_dir(self) -> Path:
        return cache_dir()


class TaskBuilder(Protocol):
    """``task`` group: the desired trajectories of a run."""

    def __call__(self, cfg: Any, ctx: BuildContext, /) -> Any: ...


class PlantBuilder(Protocol):
    """``plant`` group: the robot or body."""

    def __call__(self, cfg: Any, ctx: BuildContext, /) -> Any: ...


class ControllerBuilder(Protocol):
    """``controller`` group: the first brain-side stage (its signals are named by the build from its schema)."""

    def __call__(self, cfg: Any, ctx: BuildContext, /) -> Any: ...


class StageBuilder(Protocol):
    """``stage`` group (all but receivers): a brain- or robot-side stage."""

    def __call__(self, cfg: Any, ctx: BuildContext, /) -> Any: ...


class ReceiverBuilder(Protocol):
    """``stage`` group, receivers: the first robot-side stage, given the signals the link delivers."""

    def __call__(self, cfg: Any, ctx: BuildContext, signals: tuple[Signal, ...], /) -> Any: ...


class DelayBuilder(Protocol):
    """``delay`` group: the link's delay model."""

    def __call__(self, cfg: Any, ctx: BuildContext, /) -> DelayView: ...


class EventBuilder(Protocol):
    """``event`` group: given the plant, the function that fires the event."""

    def __call__(self, cfg: Any, plant: Any, /) -> Callable[[], None]: ...


class MossyEncoderBuilder(Protocol):
    """``encoder`` group, mossy fibres: given the ranges of the encoded values."""

    def __call__(self, cfg: Any, lo: np.ndarray, hi: np.ndarray, /) -> Any: ...


class ClimbingEncoderBuilder(Protocol):
    """``encoder`` group, climbing fibres: given the joints, the fibres per joint, the error gains and a
    generator."""

    def __call__(self, cfg: Any, n_joints: int, fibres_per_joint: int, kpos: Any, kvel: Any,
                 rng: np.random.Generator, /) -> Any: ...


class LinkBuilder(Protocol):
    """``link`` group: the transport of one side (``role``), through the delay relay or not."""

    def __call__(self, cfg: Any, role: Literal["brain", "robot"], via_relay: bool, /) -> Any: ...


class ConnectorBuilder(Protocol):
    """``connector`` group: a projection's synapses (``cerebx.snn.connectors.Synapses``, local indices) drawn from
    its rule, the two populations' sizes, whether they are one population, and the projection's generator."""

    def __call__(self, rule: Any, n_pre: int, n_post: int, same_population: bool, rng: Any, /) -> Any: ...


class PlasticityBuilder(Protocol):
    """``plasticity`` group: the engine form of a rule (``cerebx.snn.plasticity.TraceSpec`` or ``PairingSpec``)
    at the network's step ``dt_ms``."""

    def __call__(self, rule: Any, dt_ms: float, /) -> Any: ...
