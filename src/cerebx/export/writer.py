"""Write a network for NEST or PyNN: ``network.npz`` (cerebx's exact synapses, neuron parameters, input spike
trains) and a standalone script beside it that builds the network from it (``scripts/nest_network.py``,
``scripts/pynn_network.py``, copied as they are).

Synapses come from the topology cerebx builds (``snn/topology.py``), never from a re-draw: an all-to-all
projection is its ``[n_pre, n_post]`` weight matrix (``w/NAME``), every other one its synapse list (``pre/NAME``,
``post/NAME``, ``w/NAME``; indices local to the populations). Input spike trains are ``in/POP/idx`` (local fibre)
and ``in/POP/t`` (ms, cerebx time). NEST and PyNN cannot emit a spike at t = 0 (cerebx's first input instant), so
the scripts run NEST ``t_offset_ms`` ahead of cerebx: a spike at cerebx time t is emitted at t + t_offset_ms, and
the spike times they write are cerebx times again (exact: every neuron is at rest until the first input).
"""

from __future__ import annotations

import json
import shutil
from dataclasses import asdict
from pathlib import Path

import numpy as np

from cerebx.errors import CerebxError
from cerebx.export.mapping import Plan, plan
from cerebx.snn.schema import NetworkConfig
from cerebx.snn.topology import Topology, build_topology

SCRIPTS = Path(__file__).parent / "scripts"
TARGETS = {"nest": "nest_network.py", "pynn": "pynn_network.py"}
NPZ = "network.npz"
MAX_SLICE_MS = 2.0


def synapse_tables(topo: Topology, weights: dict[str, np.ndarray] | None = None) -> dict[str, dict[str, np.ndarray]]:
    """Every projection's synapses as built: ``{"w": [n_pre, n_post]}`` for an all-to-all one, else
    ``{"pre", "post", "w", "d"}`` (local indices, float32 nS, each synapse's delay in ms: a projection whose delays
    differ is built as one table per delay, joined here). ``weights``: all-to-all matrices to use instead of the
    initial ones (e.g. a trained network's)."""
    out: dict[str, dict[str, np.ndarray]] = {}
    lo = dict(zip(topo.names, topo.lo.tolist()))
    for d in topo.dense:
        w = topo.dense_block(d) if weights is None or d.name not in weights else weights[d.name]
        out[d.name] = {"w": np.asarray(w, dtype=np.float32)}
    pieces: dict[str, list[dict[str, np.ndarray]]] = {}
    for s in topo.sparse:
        post_pop = topo.cfg.projections[s.name].post
        pre = np.repeat(np.arange(s.n_pre, dtype=np.int32), np.diff(s.ptr))
        pieces.setdefault(s.name, []).append({
            "pre": pre, "post": (s.post - lo[post_pop]).astype(np.int32), "w": s.w.astype(np.float32),
            "d": np.full(len(pre), s.delay * topo.dt_ms, dtype=np.float64)})
    for name, parts in pieces.items():
        out[name] = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    return out


def count_and_sum(tables: dict[str, dict[str, np.ndarray]]) -> dict[str, tuple[int, float]]:
    """(synapses, weight sum in nS) per projection."""
    return {name: (int(t["w"].size), float(t["w"].sum(dtype=np.float64))) for name, t in tables.items()}


def export(cfg: NetworkConfig, out: Path, to: tuple[str, ...] = ("nest",), static: bool = False,
           approximate: bool = False, inputs: dict[str, tuple[np.ndarray, np.ndarray]] | None = None,
           weights: dict[str, np.ndarray] | None = None, topo: Topology | None = None) -> Plan:
    """Write ``out/network.npz`` and the script of each target in ``to``; returns the :class:`Plan`. Refuses
    (:class:`CerebxError`, one line naming the kinds) what the targets cannot express. ``inputs``: input
    population -> (local fibre indices, spike times in ms) to drive the network with."""
    p = plan(cfg, static=static, approximate=approximate)
    if p.problems:
        raise CerebxError(f"cerebx export: {cfg.name}: cannot be expressed in NEST/PyNN: " + "; ".join(p.problems))
    bad = [t for t in to if t not in TARGETS]
    if bad:
        raise CerebxError(f"cerebx export: --to: unknown target {bad[0]!r} (choose from {', '.join(TARGETS)})")
    topo = topo if topo is not None else build_topology(cfg)
    tables = synapse_tables(topo, weights)
    arrays: dict[str, np.ndarray] = {}
    projections = {}
    for name, pp in p.projections.items():
        t = tables[name]
        for key, a in t.items():
            arrays[f"{key}/{name}"] = a
        delays = t["d"] if "d" in t else np.array([pp.delay_ms])
        projections[name] = {**asdict(pp), "layout": "dense" if "pre" not in t else "list", "n": int(t["w"].size),
                             "delay_ms": float(delays.min()) if delays.size else pp.delay_ms,
                             "max_delay_ms": float(delays.max()) if delays.size else pp.delay_ms}
    inputs = inputs or {}
    for pop, (idx, times) in inputs.items():
        if pop not in p.populations or p.populations[pop].kind != "input":
            raise CerebxError(f"cerebx export: inputs: {pop!r} is not an input population of {cfg.name}")
        arrays[f"in/{pop}/idx"] = np.asarray(idx, dtype=np.int32)
        arrays[f"in/{pop}/t"] = np.asarray(times, dtype=np.float64)
    meta = {
        "name": cfg.name, "resolution_ms": p.resolution_ms, "t_offset_ms": p.resolution_ms,
        "populations": {k: asdict(v) for k, v in p.populations.items()},
        "projections": projections, "inputs": sorted(inputs), "dropped": p.dropped, "notes": p.notes,
    }
    arrays["meta"] = np.array(json.dumps(meta))
    try:
        out.mkdir(parents=True, exist_ok=True)
        np.savez(out / NPZ, **arrays)
        for target in to:
            shutil.copyfile(SCRIPTS / TARGETS[target], out / TARGETS[target])
    except OSError as err:
        raise CerebxError(f"{out}: cannot be written ({err.strerror or err})") from None
    return p


def read_npz(path: Path) -> tuple[dict, dict[str, dict[str, np.ndarray]]]:
    """(meta, synapse tables) of an exported ``network.npz``."""
    with np.load(path, allow_pickle=False) as data:
        meta = json.loads(str(data["meta"]))
        tables: dict[str, dict[str, np.ndarray]] = {}
        for key in data.files:
            kind, _, name = key.partition("/")
            if kind in ("w", "pre", "post", "d"):
                tables.setdefault(name, {})[kind] = data[key]
    return meta, tables
