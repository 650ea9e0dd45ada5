"""Luque et al. 2011 as a cerebx plugin: a crude inverse dynamics model plus a corrective spiking cerebellum
on three joints of a lightweight arm manipulating objects, with its presets, studies and figures.

Registered through the ``cerebx.plugins`` entry point ``luque2011`` (see pyproject.toml).
"""

from cerebx.api.schema import add_bench_run, add_config_source, add_report, controllers, plants, tasks
from cerebx_luque2011.cerebellum.schema import Luque2011Cerebellum
from cerebx_luque2011.schema import CrudeInverseDynamics, LuqueEightTask, LWR3Config


def register() -> None:
    tasks.register(LuqueEightTask, "cerebx_luque2011.task:LuqueEight")
    plants.register(LWR3Config, "cerebx_luque2011.arm:LWR3Arm")
    controllers.register(CrudeInverseDynamics, "cerebx_luque2011.inverse_dynamics:CrudeInverseDynamicsStage")
    controllers.register(Luque2011Cerebellum, "cerebx_luque2011.cerebellum.controller:Luque2011Stage")
    add_config_source("cerebx_luque2011.conf")
    add_report("cerebx_luque2011.report")
    add_bench_run("luque2011_distributed", ["+experiment=luque2011_distributed"])
