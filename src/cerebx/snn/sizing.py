"""A network sized from the plant's joint count (docs/models.md#network-sizing).

A network preset may give its per-joint populations as ``per_joint: {population: cells per joint}`` instead of
sizes for one arm. Before validation, the spiking controller's ``complete`` hook turns it into the network
for the experiment's plant (:func:`sized_network`): each listed population gets ``cells x joints`` neurons in
one microcomplex per joint, ``joint_combinations`` rules get the joint count, and every projection's
``synapses`` is what its rule gives for the new sizes (the expectation, rounded, for a random rule). The
recorded config holds the result, so a run still shows every size it ran with.

``reference_joints`` (optional) keeps each cell's synaptic drive when an all-to-all projection from a
per-joint population changes size with the joint count (one active state per joint reaches every post cell):
its weight, weight range and plasticity steps are scaled by reference_joints / joints.
"""

from __future__ import annotations

import copy
from typing import Any

from cerebx import registry
from cerebx.snn.schema import _rule_count

KEY = "per_joint"
REFERENCE = "reference_joints"
_SCALED_STEPS = ("ltp_nS", "ltd_nS", "fixed_nS", "kernel_nS")


def plant_joints(experiment: dict[str, Any]) -> int | None:
    """The joint count of the experiment's plant (its schema validated from the plain data), or None when the
    plant is not (yet) a valid config: validation then reports the plant's own problem."""
    plant = experiment.get("plant")
    kind = plant.get("kind") if isinstance(plant, dict) else None
    if not isinstance(kind, str) or kind not in registry.plants:
        return None
    try:
        return int(registry.plants[kind].schema.model_validate(plant).n_joints)
    except (ValueError, TypeError):
        return None


def sized_network(network: dict[str, Any], n_joints: int) -> dict[str, Any]:
    """``network`` (plain data) with its ``per_joint`` populations sized for ``n_joints`` joints; unchanged
    when it has no ``per_joint`` key. A ``per_joint`` entry naming no population, or not a positive number of
    cells, is a ``ValueError`` (a validation error of the experiment); other values the schema refuses are left
    for validation to report."""
    if not isinstance(network, dict) or KEY not in network:
        return network
    out = copy.deepcopy(network)
    per_joint = out.pop(KEY)
    reference = out.pop(REFERENCE, None)
    pops = out.get("populations")
    if not isinstance(per_joint, dict) or not isinstance(pops, dict):
        out[KEY] = per_joint  # refused by the schema, with its path
        return out
    for name, cells in per_joint.items():
        if not isinstance(pops.get(name), dict):
            raise ValueError(f"controller.network.per_joint.{name}: no population {name!r} in the network")
        if not isinstance(cells, int) or isinstance(cells, bool) or cells < 1:
            raise ValueError(f"controller.network.per_joint.{name}: {cells!r} is not a positive whole number of cells")
        pops[name] = {**pops[name], "size": cells * n_joints, "microcomplexes": n_joints}
    for proj in (out.get("projections") or {}).values():
        if not isinstance(proj, dict):
            continue
        rule = proj.get("rule")
        if isinstance(rule, dict) and rule.get("kind") == "joint_combinations":
            proj["rule"] = {**rule, "joints": n_joints}
        count = _count(proj, pops)
        if count is not None:
            proj["synapses"] = count
        if reference and _scaled(proj, per_joint):
            _scale(proj, reference / n_joints)
    return out


def _count(proj: dict[str, Any], pops: dict[str, Any]) -> int | None:
    pre, post = pops.get(proj.get("pre")), pops.get(proj.get("post"))
    if not (isinstance(pre, dict) and isinstance(post, dict)):
        return None
    try:
        rule = proj.get("rule")
        parsed = registry.connectors[rule["kind"]].schema.model_validate(rule)
        got = _rule_count(parsed, int(pre["size"]), int(post["size"]), "", [], proj.get("pre") == proj.get("post"))
    except (ValueError, TypeError, KeyError):
        return None
    if isinstance(got, tuple):
        return int(round(got[0]))
    return got


def _scaled(proj: dict[str, Any], per_joint: dict[str, Any]) -> bool:
    rule = proj.get("rule")
    return (isinstance(rule, dict) and rule.get("kind") == "all_to_all" and proj.get("pre") in per_joint
            and proj.get("post") in per_joint and not proj.get("teaching", False))


def _scale(proj: dict[str, Any], f: float) -> None:
    if isinstance(proj.get("weight_nS"), (int, float)):
        proj["weight_nS"] = round(proj["weight_nS"] * f, 9)
    rng = proj.get("weight_range_nS")
    if isinstance(rng, (list, tuple)) and len(rng) == 2:
        proj["weight_range_nS"] = [round(x * f, 9) for x in rng]
    rule = proj.get("plasticity")
    if isinstance(rule, dict):
        proj["plasticity"] = {k: round(v * f, 12) if k in _SCALED_STEPS and isinstance(v, (int, float)) else v
                              for k, v in rule.items()}


def broadcast_per_joint(values: Any, n_joints: int) -> Any:
    """A one-entry per-joint list as ``n_joints`` entries (a gain written once for every joint); anything else
    unchanged."""
    if isinstance(values, (list, tuple)) and len(values) == 1:
        return [values[0]] * n_joints
    return values
