"""Build a cerebx network with PyNN 0.13 (pyNN.nest by default) from ``network.npz`` beside this file (written by
``cerebx export``), drive it with the input spike trains stored there and record every population's spikes.

    python pynn_network.py --ms 1000                  # spikes to spikes_pynn.npz
    python pynn_network.py --backend pyNN.neuron      # another PyNN backend

Neurons: ``IF_cond_exp`` (cerebx lif_cond; PyNN units: nF, uS, mV, ms), inputs: ``SpikeSourceArray``; synapses
static, or pair STDP (NEST's stdp_synapse) as an ``STDPMechanism`` on excitatory input. All-to-all
projections use ``AllToAllConnector`` with cerebx's weight matrix, the others ``FromListConnector`` over cerebx's
synapse list. As in the NEST script, the simulator runs ``t_offset_ms`` ahead of cerebx (no spike can be emitted at
t = 0); recorded times are cerebx times. Requires numpy and PyNN with a backend.
"""

from __future__ import annotations

import argparse
import importlib
import json
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def load(path: Path = HERE / "network.npz") -> tuple[dict, dict[str, np.ndarray]]:
    with np.load(path, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    return json.loads(str(arrays.pop("meta"))), arrays


def build(sim, meta: dict, arrays: dict[str, np.ndarray]) -> dict:
    """Populations (each recording its spikes), input spike trains and projections; returns name -> Population."""
    res = meta["resolution_ms"]
    lo = [p["delay_ms"] for p in meta["projections"].values()] or [res]
    hi = [p.get("max_delay_ms", p["delay_ms"]) for p in meta["projections"].values()] or [res]
    sim.setup(timestep=res, min_delay=min(lo), max_delay=max(hi))
    off = meta["t_offset_ms"]
    pops = {}
    for name, p in meta["populations"].items():
        cell = getattr(sim, p["pynn_model"])(**p["pynn_params"])
        pops[name] = sim.Population(p["size"], cell, label=name)
        if "v_rest" in p["pynn_params"]:  # PyNN starts V at -65 mV, cerebx at rest
            pops[name].initialize(v=p["pynn_params"]["v_rest"])
        pops[name].record("spikes")
    for name in meta["inputs"]:
        idx, t = arrays[f"in/{name}/idx"], arrays[f"in/{name}/t"] + off
        order = np.lexsort((t, idx))
        idx, t = idx[order], t[order]
        bounds = np.searchsorted(idx, np.arange(pops[name].size + 1))
        pops[name].set(spike_times=[sim.Sequence(t[a:b]) for a, b in zip(bounds[:-1], bounds[1:])])
    for name, pr in meta["projections"].items():
        pre, post = pops[pr["pre"]], pops[pr["post"]]
        w = arrays[f"w/{name}"].astype(np.float64) / 1000.0  # nS -> uS
        tau_minus = meta["populations"][pr["post"]]["nest_params"].get("tau_minus", 20.0)
        if pr["layout"] == "dense":
            conn, syn = sim.AllToAllConnector(), synapse(sim, name, pr, tau_minus, weight=w, delay=pr["delay_ms"])
        else:
            d = arrays.get(f"d/{name}", np.full(len(w), pr["delay_ms"]))
            rows = np.column_stack([arrays[f"pre/{name}"], arrays[f"post/{name}"], w, d])
            conn = sim.FromListConnector(rows, column_names=["weight", "delay"])
            syn = synapse(sim, name, pr, tau_minus)
        sim.Projection(pre, post, conn, syn, receptor_type=pr["pynn_receptor"], label=name)
    return pops


def synapse(sim, name: str, pr: dict, tau_minus: float, **kw):
    """The projection's PyNN synapse type: static, or NEST's stdp_synapse as an STDPMechanism (pair rule with
    Gütig weight dependence; the whole delay dendritic, as in NEST)."""
    if pr["synapse"] == "static_synapse":
        return sim.StaticSynapse(**kw)
    if pr["synapse"] == "stdp_synapse" and pr["sign"] > 0:
        q = pr["synapse_params"]
        mu = {"mu_plus": q["mu_plus"], "mu_minus": q["mu_minus"]}
        dependence = sim.GutigWeightDependence(w_min=0.0, w_max=q["Wmax"] / 1000.0, **mu)
        dependence.parameter_space.update(**mu)  # pyNN.nest 0.13's __init__ drops them (keeps 0.5)
        return sim.STDPMechanism(
            timing_dependence=sim.SpikePairRule(tau_plus=q["tau_plus"], tau_minus=tau_minus, A_plus=q["lambda"],
                                                A_minus=q["alpha"] * q["lambda"]),
            weight_dependence=dependence, dendritic_delay_fraction=1.0, **kw)
    raise SystemExit(f"projections.{name}: {pr['synapse']} on {pr['pynn_receptor']} input has no PyNN synapse type "
                     "in this script (use nest_network.py)")


def spikes(pops: dict, off: float) -> dict[str, np.ndarray]:
    out = {}
    for name, pop in pops.items():
        trains = pop.get_data("spikes").segments[0].spiketrains
        idx = np.concatenate([np.full(len(st), i, dtype=np.int32) for i, st in enumerate(trains)] or [np.zeros(0)])
        t = np.concatenate([np.asarray(st.magnitude, dtype=np.float64) for st in trains] or [np.zeros(0)])
        out[f"{name}/idx"], out[f"{name}/t"] = idx.astype(np.int32), t - off
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ms", type=float, default=0.0, help="simulated time (ms)")
    ap.add_argument("--backend", default="pyNN.nest", help="the PyNN backend module")
    ap.add_argument("--npz", default=str(HERE / "network.npz"))
    ap.add_argument("--out", default=str(HERE / "spikes_pynn.npz"), help="recorded spikes")
    args = ap.parse_args()
    sim = importlib.import_module(args.backend)
    meta, arrays = load(Path(args.npz))
    t0 = time.perf_counter()
    pops = build(sim, meta, arrays)
    build_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    sim.run(args.ms + meta["t_offset_ms"])
    wall = time.perf_counter() - t0
    np.savez(args.out, **spikes(pops, meta["t_offset_ms"]))
    sim.end()
    print(json.dumps({"build_s": build_s, "sim_s": wall, "ms": args.ms, "backend": args.backend}))


if __name__ == "__main__":
    main()
