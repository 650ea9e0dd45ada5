"""A trained network's weights for ``cerebx export --weights RUN``: the learned state a run saved at its end
(``controller_state.npz``: the dense blocks ``net_dense_w`` and, with sparse learning rules, ``net_sp_w``),
written into the topology the run built (its network and seed, from the configuration the run recorded)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from cerebx import runfiles
from cerebx.errors import CerebxError
from cerebx.persistence.state import load_state_npz
from cerebx.recording.reader import read_metadata
from cerebx.schema.legacy import upgrade
from cerebx.snn.schema import NetworkConfig
from cerebx.snn.topology import Topology


def state_file(run: Path) -> Path:
    """The learned state of ``run``: a run folder's ``controller_state.npz``, or a state file itself."""
    path = Path(run) / runfiles.STATE if Path(run).is_dir() else Path(run)
    if not path.is_file():
        raise CerebxError(f"{run}: no learned state ({runfiles.STATE}): the run has not finished, or its "
                          "controller keeps no network")
    return path


def recorded_network(run: Path) -> tuple[dict, int]:
    """The network (plain dict) and seed of the configuration a run folder recorded in its log."""
    try:
        config = upgrade(json.loads(read_metadata(run)["config"]["json"]))
    except (CerebxError, KeyError, OSError, ValueError):
        raise CerebxError(f"{run}: its recorded configuration cannot be read (a run folder with run.mcap)") from None
    network = (config.get("controller") or {}).get("network")
    if not isinstance(network, dict):
        raise CerebxError(f"{run}: its controller has no network")
    return network, int(config.get("seed") or 0)


def load_learned(cfg: NetworkConfig, topo: Topology, run: Path) -> Path:
    """Write the weights ``run`` learned into ``topo`` (built from ``cfg`` with the run's seed); returns the
    state file. Refuses (one line) a state saved from a network of another structure. The saved arrays hold the
    projections' weights in the order the saving network listed them (recorded in the state's ``layout``; a
    state saved before that follows ``cfg``'s order): each projection's block is found by its name, so ``cfg``
    may list its projections in another order."""
    path = state_file(run)
    data, meta = load_state_npz(path, "SNN")
    if meta.get("fingerprint") != cfg.fingerprint():
        raise CerebxError(f"{path}: saved from network {meta.get('network')!r} of another structure than "
                          f"{cfg.name!r} (fingerprint {meta.get('fingerprint')}, not {cfg.fingerprint()})")
    order = list((meta.get("layout") or {}).get("projections") or cfg.projections)
    if sorted(order) != sorted(cfg.projections):
        raise CerebxError(f"{path}: its projections ({', '.join(order)}) are not those of {cfg.name!r}")
    dense_n = {d.name: d.n_pre * d.n_post for d in topo.dense}
    dense = data["net_dense_w"] if "net_dense_w" in data.files else None
    if dense is None or dense.shape != topo.dense_w.shape:
        raise CerebxError(f"{path}: its dense weights do not fit {cfg.name!r}")
    at = _blocks(order, dense_n)
    for d in topo.dense:
        topo.dense_w[d.w_off : d.w_off + dense_n[d.name]] = dense[at[d.name] : at[d.name] + dense_n[d.name]]
    if "net_sp_w" in data.files:
        sparse_n: dict[str, int] = {}
        for s in topo.sparse:
            sparse_n[s.name] = sparse_n.get(s.name, 0) + len(s.w)
        sp_w, total = data["net_sp_w"], sum(sparse_n.values())
        if len(sp_w) != total:
            raise CerebxError(f"{path}: its {len(sp_w)} sparse weights do not fit the {total} of {cfg.name!r}")
        at = _blocks(order, sparse_n)
        for s in topo.sparse:  # the pieces of a projection are consecutive, in the same order in both
            s.w[:] = sp_w[at[s.name] : at[s.name] + len(s.w)]
            at[s.name] += len(s.w)
    return path


def _blocks(order: list[str], length: dict[str, int]) -> dict[str, int]:
    """Where each projection's block starts in an array of blocks laid out in ``order`` (those in ``length``)."""
    starts = np.cumsum([0] + [length[n] for n in order if n in length])
    return {n: int(a) for n, a in zip([n for n in order if n in length], starts)}
