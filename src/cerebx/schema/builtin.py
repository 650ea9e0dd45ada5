"""Registers the built-in variants. Builders are named as ``module:attr`` strings written here in
code (never in configuration) so heavy modules (MuJoCo, numba kernels) load only when used."""

from cerebx import registry
from cerebx.schema import controller as c
from cerebx.schema import delay as d
from cerebx.schema import plant as p
from cerebx.schema import task as t
from cerebx.schema.ann import ANNController

registry.tasks.register(t.JointSineTask, "cerebx.tasks.joint_sine:JointSine")
registry.tasks.register(t.CircleTask, "cerebx.tasks.cartesian:build_cartesian_task")
registry.tasks.register(t.EightTask, "cerebx.tasks.cartesian:build_cartesian_task")
registry.tasks.register(t.InclinedCircleTask, "cerebx.tasks.cartesian:build_cartesian_task")
registry.tasks.register(t.CircleEightTask, "cerebx.tasks.cartesian:build_cartesian_task")
registry.tasks.register(t.ReachingTask, "cerebx.tasks.cartesian:build_cartesian_task")

registry.plants.register(p.Planar2Config, "cerebx.plants.planar2:Planar2Arm")
registry.plants.register(p.BaxterConfig, "cerebx.plants.baxter:BaxterArm")

registry.controllers.register(c.PDController, "cerebx.controllers.pd:PD")
registry.controllers.register(c.PositionController, "cerebx.controllers.position:PositionServo")
registry.controllers.register(c.SNNController, "cerebx.controllers.snn:SNNControllerImpl")
registry.controllers.register(ANNController, "cerebx.controllers.ann:ANN")

registry.delays.register(d.NoDelay, "cerebx.loop.delays:build_delay")
registry.delays.register(d.ConstantDelay, "cerebx.loop.delays:build_delay")
registry.delays.register(d.GammaDelay, "cerebx.loop.delays:build_delay")
registry.delays.register(d.TraceDelay, "cerebx.loop.delays:build_delay")
registry.delays.register(d.PercentileDelay, "cerebx.loop.delays:build_delay")
