"""The platform's own kinds, registered through the ``cerebx.plugins`` entry point ``core`` like any
plugin's. Builders are named as ``module:attr`` strings written here in code (never in configuration), so
heavy modules (MuJoCo, numba kernels) load only when a run uses them; each group's builders have the
signature of its protocol in ``cerebx/builders.py`` (``TaskBuilder``, ``ReceiverBuilder``, ...)."""

from cerebx import registry
from cerebx.controllers.snn import schema as snn
from cerebx.link import schema as lk
from cerebx.schema import arm_tasks as at
from cerebx.schema import controller as c
from cerebx.schema import delay as d
from cerebx.schema import events as e
from cerebx.schema import muscles as m
from cerebx.schema import plant as p
from cerebx.schema import spinal as sp
from cerebx.schema import stages as s
from cerebx.schema import task as t
from cerebx.snn import connectors as cn
from cerebx.snn import plasticity as pl
from cerebx.snn import schema as net
from cerebx.snn.schema import PoissonEncoder


def register() -> None:
    registry.tasks.register(t.JointSineTask, "cerebx.tasks.joint_sine:JointSine")
    registry.tasks.register(t.CircleTask, "cerebx.tasks.cartesian:build_circle")
    registry.tasks.register(t.EightTask, "cerebx.tasks.cartesian:build_eight")
    registry.tasks.register(t.InclinedCircleTask, "cerebx.tasks.cartesian:build_inclined_circle")
    registry.tasks.register(t.CircleEightTask, "cerebx.tasks.cartesian:build_circle_eight")
    registry.tasks.register(t.ReachingTask, "cerebx.tasks.cartesian:build_reaching")
    registry.tasks.register(at.FlexionExtensionTask, "cerebx.tasks.upper_limb:FlexionExtension")
    registry.tasks.register(at.VerticalCircleTask, "cerebx.tasks.upper_limb:VerticalCircle")

    registry.plants.register(p.Planar2Config, "cerebx.plants.planar2:Planar2Arm")
    registry.plants.register(p.BaxterConfig, "cerebx.plants.baxter:BaxterArm")
    registry.plants.register(p.UpperLimbConfig, "cerebx.plants.upper_limb:UpperLimb")

    registry.controllers.register(c.PDController, "cerebx.controllers.pd:PD")
    registry.controllers.register(c.PositionController, "cerebx.controllers.position:PositionServo")
    registry.controllers.register(c.PIDVelocity, "cerebx.stages.pid:build_pid")
    registry.controllers.register(c.CompositeController, "cerebx.build:build_composite")
    registry.controllers.register(snn.SNNController, "cerebx.controllers.snn.controller:SNNControllerImpl")
    registry.controllers.register(m.MuscleRestController, "cerebx.stages.muscles:build_muscle_rest")

    # receivers: ReceiverBuilder (cfg, ctx, the signals the link delivers); the others: StageBuilder (cfg, ctx)
    registry.stages.register(s.HoldConfig, "cerebx.stages.receivers:build_hold")
    registry.stages.register(s.MeanFilterConfig, "cerebx.stages.receivers:build_mean")
    registry.stages.register(s.FuturePastFilterConfig, "cerebx.stages.receivers:build_future_past")
    registry.stages.register(s.SupervisorConfig, "cerebx.stages.supervisor:build_supervisor")
    registry.stages.register(m.EkebergConfig, "cerebx.stages.muscles:build_ekeberg")
    registry.stages.register(sp.SpinalCordConfig, "cerebx.stages.spinal:SpinalCord")
    registry.stages.register(sp.DirectMusclesConfig, "cerebx.stages.spinal:DirectMuscles")
    registry.stages.register(sp.SplitPairsConfig, "cerebx.stages.spinal:SplitPairs")

    registry.delays.register(d.NoDelay, "cerebx.loop.delays:no_delay")
    registry.delays.register(d.ConstantDelay, "cerebx.loop.delays:constant_delay")
    registry.delays.register(d.GammaDelay, "cerebx.loop.delays:gamma_delay")
    registry.delays.register(d.TraceDelay, "cerebx.loop.delays:trace_delay")
    registry.delays.register(d.PercentileDelay, "cerebx.loop.delays:percentile_delay")

    # EventBuilder: (cfg, plant) -> the function that fires the event
    registry.events.register(e.AttachPayload, "cerebx.plants.events:attach_payload")
    registry.events.register(e.DetachPayload, "cerebx.plants.events:detach_payload")
    registry.events.register(e.ElasticBand, "cerebx.plants.events:elastic_band")
    registry.events.register(e.RemoveBand, "cerebx.plants.events:remove_band")
    registry.events.register(e.ForcePulse, "cerebx.plants.events:force_pulse")
    registry.events.register(e.FingerPush, "cerebx.plants.events:finger_push")
    registry.events.register(e.Grab, "cerebx.plants.events:grab")

    # MossyEncoderBuilder (cfg, lo, hi); ClimbingEncoderBuilder (cfg, n_joints, fibres_per_joint, kpos, kvel, rng)
    registry.encoders.register(snn.BoxEncoder, "cerebx.snn.encoders:MossyEncoder")
    registry.encoders.register(snn.CFEncoder, "cerebx.snn.encoders:ClimbingEncoder")
    registry.encoders.register(PoissonEncoder, "cerebx.snn.encoders:PoissonMossyEncoder")

    # links: the tick-grid one of simulated time, and transports between processes (LinkBuilder: cfg, role, via_relay)
    registry.links.register(lk.SimLink, "cerebx.link.transport:build_sim")
    registry.links.register(lk.ZenohLink, "cerebx.link.zenoh_link:ZenohTransport")
    registry.links.register(lk.UdpLink, "cerebx.link.udp:UdpTransport")

    # network connectors take (rule, n_pre, n_post, same population, rng) and return the drawn synapses
    registry.connectors.register(net.AllToAll, "cerebx.snn.topology:all_to_all")
    registry.connectors.register(net.OneToOne, "cerebx.snn.topology:one_to_one")
    registry.connectors.register(net.JointCombinations, "cerebx.snn.topology:joint_combinations")
    registry.connectors.register(cn.FixedIndegree, cn.fixed_indegree)
    registry.connectors.register(cn.FixedOutdegree, cn.fixed_outdegree)
    registry.connectors.register(cn.FixedProbability, cn.fixed_probability)
    registry.connectors.register(cn.FromFile, cn.from_file)

    # plasticity builders take (rule, dt_ms) and return the engine's form of the rule (snn/plasticity.py)
    registry.plasticity_rules.register(net.KernelSTDP, "cerebx.snn.topology:kernel_stdp")
    registry.plasticity_rules.register(pl.PairSTDP, pl.pair_stdp)
    registry.plasticity_rules.register(pl.SymmetricCos, pl.symmetric_cos)
    registry.plasticity_rules.register(pl.SymmetricCosSTDP, pl.symmetric_cos)
