"""Every registered builder has the signature of its group's protocol (``cerebx/builders.py``), and the build
context the builders are given is the one ``build_components`` returns."""

from __future__ import annotations

import inspect

import pytest

from cerebx import builders, registry
from cerebx.build import build_components

pytestmark = pytest.mark.integration

PROTOCOLS = {
    "task": builders.TaskBuilder,
    "plant": builders.PlantBuilder,
    "controller": builders.ControllerBuilder,
    "delay": builders.DelayBuilder,
    "event": builders.EventBuilder,
    "link": builders.LinkBuilder,
    "connector": builders.ConnectorBuilder,
    "plasticity": builders.PlasticityBuilder,
}


def _protocol(group: str, schema: type) -> type:
    if group == "stage":
        return builders.ReceiverBuilder if getattr(schema, "receiver", False) else builders.StageBuilder
    if group == "encoder":
        return builders.MossyEncoderBuilder if schema.role == "mossy" else builders.ClimbingEncoderBuilder
    return PROTOCOLS[group]


def _arguments(protocol: type) -> int:
    """How many positional arguments the protocol's ``__call__`` passes."""
    return len(inspect.signature(protocol.__call__).parameters) - 1  # self


def test_every_registered_builder_takes_its_groups_arguments():
    registry.load_plugins()
    checked = 0
    for group, reg in registry.GROUPS.items():
        for kind in reg.kinds():
            entry = reg[kind]
            n = _arguments(_protocol(group, entry.schema))
            try:
                inspect.signature(entry.resolve()).bind(*range(n))
            except TypeError as err:
                pytest.fail(f"{group} {kind} ({entry.plugin}): does not take {n} positional arguments: {err}")
            checked += 1
    assert checked >= 40  # the core's kinds and the paper plugins'


def test_the_protocols_name_the_arguments_the_builtin_comments_named():
    assert _arguments(builders.ReceiverBuilder) == 3 and _arguments(builders.StageBuilder) == 2
    assert _arguments(builders.ClimbingEncoderBuilder) == 6 and _arguments(builders.MossyEncoderBuilder) == 3
    assert _arguments(builders.EventBuilder) == 2 and _arguments(builders.LinkBuilder) == 3


def test_the_build_context_holds_every_part_and_a_generator_per_component(load):
    ctx = build_components(load(["+experiment=demo"]))
    assert isinstance(ctx, builders.BuildContext)
    assert ctx.plant.n_joints == 2 and ctx.task.steps_per_trial == 1000
    assert ctx.brain[0] is ctx.controller and ctx.receiver is not None and ctx.link is not None
    a, b = ctx.rng("plant").random(3), ctx.rng("plant").random(3)
    assert (a == b).all() and (a != ctx.rng("task").random(3)).all()
    assert (a == builders.component_rng(ctx.cfg.seed, "plant").random(3)).all()
