"""The runtime half of :mod:`cerebx.api` (stages, plants, tasks, checkers, learned state, loading and reading
runs), loaded on first use of one of its names."""

from cerebx.build import build_components
from cerebx.builders import (
    BuildContext,
    ClimbingEncoderBuilder,
    ConnectorBuilder,
    ControllerBuilder,
    DelayBuilder,
    EventBuilder,
    LinkBuilder,
    MossyEncoderBuilder,
    PlantBuilder,
    PlantView,
    PlasticityBuilder,
    ReceiverBuilder,
    StageBuilder,
    TaskBuilder,
    TaskView,
)
from cerebx.config import load
from cerebx.controllers.base import ControlInput, Controller, TorqueMsg
from cerebx.controllers.ranges import mf_ranges
from cerebx.export.mapping import NeuronMap, PlasticityMap, Refused, register_export
from cerebx.kernel_struct import KernelStruct
from cerebx.lwpr.model import LWPR
from cerebx.metrics import final_mae
from cerebx.persistence.state import load_state_npz, save_state_npz
from cerebx.plants.base import Plant, PlantEvent
from cerebx.plants.check import check_plant
from cerebx.plants.interaction import grab_anchor, half_sine
from cerebx.plants.mujoco_arm import MujocoArm
from cerebx.recording.reader import channel_counts, read_messages, read_metadata, read_summary
from cerebx.signals import Frame
from cerebx.snn.encoders import ClimbingEncoder, MossyEncoder
from cerebx.snn.topology import ltd_kernel_table
from cerebx.stages.base import Stage
from cerebx.stages.check import check_experiment
from cerebx.stages.pid import updates_every
from cerebx.tasks.base import Task, TrialReference

__all__ = [
    "NeuronMap",
    "PlasticityMap",
    "Refused",
    "register_export",
    "BuildContext",
    "ClimbingEncoderBuilder",
    "ControllerBuilder",
    "DelayBuilder",
    "EventBuilder",
    "LinkBuilder",
    "ConnectorBuilder",
    "PlasticityBuilder",
    "MossyEncoderBuilder",
    "PlantBuilder",
    "PlantView",
    "ReceiverBuilder",
    "StageBuilder",
    "TaskBuilder",
    "TaskView",
    "LWPR",
    "ClimbingEncoder",
    "ControlInput",
    "Controller",
    "Frame",
    "KernelStruct",
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
