"""Speed and memory of the spiking network alone (no plant), driven like the closed loop.

A synthetic sinusoidal joint state (desired and a lagging "actual") feeds the MF box encoder
and the CF error encoder every 2 ms, with plasticity on, so GC, PC, DCN activity, LTP and LTD
all run as they would in an experiment. The encoder output is computed before the timed loop
(the encoders are part of the controller's cost, not the network's), so ``rt_factor`` and
``us_per_step`` measure ``Network.step`` alone. As many steps again follow with the kernels timed part by
part (``per_step_us``, :meth:`~cerebx.snn.network.Network.start_profile`), with the mean number of granule
cells off rest per step (``listed_neurons``: how quiet the granule layer is; for a lumped population also the classes
it integrates instead, ``<population> (classes)``).
"""

from __future__ import annotations

import resource
import time
from typing import Any

import numpy as np

from cerebx.controllers.snn.schema import BoxEncoder, CFEncoder, ErrorGains
from cerebx.snn.encoders import ClimbingEncoder, MossyEncoder
from cerebx.snn.network import Network
from cerebx.snn.schema import NetworkConfig
from cerebx.snn.topology import I_COMPACT

STEP_S = 0.002


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _per_step_parts(net: Network, inputs: list[np.ndarray]) -> tuple[dict[str, float], dict[str, float]]:
    """Microseconds per step of each part of the network's kernels over ``inputs`` (``total``: the profiled
    steps' wall time, calls included), and the mean number of neurons off rest that each population with a list
    of them (``compact``: the granule cells) integrates per step."""
    net.step(inputs[0])  # the step kernel compiled (or loaded) before the clock starts
    net.start_profile()
    listed = np.zeros_like(net.n_act)
    classes = np.zeros_like(net.n_act)
    t0 = time.perf_counter()
    for x in inputs[1:]:
        net.step(x)
        listed += net.n_act
        classes += net.lp.n_cls - net.lp.n_free
    wall = time.perf_counter() - t0
    n = max(1, len(inputs) - 1)
    us = 1e6 / n
    out = {k: round(v * us, 2) for k, v in net.profile().items()}
    out["total"] = round(wall * us, 2)
    net.prof = None
    compact = np.flatnonzero(net.pop_i[:, I_COMPACT])
    lumped = set(net.lumped)
    return out, {net.topo.names[i]: round(float(listed[i]) / n, 1) for i in compact} | {
        f"{name} (classes)": round(float(classes[net.topo.index[name]]) / n, 1) for name in sorted(lumped)}


def bench_network(network_cfg: NetworkConfig, seconds: float = 3.0, warmup: float = 0.5,
                  parallel: bool = False, seed: int = 0) -> dict[str, Any]:
    """Build the network, run ``warmup`` then ``seconds`` of simulated time; report speed."""
    t0 = time.perf_counter()
    net = Network(network_cfg, parallel=parallel)
    io = network_cfg.io
    mf_sl, cf_sl = net.index(io.mossy), net.index(io.climbing)
    n_mf, n_cf = mf_sl.stop - mf_sl.start, cf_sl.stop - cf_sl.start
    F = 10 if n_mf % 40 == 0 and n_mf // 40 > 0 else 5
    joints = n_mf // (4 * F)
    mf = MossyEncoder(BoxEncoder(fibers_per_signal=F), -np.ones((joints, 4)), np.ones((joints, 4)))
    gains = ErrorGains()
    cf = ClimbingEncoder(CFEncoder(), joints, n_cf // joints, gains.kpos, gains.kvel,
                         np.random.default_rng(seed))
    phase = np.arange(joints)
    net.step(np.zeros(0, np.int32))  # JIT compile / cache load counts as build
    build_s = time.perf_counter() - t0

    def drive(k: int) -> np.ndarray:
        t = k * STEP_S
        w = np.pi  # one 2 s period
        q_des, qd_des = np.sin(w * t + phase), np.cos(w * t + phase)
        q, qd = np.sin(w * (t - 0.05) + phase), np.cos(w * (t - 0.05) + phase)
        e = cf.error(q_des, q, qd_des, qd)
        return np.concatenate([mf.active(q_des, q, qd_des, qd) + mf_sl.start,
                               cf.active(e) + cf_sl.start]).astype(np.int32)

    n_warm, n_run = int(round(warmup / STEP_S)), int(round(seconds / STEP_S))
    for k in range(n_warm):
        net.step(drive(k))
    # the encoders are not part of the network: their spikes are computed before the timed loop
    inputs = [drive(k) for k in range(n_warm, n_warm + n_run)]
    edges = np.array([net.index(name).stop for name in net.topo.names])
    counts_arr = np.zeros(len(edges) + 1, dtype=np.int64)
    bounds = [(name, net.index(name)) for name in net.topo.names]
    t1 = time.perf_counter()
    for k in range(n_run):
        sp = net.step(inputs[k])
        if sp.idx.size:
            counts_arr += np.bincount(np.searchsorted(edges, sp.idx, side="right"), minlength=len(edges) + 1)
    wall = time.perf_counter() - t1
    counts = {name: int(counts_arr[i]) for i, name in enumerate(net.topo.names)}
    parts, listed = _per_step_parts(net, [drive(k) for k in range(n_warm + n_run, n_warm + 2 * n_run)])
    return {
        "network": network_cfg.name,
        "neurons": net.n_neurons,
        "synapses": net.n_synapses,
        "plastic_synapses": net.n_plastic,
        "build_s": round(build_s, 3),
        "sim_s": seconds,
        "wall_s": round(wall, 3),
        "rt_factor": round(seconds / wall, 2),
        "us_per_step": round(wall / n_run * 1e6, 1),
        "per_step_us": parts,
        "listed_neurons": listed,
        "threads": net.n_threads,
        "parallel": parallel,
        "rates_hz": {name: round(counts[name] / seconds / (sl.stop - sl.start), 2)
                     for name, sl in bounds if net.topo.kind[net.topo.index[name]] != 0},
        "ltd_pf_spikes_dropped": int(net.pf_lost.sum()),
        "peak_rss_mb": round(peak_rss_mb(), 1),
    }
