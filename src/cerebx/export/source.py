"""The network a ``cerebx export`` or ``cerebx crosscheck`` command names: a network preset (``conf/network`` of
cerebx or a plugin, e.g. ``full``, ``thesis_ch3``), or a YAML file holding a network (its ``controller.network``
when it is a whole experiment, e.g. a run's ``config.yaml`` or ``cerebx validate``'s output)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from cerebx.errors import CerebxError, ConfigError
from cerebx.snn.schema import NetworkConfig


def load_network(source: str, overrides: list[str] | None = None) -> NetworkConfig:
    """The validated network ``source`` names (``overrides``: ``key=value`` as for ``cerebx run`` on a preset, e.g.
    ``controller.network.projections.pf_pc.weight_nS=1.0``; on a file, keys of its network, e.g. ``dt_ms=0.1``)."""
    path = Path(source)
    if path.suffix in (".yaml", ".yml") or path.is_file():
        try:
            doc = yaml.safe_load(path.read_text())
        except OSError as err:
            raise CerebxError(f"{source}: cannot be read ({err.strerror or err})") from None
        except yaml.YAMLError as err:
            raise CerebxError(f"{source}: not YAML ({str(err).splitlines()[0]})") from None
        net = _network_part(doc)
        if net is None:
            raise CerebxError(f"{source}: holds no network (populations and projections, or controller.network)")
        for item in overrides or []:
            _override(net, item, source)
        return _validate(_sized(net, doc if isinstance(doc, dict) else {}, source), source)
    from cerebx.config import compose, through_references, to_plain  # Hydra only when a preset is composed

    args = ["+task=circle", f"network={source}", *(overrides or [])]
    try:
        plain = to_plain(compose(args))
    except ConfigError as err:
        raise CerebxError(err.problems[0]) from None
    net = _network_part(plain)
    if net is None:
        raise CerebxError(f"{source}: the composed controller has no network")
    try:
        return _validate(_sized(net, plain, f"network={source}"), f"network={source}")
    except CerebxError:
        added = [o for o in args if o.startswith("+") and "." in o.split("=", 1)[0]]
        problems = through_references(added, None, args) if added else []
        if problems:
            raise CerebxError(problems[0]) from None
        raise


def _sized(net: dict, experiment: dict, where: str) -> dict:
    """A network written per joint (``per_joint``, snn/sizing.py) sized for the experiment's plant, as a run
    sizes it; a bare network file with ``per_joint`` names no plant and is refused."""
    from cerebx.snn.sizing import KEY, plant_joints, sized_network

    if KEY not in net:
        return net
    joints = plant_joints(experiment)
    if joints is None:
        raise CerebxError(f"{where}: per_joint: the network is sized from a plant's joints; give a whole experiment "
                          "(e.g. a run's config.yaml) or a network preset")
    try:
        return sized_network(net, joints)
    except ValueError as err:
        raise CerebxError(f"{where}: {err}") from None


def _override(net: dict, item: str, source: str) -> None:
    """Apply ``dotted.key=value`` (value read as YAML) to a file's network, e.g. ``dt_ms=0.1``."""
    key, eq, text = item.partition("=")
    *parents, last = key.split(".")
    node: Any = net
    for k in parents:
        node = node.get(k) if isinstance(node, dict) else None
    if not eq or not key or not isinstance(node, dict):
        raise CerebxError(f"{source}: override {item!r}: not key=value with a key of the network (e.g. dt_ms=0.1)")
    node[last] = yaml.safe_load(text)


def _network_part(doc: Any) -> dict | None:
    if not isinstance(doc, dict):
        return None
    if "populations" in doc and "projections" in doc:
        return doc
    ctrl = doc.get("controller")
    net = ctrl.get("network") if isinstance(ctrl, dict) else None
    return net if isinstance(net, dict) else None


def validate_network(net: dict, where: str) -> NetworkConfig:
    """``net`` validated; a problem is one line ``where: location: message``."""
    return _validate(net, where)


def _validate(net: dict, where: str) -> NetworkConfig:
    try:
        return NetworkConfig.model_validate(net)
    except ValidationError as err:
        e = err.errors()[0]
        loc = ".".join(str(x) for x in e["loc"])
        raise CerebxError(f"{where}: {loc + ': ' if loc else ''}{e['msg']}") from None
