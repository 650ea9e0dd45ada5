"""Turns a validated experiment config into the live parts of a closed loop, through the registries.

Order: plant, task (which may need the plant model for IK), the brain side (controller, then the
brain stages), the link (delay model), the robot side (receiver, then the robot stages), the plant
events. On the way the signals are checked: each stage must find what it reads among what the task,
the link, the plant and the stages before it provide, and the robot side must end with what the
plant is commanded with. A mismatch is one :class:`~cerebx.errors.ConfigError` line naming both
neighbours.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from cerebx import registry
from cerebx.builders import BuildContext, cache_dir, component_rng
from cerebx.delay_channel import Link
from cerebx.errors import ConfigError
from cerebx.stages.base import Stage
from cerebx.stages.controllers import Composite
from cerebx.wiring import wire

__all__ = ["BuildContext", "as_stage", "build_components", "build_composite", "cache_dir", "component_rng"]


def as_stage(obj: Any, cfg: Any, n_joints: int) -> Stage:
    """The stage a controller builder returned, named after its kind, with the signals its schema declares."""
    if not isinstance(obj, Stage):
        raise TypeError(f"controller {cfg.kind!r}: builder returned {type(obj).__name__}, not a Stage (a "
                        "joint-torque controller subclasses Controller, itself a Stage)")
    io = cfg.io(n_joints)
    obj.name, obj.reads, obj.writes, obj.adds = cfg.kind, io.reads, io.writes, io.adds | obj.adds
    return obj


def build_composite(cfg: Any, ctx: BuildContext) -> Composite:
    """Each part is built by its own registry entry; parts keep their own state."""
    n = ctx.plant.n_joints
    return Composite([as_stage(registry.controllers.build(p, ctx), p, n) for p in cfg.parts])


def _check_step(ctx: BuildContext) -> None:
    """The control step is one value (``control_dt_ms``); plant and task must run on it."""
    dt_s = ctx.cfg.control_dt_ms / 1000.0
    for what, part in (("plant", ctx.plant), ("task", ctx.task)):
        got = getattr(part, "control_dt_s", dt_s)
        if abs(got - dt_s) > 1e-12:
            raise ConfigError(f"{what}: runs at {got * 1000:g} ms steps, the loop at {ctx.cfg.control_dt_ms:g} ms")


def build_components(cfg: Any, run_dir: Path | None = None) -> BuildContext:
    """Build and connect every part of the loop of ``cfg`` (its signals were checked by :func:`wire`
    when the config was validated; the built plant must declare the same signals as its schema).

    Parameters
    ----------
    cfg : ExperimentConfig
        The validated experiment (``load(overrides)[0]``).
    run_dir : Path, optional
        The run's folder, for builders that write there.

    Returns
    -------
    BuildContext
        Every part of the loop: plant, task, controller and brain stages, link, receiver, robot stages,
        events.
    """
    wiring = wire(cfg)
    ctx = BuildContext(cfg=cfg, run_dir=run_dir)
    ctx.plant = registry.plants.build(cfg.plant, ctx)
    ctx.task = registry.tasks.build(cfg.task, ctx)
    _check_step(ctx)
    n = ctx.plant.n_joints
    for what in ("sensor_signals", "command_signals"):
        built, declared = getattr(ctx.plant, what)(), getattr(cfg.plant, what)()
        if {k: v.size for k, v in built.items()} != {k: v.size for k, v in declared.items()}:
            raise ConfigError(f"plant {cfg.plant.kind}: {what} of the built plant differ from its schema's")
    ctx.controller = registry.controllers.build(cfg.controller, ctx)
    ctx.brain = [as_stage(ctx.controller, cfg.controller, n)]
    ctx.brain += [registry.stages.build(s, ctx) for s in cfg.brain]
    ctx.sent = wiring.sent
    ctx.receiver = registry.stages.build(wiring.receiver, ctx, ctx.sent)
    ctx.robot = [registry.stages.build(s, ctx) for s in wiring.robot]
    delay = registry.delays.build(cfg.delay, ctx)
    ctx.link = Link(delay.r2c, delay.c2r, cfg.control_dt_ms)
    ctx.events = [(ev, registry.events.build(ev.action, ctx.plant)) for ev in cfg.events]
    return ctx
