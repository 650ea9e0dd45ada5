"""Build a cerebx network in NEST 3.10 from ``network.npz`` beside this file (written by ``cerebx export``), drive
it with the input spike trains stored there and record every population's spikes.

    python nest_network.py --ms 1000                  # simulate 1 s, spikes to spikes_nest.npz
    python nest_network.py --ms 1000 --slice-ms 2     # the same in 2 ms slices (as cerebx's 500 Hz loop)
    python nest_network.py --connections              # synapse count and weight sum per projection (JSON)
    python nest_network.py --ms 1000 --weights        # with the plastic projections' weights (STDP)

Neurons: ``iaf_cond_exp`` (cerebx lif_cond; V_reset = E_L), inputs: ``spike_train_injector``. Every projection
has its own copy of its synapse model (``cx_NAME``) so that ``nest.GetConnections(synapse_model="cx_NAME")``
finds it; all-to-all projections are connected with cerebx's weight matrix, the others one-to-one over
cerebx's synapse list; inhibitory (GABA) weights are negative, as iaf_cond_exp takes them. NEST cannot emit a spike
at t = 0, so NEST runs ``t_offset_ms`` ahead: cerebx time t is NEST time t + t_offset_ms (``build`` simulates
that lead-in, in which nothing happens: every neuron is at rest until the first input), and recorded times are
cerebx times. Requires only numpy and nest.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import nest
import numpy as np

HERE = Path(__file__).resolve().parent


def load(path: Path = HERE / "network.npz") -> tuple[dict, dict[str, np.ndarray]]:
    with np.load(path, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files}
    return json.loads(str(arrays.pop("meta"))), arrays


def build(meta: dict, arrays: dict[str, np.ndarray], threads: int = 1, weights: dict | None = None) -> dict:
    """Populations, input spike trains and synapses; returns name -> NodeCollection. Ends at cerebx time 0.
    ``weights``: receives a weight recorder per plastic projection (every weight a spike transmits)."""
    nest.ResetKernel()
    nest.verbosity = nest.VerbosityLevel.ERROR
    nest.set(resolution=meta["resolution_ms"], local_num_threads=threads)
    off = meta["t_offset_ms"]
    pops = {}
    for name, p in meta["populations"].items():
        pops[name] = nest.Create(p["nest_model"], p["size"], params=p["nest_params"] or None)
    for name in meta["inputs"]:
        idx, t = arrays[f"in/{name}/idx"], arrays[f"in/{name}/t"] + off
        order = np.lexsort((t, idx))
        idx, t = idx[order], t[order]
        bounds = np.searchsorted(idx, np.arange(len(pops[name]) + 1))
        pops[name].set([{"spike_times": t[a:b].tolist()} for a, b in zip(bounds[:-1], bounds[1:])])
    for name, pr in meta["projections"].items():
        syn = f"cx_{name}"
        params = dict(pr["synapse_params"])
        if weights is not None and pr["synapse"] != "static_synapse":
            weights[name] = nest.Create("weight_recorder")
            params["weight_recorder"] = weights[name]
        nest.CopyModel(pr["synapse"], syn, params)
        pre, post = pops[pr["pre"]], pops[pr["post"]]
        w = arrays[f"w/{name}"].astype(np.float64) * pr["sign"]
        if pr["layout"] == "dense":
            nest.Connect(pre, post, "all_to_all", {"synapse_model": syn, "weight": np.ascontiguousarray(w.T),
                                                  "delay": pr["delay_ms"]})
        else:
            src = arrays[f"pre/{name}"].astype(np.int64) + pre[0].global_id
            tgt = arrays[f"post/{name}"].astype(np.int64) + post[0].global_id
            nest.Connect(src, tgt, "one_to_one", {"synapse_model": syn, "weight": w,
                                                  "delay": arrays.get(f"d/{name}", np.full(len(w), pr["delay_ms"]))})
    nest.Simulate(off)
    return pops


def record(pops: dict) -> dict:
    """A spike recorder on every population."""
    recs = {}
    for name, nodes in pops.items():
        recs[name] = nest.Create("spike_recorder")
        nest.Connect(nodes, recs[name])
    return recs


def run(ms: float, slice_ms: float = 0.0, mode: str = "simulate") -> tuple[float, float]:
    """Advance ``ms``: in one Simulate, or in ``slice_ms`` slices (``mode`` simulate: Simulate per slice; run:
    Run per slice inside one RunManager). Returns the wall and CPU time (s)."""
    t0, c0 = time.perf_counter(), time.process_time()
    if slice_ms <= 0:
        nest.Simulate(ms)
    elif mode == "run":
        with nest.RunManager():
            for _ in range(int(round(ms / slice_ms))):
                nest.Run(slice_ms)
    else:
        for _ in range(int(round(ms / slice_ms))):
            nest.Simulate(slice_ms)
    return time.perf_counter() - t0, time.process_time() - c0


def spikes(meta: dict, pops: dict, recs: dict) -> dict[str, np.ndarray]:
    """Recorded spikes as ``POP/idx`` (local index) and ``POP/t`` (cerebx time, ms)."""
    out = {}
    for name, rec in recs.items():
        ev = rec.get("events")
        out[f"{name}/idx"] = (np.asarray(ev["senders"]) - pops[name][0].global_id).astype(np.int32)
        out[f"{name}/t"] = np.asarray(ev["times"], dtype=np.float64) - meta["t_offset_ms"]
    return out


def plastic(meta: dict, pops: dict, weights: dict) -> dict[str, np.ndarray]:
    """Each plastic projection's weights as its spikes transmitted them (``wr/NAME/{pre,post,t,w}``, cerebx time
    of the presynaptic spike) and at the end (``w_end/NAME/{pre,post,w,d,kplus}``); local indices, cerebx's sign."""
    out = {}
    for name, rec in weights.items():
        pr = meta["projections"][name]
        pre0, post0 = pops[pr["pre"]][0].global_id, pops[pr["post"]][0].global_id
        ev = rec.get("events")
        out[f"wr/{name}/pre"] = (np.asarray(ev["senders"]) - pre0).astype(np.int32)
        out[f"wr/{name}/post"] = (np.asarray(ev["targets"]) - post0).astype(np.int32)
        out[f"wr/{name}/t"] = np.asarray(ev["times"], dtype=np.float64) - meta["t_offset_ms"]
        out[f"wr/{name}/w"] = np.asarray(ev["weights"], dtype=np.float64) * pr["sign"]
        conns = nest.GetConnections(synapse_model=f"cx_{name}")
        st = {k: np.asarray(conns.get(k)).reshape(-1) for k in ("source", "target", "weight", "delay", "Kplus")}
        out[f"w_end/{name}/pre"] = (st["source"] - pre0).astype(np.int32)
        out[f"w_end/{name}/post"] = (st["target"] - post0).astype(np.int32)
        out[f"w_end/{name}/w"] = st["weight"].astype(np.float64) * pr["sign"]
        out[f"w_end/{name}/d"] = st["delay"].astype(np.float64)
        out[f"w_end/{name}/kplus"] = st["Kplus"].astype(np.float64)
    return out


def connections(meta: dict) -> dict[str, dict[str, float]]:
    """Synapse count, weight sum (nS, cerebx's sign) and delay sum (ms) of every projection, as NEST holds them."""
    out = {}
    for name, pr in meta["projections"].items():
        conns = nest.GetConnections(synapse_model=f"cx_{name}")
        w = np.asarray(conns.get("weight"), dtype=np.float64).reshape(-1) if len(conns) else np.zeros(0)
        d = np.asarray(conns.get("delay"), dtype=np.float64).reshape(-1) if len(conns) else np.zeros(0)
        out[name] = {"synapses": len(conns), "weight_sum_nS": float(w.sum()) * pr["sign"],
                     "delay_sum_ms": float(d.sum())}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ms", type=float, default=0.0, help="simulated time (ms)")
    ap.add_argument("--slice-ms", type=float, default=0.0, help="advance in slices of this length (0: one call)")
    ap.add_argument("--mode", choices=("simulate", "run"), default="simulate",
                    help="slices as Simulate calls or as Run calls inside one RunManager")
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--npz", default=str(HERE / "network.npz"))
    ap.add_argument("--out", default=str(HERE / "spikes_nest.npz"), help="recorded spikes")
    ap.add_argument("--connections", action="store_true", help="print synapse counts and weight sums (JSON)")
    ap.add_argument("--weights", action="store_true", help="also record the plastic projections' weights (at every "
                    "transmitted spike and at the end) into the spikes file")
    args = ap.parse_args()
    meta, arrays = load(Path(args.npz))
    t0 = time.perf_counter()
    weights: dict = {}
    pops = build(meta, arrays, args.threads, weights if args.weights else None)
    build_s = time.perf_counter() - t0
    if args.connections:
        print(json.dumps(connections(meta)))
        return
    recs = record(pops)
    wall, cpu = run(args.ms, args.slice_ms, args.mode)
    np.savez(args.out, **spikes(meta, pops, recs), **plastic(meta, pops, weights))
    print(json.dumps({"build_s": build_s, "sim_s": wall, "sim_cpu_s": cpu, "ms": args.ms, "slice_ms": args.slice_ms,
                      "mode": args.mode, "threads": args.threads}))


if __name__ == "__main__":
    main()
