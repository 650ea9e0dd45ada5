"""Capolei et al. 2020 as a cerebx plugin: forward and inverse cerebellar modules with an LWPR granular layer
beside the platform's velocity PID, on an iCub wrist holding a table with a ball, with its presets, studies
and figures.

Registered through the ``cerebx.plugins`` entry point ``capolei2020`` (see pyproject.toml).
"""

from cerebx.api.schema import add_config_source, add_report, controllers, plants, tasks
from cerebx_capolei2020.modules.schema import CapoleiForward, CapoleiInverse
from cerebx_capolei2020.schema import ICubWristConfig, WristOscillationTask


def register() -> None:
    tasks.register(WristOscillationTask, "cerebx_capolei2020.task:WristOscillation")
    plants.register(ICubWristConfig, "cerebx_capolei2020.wrist:ICubWrist")
    controllers.register(CapoleiForward, "cerebx_capolei2020.modules.controller:build_forward")
    controllers.register(CapoleiInverse, "cerebx_capolei2020.modules.controller:build_inverse")
    add_config_source("cerebx_capolei2020.conf")
    add_report("cerebx_capolei2020.report")
