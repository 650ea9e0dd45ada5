"""Turns a validated experiment config into the live parts of a closed loop, through the registries.

Order: plant, task (which may need the plant model for IK), the brain side (controller, then the
brain stages), the link (delay model), the robot side (receiver, then the robot stages), the plant
events. On the way the signals are checked: each stage must find what it reads among what the task,
the link, the plant and the stages before it provide, and the robot side must end with what the
plant is commanded with. A mismatch is one :class:`~cerebx.errors.ConfigError` line naming both
neighbours.
"""

from __future__ import annotations

import os
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cerebx import registry
from cerebx.controllers.base import Controller
from cerebx.errors import ConfigError
from cerebx.loop.link import Link
from cerebx.loop.signals import Signal
from cerebx.stages.base import Receiver, Stage, check_chain, check_feeds_plant
from cerebx.stages.controllers import Composite, TorqueControllerStage


def component_rng(seed: int, name: str) -> np.random.Generator:
    """An independent generator per component, derived from the one experiment seed."""
    return np.random.default_rng(np.random.SeedSequence([seed, zlib.crc32(name.encode())]))


def cache_dir() -> Path:
    """Where derived artefacts (IK joint paths) are cached; override with CEREBX_CACHE."""
    root = Path(os.environ.get("CEREBX_CACHE", Path.home() / ".cache" / "cerebx"))
    root.mkdir(parents=True, exist_ok=True)
    return root


@dataclass
class BuildContext:
    """What builders may use (the whole config, the parts already built, the seed) and, once
    :func:`build_components` is done, every part of the loop."""

    cfg: Any
    plant: Any = None
    task: Any = None
    run_dir: Path | None = None
    controller: Any = None  # the object the controller group built (a Controller or a Stage)
    brain: list[Stage] = field(default_factory=list)  # controller stage first
    link: Link | None = None
    sent: tuple[Signal, ...] = ()  # what the brain side sends over the link
    receiver: Receiver | None = None
    robot: list[Stage] = field(default_factory=list)
    events: list[tuple[Any, Any]] = field(default_factory=list)  # (scheduled event, fire)

    def rng(self, name: str) -> np.random.Generator:
        return component_rng(self.cfg.seed, name)

    @property
    def cache_dir(self) -> Path:
        return cache_dir()


def as_stage(obj: Any, kind: str, n_joints: int) -> Stage:
    """A controller as a brain-side stage (joint-torque controllers run behind an adapter)."""
    if isinstance(obj, Stage):
        obj.name = kind
        return obj
    if isinstance(obj, Controller):
        return TorqueControllerStage(obj, kind, n_joints)
    raise TypeError(f"controller {kind!r}: builder returned {type(obj).__name__}, neither a Controller nor a Stage")


def build_composite(cfg: Any, ctx: BuildContext) -> Composite:
    """Each part is built by its own registry entry; parts keep their own state."""
    n = ctx.plant.n_joints
    return Composite([as_stage(registry.controllers.build(p, ctx), p.kind, n) for p in cfg.parts])


def _check_step(ctx: BuildContext) -> None:
    """The control step is one value (``control_dt_ms``); plant and task must run on it."""
    dt_s = ctx.cfg.control_dt_ms / 1000.0
    for what, part in (("plant", ctx.plant), ("task", ctx.task)):
        got = getattr(part, "control_dt_s", dt_s)
        if abs(got - dt_s) > 1e-12:
            raise ConfigError(f"{what}: runs at {got * 1000:g} ms steps, the loop at {ctx.cfg.control_dt_ms:g} ms")


def build_components(cfg: Any, run_dir: Path | None = None) -> BuildContext:
    """Build and connect every part of the loop of ``cfg``."""
    ctx = BuildContext(cfg=cfg, run_dir=run_dir)
    ctx.plant = registry.plants.build(cfg.plant, ctx)
    ctx.task = registry.tasks.build(cfg.task, ctx)
    _check_step(ctx)
    plant, n = ctx.plant, ctx.plant.n_joints
    sensors, commands = plant.sensor_signals(), plant.command_signals()

    # brain side: the task's reference and the (delayed) sensor signals, then the stages in order
    ctx.controller = registry.controllers.build(cfg.controller, ctx)
    ctx.brain = [as_stage(ctx.controller, cfg.controller.kind, n)]
    ctx.brain += [registry.stages.build(s, ctx) for s in cfg.brain]
    ref = {"ref.q": Signal("ref.q", n, "rad"), "ref.qd": Signal("ref.qd", n, "rad/s")}
    have = check_chain("brain", "the task and the link", {**ref, **sensors}, ctx.brain)
    written = {s.name: s for st in ctx.brain for s in st.writes}

    # robot side: what it needs from the brain crosses the link
    robot_cfg = list(cfg.robot)
    first = robot_cfg[0] if robot_cfg and robot_cfg[0].receiver else registry.stages.parse({"kind": "hold"})
    if robot_cfg and robot_cfg[0].receiver:
        robot_cfg = robot_cfg[1:]
    ctx.robot = [registry.stages.build(s, ctx) for s in robot_cfg]
    needed = set(commands) | {r for st in ctx.robot for r in st.reads}
    ctx.sent = tuple(have[name] for name in written if name in needed and name not in sensors)
    if not ctx.sent:
        raise ConfigError(f"controller: {cfg.controller.kind} writes "
                          f"{', '.join(str(s) for s in written.values()) or 'nothing'}, but neither the robot "
                          f"stages nor plant {cfg.plant.kind} ({', '.join(str(s) for s in commands.values())}) use it")
    ctx.receiver = registry.stages.build(first, ctx, ctx.sent)
    delay = registry.delays.build(cfg.delay, ctx)
    ctx.link = Link(delay.r2c, delay.c2r, cfg.control_dt_ms)
    source = f"the link ({first.kind}: {', '.join(str(s) for s in ctx.sent)}) and plant {cfg.plant.kind}"
    have = check_chain("robot", source, {**{s.name: s for s in ctx.sent}, **sensors}, ctx.robot)
    last = f"robot stage {len(ctx.robot) - 1} ({ctx.robot[-1].name})" if ctx.robot else source
    check_feeds_plant(last, have, cfg.plant.kind, commands)

    ctx.events = [(ev, registry.events.build(ev.action, plant)) for ev in cfg.events]
    return ctx
