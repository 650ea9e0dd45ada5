"""The supported names for a plugin's configuration schemas: what a plugin's ``schema`` module may import.

Everything here belongs to the schema layer, so importing it runs no physics, network or log (a config can be
validated without MuJoCo or numba). The runtime names (stages, plants, tasks, the run reader) are in
:mod:`cerebx.api` too, the report's in :mod:`cerebx.report.api`; a plugin imports nothing else from cerebx (an
import contract in ``pyproject.toml`` holds it to that).

Registering kinds: each group is a :class:`~cerebx.registry.Registry` (``controllers``, ``stages``,
``plants``, ``tasks``, ``delays``, ``events``, ``encoders``, ``links``, and for spiking networks ``connectors``
and ``plasticity_rules``) whose ``register(schema, builder)``
takes the kind's schema (its ``kind`` field's default names it) and its builder (a callable, or
``"module:function"`` imported on first use). A field holding any kind of a group is typed ``Plugin(group)``.
"""

from cerebx.controllers.snn.schema import SNNController
from cerebx.errors import CerebxError, ConfigError, StateMismatchError
from cerebx.lwpr.schema import LWPRParams
from cerebx.registry import (
    Plugin,
    add_bench_run,
    add_config_source,
    add_report,
    connectors,
    controllers,
    delays,
    encoders,
    events,
    links,
    plants,
    plasticity_rules,
    stages,
    tasks,
)
from cerebx.schema.base import CONTROL_DT_MS, NonNegFloat, PerJoint, PhysicsStepMs, PlantSchema, PositiveFloat, Strict
from cerebx.schema.controller import VELOCITY_ERROR, ControllerConfig, GivenRanges, TaskRanges, periodic_part_problems
from cerebx.schema.muscles import EkebergConfig
from cerebx.schema.stages import StageConfig
from cerebx.signals import Signal, StageIO, joint_signals
from cerebx.snn.connectors import Synapses, projection_rng
from cerebx.snn.plasticity import PairingSpec, TraceSpec
from cerebx.snn.schema import KernelSTDP

__all__ = [
    "CONTROL_DT_MS",
    "VELOCITY_ERROR",
    "CerebxError",
    "ConfigError",
    "ControllerConfig",
    "EkebergConfig",
    "GivenRanges",
    "KernelSTDP",
    "LWPRParams",
    "NonNegFloat",
    "PerJoint",
    "PhysicsStepMs",
    "PairingSpec",
    "PlantSchema",
    "Plugin",
    "PositiveFloat",
    "SNNController",
    "Signal",
    "StageConfig",
    "StageIO",
    "StateMismatchError",
    "Strict",
    "Synapses",
    "TaskRanges",
    "TraceSpec",
    "add_bench_run",
    "add_config_source",
    "add_report",
    "connectors",
    "controllers",
    "delays",
    "encoders",
    "events",
    "joint_signals",
    "links",
    "periodic_part_problems",
    "plants",
    "plasticity_rules",
    "projection_rng",
    "stages",
    "tasks",
]
