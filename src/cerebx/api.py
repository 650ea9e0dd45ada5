"""The supported names for plugins: what a lab's package (and the paper plugins that ship with cerebx) may
import from cerebx. Everything else is internal and may change between versions; an import contract in
``pyproject.toml`` holds the paper packages and ``examples/`` to these modules (``make lint``).

- Configuration (schema layer, no physics or network loaded): every name of :mod:`cerebx.schema.api`,
  re-exported here; a plugin's own ``schema`` module imports from there.
- Runtime shapes: :class:`Stage` (a part of the loop that reads and writes named signals every tick; a
  torque controller is a stage), :class:`Controller` (the older controller shape, still accepted),
  :class:`Plant` (a robot or body; :class:`MujocoArm` for MuJoCo models), :class:`Task` and
  :class:`TrialReference` (desired trajectories), the encoders' interface (:class:`MossyEncoder` and
  :class:`ClimbingEncoder`: see ``docs/howto/cerebellum.md``), :class:`Frame` (one tick's signals).
- Checkers a plugin runs in its tests: :func:`check_plant`, :func:`check_experiment`.
- Learned state: :func:`save_state_npz` and :func:`load_state_npz`.
- Building and loading an experiment: :func:`load` (compose and validate a command line's overrides),
  :func:`build_components`.
- Reading runs: :func:`read_summary`, :func:`read_messages` (an MCAP log's messages), :func:`read_metadata`,
  :func:`channel_counts`, :func:`final_mae`.
- The report's names (figures, checks, runs) are in :mod:`cerebx.report.api`.
"""

from cerebx.build import build_components
from cerebx.config import load
from cerebx.controllers.base import ControlInput, Controller, TorqueMsg
from cerebx.controllers.pid import updates_every
from cerebx.controllers.ranges import mf_ranges
from cerebx.controllers.state import load_state_npz, save_state_npz
from cerebx.lwpr.model import LWPR
from cerebx.metrics import final_mae
from cerebx.plants.base import Plant, PlantEvent
from cerebx.plants.check import check_plant
from cerebx.plants.interaction import grab_anchor, half_sine
from cerebx.plants.mujoco_arm import MujocoArm
from cerebx.recording.reader import channel_counts, read_messages, read_metadata, read_summary
from cerebx.schema.api import *  # noqa: F403 - the schema layer's names are part of this API
from cerebx.schema.api import __all__ as _schema_names
from cerebx.signals import Frame
from cerebx.snn.encoders import ClimbingEncoder, MossyEncoder
from cerebx.snn.topology import ltd_kernel_table
from cerebx.stages.base import Stage
from cerebx.stages.check import check_experiment
from cerebx.tasks.base import Task, TrialReference

__all__ = [
    *_schema_names,
    "LWPR",
    "ClimbingEncoder",
    "ControlInput",
    "Controller",
    "Frame",
    "MossyEncoder",
    "MujocoArm",
    "Plant",
    "PlantEvent",
    "Stage",
    "Task",
    "TorqueMsg",
    "TrialReference",
    "build_components",
    "channel_counts",
    "check_experiment",
    "check_plant",
    "final_mae",
    "grab_anchor",
    "half_sine",
    "load",
    "load_state_npz",
    "ltd_kernel_table",
    "mf_ranges",
    "read_messages",
    "read_metadata",
    "read_summary",
    "save_state_npz",
    "updates_every",
]
