"""The supported names for plugins: what a lab's package (and the paper plugins that ship with cerebx) may
import from cerebx. Everything else is internal and may change between versions; an import contract in
``pyproject.toml`` holds the paper packages and ``examples/`` to ``cerebx.api``, ``cerebx.api.schema`` and
``cerebx.report.api`` (``make lint``).

- Configuration (the schema layer: no physics, network or log loaded): the names of :mod:`cerebx.api.schema`,
  re-exported here; a plugin's own ``schema`` modules import from there.
- Runtime shapes: ``Stage`` (a part of the loop that reads and writes named signals every tick, with one
  ``save_state -> bool``), ``Controller`` (the joint-torque controller's base, a ``Stage`` whose subclasses
  implement ``control(ControlInput) -> TorqueMsg``), ``Plant`` (a robot or
  body; ``MujocoArm`` for MuJoCo models), ``Task`` and ``TrialReference`` (desired trajectories), the encoders'
  interface (``MossyEncoder``, ``ClimbingEncoder``: see the how-tos), ``Frame`` (one tick's signals), ``LWPR``.
- Kernels: ``KernelStruct`` (a numba kernel's arrays and constants, named, as one argument).
- Builders: ``BuildContext`` (what a builder is given: the config, the parts built before it, a generator per
  component) and one builder protocol per registry group (``TaskBuilder``, ``PlantBuilder``,
  ``ControllerBuilder``, ``StageBuilder``, ``ReceiverBuilder``, ``DelayBuilder``, ``EventBuilder``,
  ``MossyEncoderBuilder``, ``ClimbingEncoderBuilder``, ``LinkBuilder``), with ``PlantView`` and ``TaskView``
  (what a builder may use of the plant and the task).
- Export to NEST and PyNN: ``register_export`` (what a plugin's neuron, connector or plasticity kind becomes
  there, as a ``NeuronMap``, ``PlasticityMap``, rule string or ``Refused``; ``cerebx export``, docs: cerebx and
  NEST).
- Checkers a plugin runs in its tests: ``check_plant``, ``check_experiment``.
- Learned state: ``save_state_npz``, ``load_state_npz``.
- Building and loading an experiment: ``load`` (compose and validate a command line's overrides),
  ``build_components``.
- Reading runs: ``read_summary``, ``read_messages`` (an MCAP log's messages), ``read_metadata``,
  ``channel_counts``, ``final_mae``.
- The report's names (figures, checks, runs) are in :mod:`cerebx.report.api`.

The runtime names load MuJoCo and numba; they are imported from :mod:`cerebx.api.runtime` on first use, so
``import cerebx.api.schema`` (and this package) stays as light as the schema layer.
"""

from typing import Any

from cerebx.api.schema import *  # noqa: F403 - the schema layer's names are part of this API
from cerebx.api.schema import __all__ as _schema_names

RUNTIME = (
    "BuildContext", "ClimbingEncoderBuilder", "ConnectorBuilder", "ControllerBuilder", "DelayBuilder", "EventBuilder",
    "LinkBuilder", "PlasticityBuilder",
    "MossyEncoderBuilder", "PlantBuilder", "PlantView", "ReceiverBuilder", "StageBuilder", "TaskBuilder", "TaskView",
    "LWPR", "ClimbingEncoder", "ControlInput", "Controller", "Frame", "KernelStruct", "MossyEncoder", "MujocoArm",
    "Plant",
    "PlantEvent", "Stage", "Task", "TorqueMsg", "TrialReference", "build_components", "channel_counts",
    "check_experiment", "check_plant", "final_mae", "grab_anchor", "half_sine", "load", "load_state_npz",
    "ltd_kernel_table", "mf_ranges", "read_messages", "read_metadata", "read_summary", "save_state_npz",
    "updates_every", "NeuronMap", "PlasticityMap", "Refused", "register_export",
)
"""The names :mod:`cerebx.api.runtime` provides."""

__all__ = [*_schema_names, *RUNTIME]


def __getattr__(name: str) -> Any:
    if name in RUNTIME:
        from cerebx.api import runtime

        return getattr(runtime, name)
    raise AttributeError(f"module 'cerebx.api' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
