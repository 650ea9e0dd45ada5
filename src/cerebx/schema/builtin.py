"""Registers the built-in variants. Builders are named as ``module:attr`` strings written here in
code (never in configuration) so heavy modules (MuJoCo, numba kernels) load only when used."""

from cerebx import registry
from cerebx.schema import capolei as cap
from cerebx.schema import controller as c
from cerebx.schema import delay as d
from cerebx.schema import events as e
from cerebx.schema import muscles as m
from cerebx.schema import plant as p
from cerebx.schema import stages as s
from cerebx.schema import task as t
from cerebx.schema.ann import ANNController

registry.tasks.register(t.JointSineTask, "cerebx.tasks.joint_sine:JointSine")
registry.tasks.register(t.CircleTask, "cerebx.tasks.cartesian:build_circle")
registry.tasks.register(t.EightTask, "cerebx.tasks.cartesian:build_eight")
registry.tasks.register(t.InclinedCircleTask, "cerebx.tasks.cartesian:build_inclined_circle")
registry.tasks.register(t.CircleEightTask, "cerebx.tasks.cartesian:build_circle_eight")
registry.tasks.register(t.ReachingTask, "cerebx.tasks.cartesian:build_reaching")
registry.tasks.register(t.LuqueEightTask, "cerebx.tasks.luque_eight:LuqueEight")
registry.tasks.register(t.WristOscillationTask, "cerebx.tasks.wrist_oscillation:WristOscillation")

registry.plants.register(p.Planar2Config, "cerebx.plants.planar2:Planar2Arm")
registry.plants.register(p.BaxterConfig, "cerebx.plants.baxter:BaxterArm")
registry.plants.register(p.LWR3Config, "cerebx.plants.lwr3:LWR3Arm")
registry.plants.register(p.ICubWristConfig, "cerebx.plants.icub_wrist:ICubWrist")
registry.plants.register(p.UpperLimbConfig, "cerebx.plants.upper_limb:UpperLimb")

registry.controllers.register(c.PDController, "cerebx.controllers.pd:PD")
registry.controllers.register(c.PositionController, "cerebx.controllers.position:PositionServo")
registry.controllers.register(c.SNNController, "cerebx.controllers.snn:SNNControllerImpl")
registry.controllers.register(ANNController, "cerebx.controllers.ann:ANN")
registry.controllers.register(c.CompositeController, "cerebx.build:build_composite")
registry.controllers.register(cap.PIDVelocity, "cerebx.capolei.stages:build_pid")
registry.controllers.register(cap.CapoleiForward, "cerebx.capolei.stages:build_forward")
registry.controllers.register(cap.CapoleiInverse, "cerebx.capolei.stages:build_inverse")
registry.controllers.register(m.MuscleRestController, "cerebx.stages.muscles:build_muscle_rest")

# receivers take (cfg, ctx, signals the link delivers); other stages (cfg, ctx)
registry.stages.register(s.HoldConfig, "cerebx.stages.receivers:build_hold")
registry.stages.register(s.MeanFilterConfig, "cerebx.stages.receivers:build_mean")
registry.stages.register(s.FuturePastFilterConfig, "cerebx.stages.receivers:build_future_past")
registry.stages.register(s.SupervisorConfig, "cerebx.stages.supervisor:build_supervisor")
registry.stages.register(m.EkebergConfig, "cerebx.stages.muscles:build_ekeberg")

registry.delays.register(d.NoDelay, "cerebx.loop.delays:no_delay")
registry.delays.register(d.ConstantDelay, "cerebx.loop.delays:constant_delay")
registry.delays.register(d.GammaDelay, "cerebx.loop.delays:gamma_delay")
registry.delays.register(d.TraceDelay, "cerebx.loop.delays:trace_delay")
registry.delays.register(d.PercentileDelay, "cerebx.loop.delays:percentile_delay")

# links: the tick-grid one of simulated time, and transports between processes; builders take (cfg, role, via_relay)
from cerebx.link import schema as lk  # noqa: E402

registry.links.register(lk.SimLink, "cerebx.link.transport:build_sim")
registry.links.register(lk.ZenohLink, "cerebx.link.zenoh_link:ZenohTransport")
registry.links.register(lk.UdpLink, "cerebx.link.udp:UdpTransport")

# event builders take (cfg, plant) and return the function that fires the event
registry.events.register(e.AttachPayload, "cerebx.plants.events:attach_payload")
registry.events.register(e.DetachPayload, "cerebx.plants.events:detach_payload")
registry.events.register(e.ElasticBand, "cerebx.plants.events:elastic_band")
registry.events.register(e.RemoveBand, "cerebx.plants.events:remove_band")
registry.events.register(e.ForcePulse, "cerebx.plants.events:force_pulse")
registry.events.register(e.FingerPush, "cerebx.plants.events:finger_push")
registry.events.register(e.Grab, "cerebx.plants.events:grab")

# mossy encoders take (cfg, lo, hi); climbing encoders (cfg, n_joints, fibres_per_joint, kpos, kvel, rng)
registry.encoders.register(c.BoxEncoder, "cerebx.snn.encoders:MossyEncoder")
registry.encoders.register(c.CFEncoder, "cerebx.snn.encoders:ClimbingEncoder")

# Luque et al. 2011: crude inverse dynamics + the corrective spiking cerebellum (composite parts)
from cerebx.schema import luque as lq  # noqa: E402

registry.controllers.register(lq.CrudeInverseDynamics, "cerebx.controllers.inverse_dynamics:CrudeInverseDynamicsStage")
registry.controllers.register(lq.Luque2011Cerebellum, "cerebx.controllers.luque2011:Luque2011Stage")

# the upper limb's stages (thesis ch. 4): spinal cord or direct muscle commands; torque split for PD baselines
from cerebx.schema import spinal as sp  # noqa: E402

registry.stages.register(sp.SpinalCordConfig, "cerebx.stages.spinal:SpinalCord")
registry.stages.register(sp.DirectMusclesConfig, "cerebx.stages.spinal:DirectMuscles")
registry.stages.register(sp.SplitPairsConfig, "cerebx.stages.spinal:SplitPairs")
from cerebx.schema import arm_tasks as at  # noqa: E402

registry.tasks.register(at.FlexionExtensionTask, "cerebx.tasks.upper_limb:FlexionExtension")
registry.tasks.register(at.VerticalCircleTask, "cerebx.tasks.upper_limb:VerticalCircle")
