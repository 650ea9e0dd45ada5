"""Configurations recorded by earlier versions, read as today's, so an older run still counts as the same
experiment (reports reuse it, ``resume`` continues it) when its recorded data would be the same today.

Two changes are undone here: the spiking network used to be a top-level ``network`` key of every experiment
(it now belongs to the controller that runs it: any controller kind whose schema has a ``network`` field,
and nothing else), and options added since a run was recorded are filled in with the value that does what
the run did (each controller kind and plasticity kind lists them in ``added_without_effect``, the experiment
schema its own keys)."""

from __future__ import annotations

import copy
from typing import Any

from cerebx import registry
from cerebx.schema.experiment import ADDED_WITHOUT_EFFECT


def _schema(part: Any) -> Any:
    kind = part.get("kind") if isinstance(part, dict) else None
    return registry.controllers[kind].schema if isinstance(kind, str) and kind in registry.controllers else None


def _parts(controller: dict[str, Any]) -> list[dict[str, Any]]:
    parts = controller.get("parts")
    return [p for p in parts if isinstance(p, dict)] if isinstance(parts, list) else [controller]


def _fill(part: dict[str, Any], dotted: str, value: Any) -> None:
    *parents, last = dotted.split(".")
    node: Any = part
    for key in parents:
        node = node.get(key) if isinstance(node, dict) else None
    if isinstance(node, dict) and last not in node:
        node[last] = copy.deepcopy(value)


def _upgrade_link(link: Any) -> None:
    """A real link recorded before its newer fields: filled in by its kind's schema (``upgrade_recorded``)."""
    kind = link.get("kind") if isinstance(link, dict) else None
    if not isinstance(kind, str) or kind not in registry.links:
        return
    fill = getattr(registry.links[kind].schema, "upgrade_recorded", None)
    if callable(fill):
        fill(link)


def upgrade(config: dict[str, Any]) -> dict[str, Any]:
    """A copy of a recorded experiment config in today's layout (unchanged when it already is)."""
    registry.load_plugins()
    out = copy.deepcopy(config)
    for key, value in ADDED_WITHOUT_EFFECT.items():
        out.setdefault(key, copy.deepcopy(value))
    _upgrade_link(out.get("link"))
    if isinstance(out.get("recording"), dict):
        out["recording"].setdefault("trials", None)  # recording.trials: every trial, as before windows
    network = out.pop("network", None)
    controller = out.get("controller")
    if not isinstance(controller, dict):
        return out
    for part in _parts(controller):
        schema = _schema(part)
        if schema is None:
            continue
        if network is not None and "network" in schema.model_fields and "network" not in part:
            part["network"] = copy.deepcopy(network)
        for dotted, value in schema.added_without_effect.items():
            _fill(part, dotted, value)
        _fill_plasticity(part.get("network"))
    return out


def _fill_plasticity(network: Any) -> None:
    """Options added to a plasticity kind since a run was recorded (its schema's ``added_without_effect``)."""
    projections = network.get("projections") if isinstance(network, dict) else None
    for proj in projections.values() if isinstance(projections, dict) else ():
        rule = proj.get("plasticity") if isinstance(proj, dict) else None
        kind = rule.get("kind") if isinstance(rule, dict) else None
        if isinstance(kind, str) and kind in registry.plasticity_rules:
            for dotted, value in getattr(registry.plasticity_rules[kind].schema, "added_without_effect", {}).items():
                _fill(rule, dotted, value)
