"""Run a network in cerebx and in NEST on the same input spike trains and compare what they compute.

The input is seeded (:func:`seeded_inputs`): mossy fibres box-coded from slow sinusoids (the active fibre of each
signal fires every 2 ms step, as the encoder drives them), climbing fibres Bernoulli per 2 ms step. cerebx runs
in-process (:func:`run_cerebx`, one thread, plasticity off); NEST runs the exported script
(``scripts/nest_network.py``) in a subprocess of a Python that has NEST (:func:`run_nest`). ``layer`` keeps only some
populations simulated: the others become input fibres replaying the spikes cerebx's whole network produced, so
the thesis network's Purkinje/DCN layer is compared without simulating its 60,000 granule cells in NEST.

:func:`compare` gives one row per simulated population: rates, the relative rate difference, the correlation of
per-neuron spike counts, the fraction of spikes matched within a window, and for the output population the
correlation of the per-joint output (agonist minus antagonist spikes in 20 ms bins).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cerebx.errors import CerebxError
from cerebx.export.drift import Drift, drift_row, nest_weights_at
from cerebx.export.mapping import plan
from cerebx.export.writer import TARGETS, export, synapse_tables
from cerebx.snn.schema import JointCombinations, NetworkConfig
from cerebx.snn.topology import build_topology

Spikes = dict[str, tuple[np.ndarray, np.ndarray]]
"""Population -> (local neuron index, spike time in ms)."""

STEP_MS = 2.0
FIBERS_PER_SIGNAL = 5
"""Mossy fibres per box-coded signal where no joint_combinations projection of the network says how many."""


def seeded_inputs(cfg: NetworkConfig, ms: float, seed: int = 0, cf_rate_hz: float = 5.0) -> Spikes:
    """Input spike trains of ``ms`` milliseconds (spikes at 2 ms step starts; none in the first step, so a
    recording starts from rest as a run does): the mossy population box-coded (groups of ``fibers_per_signal``
    fibres, else of :data:`FIBERS_PER_SIGNAL`, one active per group, following a sinusoid of random period
    0.5-2 s and phase), the climbing population Bernoulli at ``cf_rate_hz``."""
    rng = np.random.default_rng(seed)
    n_steps = int(round(ms / STEP_MS))
    t = np.arange(1, n_steps) * STEP_MS
    out: Spikes = {}
    mf = cfg.populations[cfg.io.mossy].size
    group = next((p.rule.fibers_per_signal for p in cfg.projections.values()
                  if p.pre == cfg.io.mossy and isinstance(p.rule, JointCombinations)), min(mf, FIBERS_PER_SIGNAL))
    n_groups = mf // group
    period = rng.uniform(500.0, 2000.0, n_groups)
    phase = rng.uniform(0, 2 * np.pi, n_groups)
    x = 0.5 + 0.5 * np.sin(2 * np.pi * t[:, None] / period + phase)  # [steps, groups]
    active = np.minimum((x * group).astype(np.int64), group - 1) + np.arange(n_groups) * group
    out[cfg.io.mossy] = (active.reshape(-1).astype(np.int32), np.repeat(t, n_groups))
    n_cf = cfg.populations[cfg.io.climbing].size
    fire = rng.random((len(t), n_cf)) < cf_rate_hz * STEP_MS / 1000.0
    steps, idx = np.nonzero(fire)
    out[cfg.io.climbing] = (idx.astype(np.int32), t[steps])
    return out


def run_cerebx(cfg: NetworkConfig, inputs: Spikes, ms: float, sliced: bool = True,
               sparse_w: np.ndarray | None = None, cpu: list[float] | None = None, learn: bool = False,
               weights: dict[str, np.ndarray] | None = None) -> tuple[Spikes, float]:
    """cerebx on one thread, plasticity off unless ``learn``, driven by ``inputs`` (every spike at a 2 ms step
    start); returns every population's spikes and the wall time of the run (build excluded). ``sliced``: one
    ``step`` call per 2 ms (the 500 Hz loop's pace); otherwise one ``step_packed`` call for the whole run (spike
    times then at step resolution are not recorded: only used for timing). ``sparse_w``: the weights of the sparse
    projections (their synapses in topology order) instead of the configured ones; ``cpu`` receives the run's CPU
    time; ``weights`` the sparse projections' weights at the end (synapse table order, :mod:`.writer`)."""
    from cerebx.snn.network import Network, pack

    net = Network(cfg, parallel=False)
    net.learn = learn
    if sparse_w is not None:
        net.sp_w[:] = sparse_w
    n_steps = int(round(ms / STEP_MS))
    topo = net.topo
    per_step: list[list[np.ndarray]] = [[] for _ in range(n_steps)]
    for pop, (idx, t) in inputs.items():
        steps = np.rint(np.asarray(t) / STEP_MS).astype(np.int64)
        if np.any(np.abs(steps * STEP_MS - t) > 1e-9):
            raise CerebxError(f"crosscheck: inputs of {pop}: cerebx takes input spikes at 2 ms step starts only")
        lo = int(topo.lo[topo.index[pop]])
        for s in np.unique(steps[steps < n_steps]):
            per_step[s].append(idx[steps == s].astype(np.int32) + lo)
    step_inputs = [np.sort(np.concatenate(x)) if x else np.zeros(0, np.int32) for x in per_step]
    dt = cfg.dt_ms
    if not sliced:
        flat, off = pack(step_inputs)
        t0, c0 = time.perf_counter(), time.process_time()
        net.step_packed(flat, off)
        if cpu is not None:
            cpu.append(time.process_time() - c0)
        return {}, time.perf_counter() - t0
    ids, times = [], []
    t0, c0 = time.perf_counter(), time.process_time()
    for s, x in enumerate(step_inputs):
        sp = net.step(x)
        if len(sp.idx):
            ids.append(sp.idx.copy())
            times.append((s * net.n_sub + sp.sub.astype(np.float64)) * dt)
    wall = time.perf_counter() - t0
    if cpu is not None:
        cpu.append(time.process_time() - c0)
    gid = np.concatenate(ids) if ids else np.zeros(0, np.int64)
    gt = np.concatenate(times) if times else np.zeros(0)
    out: Spikes = {}
    for name in topo.names:
        lo, hi = int(topo.lo[topo.index[name]]), int(topo.hi[topo.index[name]])
        m = (gid >= lo) & (gid < hi)
        out[name] = ((gid[m] - lo).astype(np.int32), gt[m])
    for pop, spikes in inputs.items():
        out[pop] = spikes
    if weights is not None:
        for name in dict.fromkeys(piece.name for piece in topo.sparse):
            weights[name] = net.sparse_weights(name)[2]
    return out, wall


def nest_python() -> str:
    """A Python that imports nest: ``$CEREBX_NEST_PYTHON``, else this one if it has NEST."""
    env = os.environ.get("CEREBX_NEST_PYTHON")
    if env:
        return env
    try:
        import importlib.util

        if importlib.util.find_spec("nest") is not None:
            return sys.executable
    except (ImportError, ValueError):
        pass
    raise CerebxError("crosscheck: NEST is not importable here: pip install 'cerebx[nest]' or set "
                      "CEREBX_NEST_PYTHON to a Python that has it")


def run_nest(folder: Path, ms: float, slice_ms: float = 0.0, mode: str = "simulate", threads: int = 1,
             python: str | None = None, weights: dict[str, np.ndarray] | None = None) -> tuple[Spikes, dict[str, Any]]:
    """Run the exported NEST script in ``folder``; returns its spikes and its timing line. ``weights`` receives
    the plastic projections' recorded weights (``wr/...``, ``w_end/...``: ``nest_network.py --weights``)."""
    script = folder / TARGETS["nest"]
    out = folder / f"spikes_nest_{mode}_{slice_ms:g}.npz"
    cmd = [python or nest_python(), str(script), "--ms", str(ms), "--slice-ms", str(slice_ms), "--mode", mode,
           "--threads", str(threads), "--out", str(out)] + (["--weights"] if weights is not None else [])
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        tail = (proc.stderr.strip().splitlines() or ["failed"])[-1]
        raise CerebxError(f"crosscheck: NEST run failed: {tail}")
    timing = json.loads(proc.stdout.strip().splitlines()[-1])
    with np.load(out) as data:
        names = {k[: -len("/idx")] for k in data.files if k.endswith("/idx") and k.count("/") == 1}
        spikes = {n: (data[f"{n}/idx"], data[f"{n}/t"]) for n in names}
        if weights is not None:
            weights.update({k: data[k] for k in data.files if k.startswith(("wr/", "w_end/"))})
    return spikes, timing


def layer_config(cfg: NetworkConfig, layer: list[str]) -> NetworkConfig:
    """``cfg`` with only the populations in ``layer`` simulated: every other becomes input fibres, and the
    projections onto those are left out."""
    d = cfg.model_dump()
    unknown = [p for p in layer if p not in d["populations"]]
    if unknown:
        raise CerebxError(f"crosscheck: --layer: unknown population {unknown[0]!r}")
    for name, pop in d["populations"].items():
        if name not in layer:
            pop["neuron"] = {"kind": "input"}
    d["projections"] = {k: p for k, p in d["projections"].items() if p["post"] in layer}
    d["name"] = f"{cfg.name}_{'_'.join(layer)}"
    return NetworkConfig.model_validate(d)


def without(cfg: NetworkConfig, projections: list[str]) -> NetworkConfig:
    d = cfg.model_dump()
    for k in projections:
        d["projections"].pop(k, None)
    return NetworkConfig.model_validate(d)


@dataclass
class Row:
    population: str
    neurons: int
    rate_cerebx_hz: float
    rate_nest_hz: float
    rate_diff: float  # (nest - cerebx) / cerebx
    count_corr: float
    matched_step: float  # spikes with a partner in the other simulator on the same grid step, of all spikes
    matched: float  # the same within the window
    output_corr: float | None = None


def _matched(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray], n: int, window: float) -> float:
    """Fraction of all spikes of a and b whose neuron fired in the other within ``window`` ms."""
    hits, total = 0, len(a[1]) + len(b[1])
    if total == 0:
        return 1.0
    for (ia, ta), (ib, tb) in ((a, b), (b, a)):
        for i in np.unique(ia):
            x, y = np.sort(ta[ia == i]), np.sort(tb[ib == i])
            if len(y) == 0:
                continue
            k = np.clip(np.searchsorted(y, x), 1, len(y) - 1) if len(y) > 1 else np.zeros(len(x), np.int64)
            near = np.minimum(np.abs(y[k] - x), np.abs(y[np.maximum(k - 1, 0)] - x))
            hits += int(np.sum(near <= window + 1e-9))
    return hits / total


def _output(sp: tuple[np.ndarray, np.ndarray], n: int, joints: int, ms: float, bin_ms: float = 20.0) -> np.ndarray:
    """Per joint, agonist (first half of the joint's block) minus antagonist spikes per bin: [joints, bins]."""
    idx, t = sp
    per = n // joints
    joint, half = idx // per, (idx % per) >= per // 2
    bins = np.minimum((t / bin_ms).astype(np.int64), int(ms / bin_ms) - 1)
    out = np.zeros((joints, int(ms / bin_ms)))
    np.add.at(out, (joint, bins), np.where(half, -1.0, 1.0))
    return out


def _corr(x: np.ndarray, y: np.ndarray) -> float:
    x, y = x.reshape(-1).astype(np.float64), y.reshape(-1).astype(np.float64)
    if x.std() == 0 or y.std() == 0:
        return float("nan") if x.std() != y.std() or not np.array_equal(x, y) else 1.0
    return float(np.corrcoef(x, y)[0, 1])


def compare(cfg: NetworkConfig, a: Spikes, b: Spikes, ms: float, window_ms: float = 1.0,
            populations: list[str] | None = None) -> list[Row]:
    """One :class:`Row` per simulated population (``a``: cerebx, ``b``: NEST)."""
    rows = []
    names = populations or [n for n, p in cfg.populations.items() if p.neuron.kind != "input"]
    for name in names:
        pop = cfg.populations[name]
        n = pop.size
        ca = np.bincount(a[name][0], minlength=n)
        cb = np.bincount(b[name][0], minlength=n)
        ra, rb = ca.sum() / n / ms * 1000.0, cb.sum() / n / ms * 1000.0
        row = Row(name, n, float(ra), float(rb), float((rb - ra) / ra) if ra else float("nan"), _corr(ca, cb),
                  _matched(a[name], b[name], n, 0.0), _matched(a[name], b[name], n, window_ms))
        if name == cfg.io.output:
            row.output_corr = _corr(_output(a[name], n, pop.microcomplexes, ms),
                                    _output(b[name], n, pop.microcomplexes, ms))
        rows.append(row)
    return rows


def table(rows: list[Row], window_ms: float) -> str:
    """The rows as a Markdown table."""
    head = ("| population | neurons | cerebx (Hz) | NEST (Hz) | rate diff | count corr. | same step "
            f"| ±{window_ms:g} ms | output corr. |\n|---|---|---|---|---|---|---|---|---|")
    lines = [head]
    for r in rows:
        oc = "" if r.output_corr is None else f"{r.output_corr:.3f}"
        lines.append(f"| {r.population} | {r.neurons:,} | {r.rate_cerebx_hz:.2f} | {r.rate_nest_hz:.2f} | "
                     f"{100 * r.rate_diff:+.2f} % | {r.count_corr:.3f} | {100 * r.matched_step:.1f} % | "
                     f"{100 * r.matched:.1f} % | {oc} |")
    return "\n".join(lines)


@dataclass
class Crosscheck:
    """What :func:`crosscheck` measured."""

    network: str
    ms: float
    rows: list[Row]
    notes: list[str]
    cerebx_s: float
    nest_s: float
    nest_build_s: float
    drift: list[Drift] = field(default_factory=list)


def crosscheck(cfg: NetworkConfig, out: Path, ms: float = 1000.0, seed: int = 0, layer: list[str] | None = None,
               window_ms: float = 1.0, python: str | None = None, plastic: bool = False) -> Crosscheck:
    """Export ``cfg`` (plastic projections static, what NEST lacks left out and said), drive cerebx and NEST with
    the same seeded input for ``ms`` and compare. With ``layer``, cerebx runs the whole network and NEST only the
    layer, fed with the spikes cerebx's other populations produced. ``plastic``: the rules NEST expresses (pair
    STDP) learn in both, and their weight drift is compared (``Crosscheck.drift``); the others stay static in
    both."""
    p = plan(cfg, static=True, approximate=True)
    notes = list(p.notes)
    cfg_run = without(cfg, [k for k in p.dropped if not cfg.projections[k].teaching]) if p.dropped else cfg
    learning = [k for k, pp in p.projections.items() if pp.synapse != "static_synapse"] if plastic else []
    frozen = [k for k, pp in p.projections.items() if pp.plastic or (not plastic and pp.synapse != "static_synapse")]
    cfg_run = static_weights(cfg_run, frozen)  # a rule that learns in one learns in both
    if plastic:
        notes += [f"projections.{k}: static in both (NEST cannot express its rule)" for k in frozen]
    inputs = seeded_inputs(cfg_run, ms, seed)
    w_cx: dict[str, np.ndarray] = {}
    cx, cx_s = run_cerebx(cfg_run, inputs, ms, learn=bool(learning), weights=w_cx)
    target = cfg_run
    nest_inputs = inputs
    if layer:
        target = layer_config(cfg_run, layer)
        nest_inputs = {n: cx[n] for n, pop in target.populations.items() if pop.neuron.kind == "input"}
        notes.append(f"NEST simulates {', '.join(layer)} only, fed with the spikes of cerebx's "
                     f"{', '.join(sorted(nest_inputs))}")
    topo = build_topology(target)
    tp = export(target, out, to=("nest",), static=True, approximate=True, inputs=nest_inputs, topo=topo)
    w_ne: dict[str, np.ndarray] = {}
    ne, timing = run_nest(out, ms, python=python, weights=w_ne if learning else None)
    names = [n for n, pop in target.populations.items() if pop.neuron.kind != "input"]
    rows = compare(cfg_run, cx, ne, ms, window_ms, names)
    tables = synapse_tables(topo)
    drift = [_drift(tp.projections[k], k, tables[k], w_cx[k], w_ne, ne, ms)[0] for k in learning
             if k in tp.projections]
    return Crosscheck(cfg.name, ms, rows, notes, cx_s, timing["sim_s"], timing["build_s"], drift)


def static_weights(cfg: NetworkConfig, projections: list[str]) -> NetworkConfig:
    """``cfg`` with the plasticity of ``projections`` removed (their weights as configured, static)."""
    d = cfg.model_dump()
    for k in projections:
        d["projections"][k]["plasticity"] = None
    return NetworkConfig.model_validate(d)


def _drift(pp: Any, name: str, table0: dict[str, np.ndarray], w_cerebx: np.ndarray, w_nest: dict[str, np.ndarray],
           ne: Spikes, ms: float) -> tuple[Drift, np.ndarray]:
    """cerebx's and NEST's weights of plastic projection ``name`` after ``ms``, compared synapse by synapse; also
    NEST's weights in synapse table order."""
    pre, post, d = table0["pre"], table0["post"], table0["d"]
    key = pre.astype(np.int64) * (1 << 32) + post
    if len(np.unique(key)) != len(key):
        raise CerebxError(f"crosscheck: projections.{name}: weight drift is compared per (pre, post) pair; this "
                          "projection has several synapses on one pair")
    w0 = {(int(j), int(i), float(x)): float(w) for j, i, x, w in zip(pre, post, d, table0["w"], strict=True)}
    at = nest_weights_at(w_nest, name, w0, ne[pp.pre], ne[pp.post], pp.synapse_params, ms)
    w_max = abs(pp.synapse_params["Wmax"])
    return drift_row(name, table0["w"].astype(np.float64), w_cerebx, np.array(list(at.values())), w_max), \
        np.array(list(at.values()))


def single_neuron(neuron: dict[str, Any], weights_nS: tuple[float, float], rate_hz: float, ms: float, dt_ms: float,
                  out: Path, replicas: int = 50, seed: int = 0, python: str | None = None) -> dict[str, float]:
    """``replicas`` copies of one lif_cond neuron, each driven through one AMPA synapse (1 ms delay) by its own
    Bernoulli train (``rate_hz``, spikes at 2 ms step starts), weights spread evenly over ``weights_nS``; cerebx
    (its integrator at ``dt_ms``) against NEST's iaf_cond_exp at resolution ``dt_ms``. Returns the rates, their
    relative difference, the count correlation and the spikes matched on the same grid step and within 1 ms."""
    nrn = {**neuron, "integration": {**neuron.get("integration", {}), "dt_ms": None}}
    cfg = NetworkConfig.model_validate({
        "name": "single", "dt_ms": dt_ms, "neurons": {},
        "populations": {"in": {"size": replicas, "neuron": {"kind": "input"}},
                        "n": {"size": replicas, "neuron": nrn}},
        "projections": {"in_n": {"pre": "in", "post": "n", "rule": {"kind": "one_to_one"}, "receptor": "ampa",
                                 "synapses": replicas, "weight_nS": weights_nS[0], "delay_ms": 1.0}},
        "io": {"mossy": "in", "climbing": "in", "output": "n", "purkinje": ["n"], "granule": "n"}})
    rng = np.random.default_rng(seed)
    t = np.arange(1, int(round(ms / STEP_MS))) * STEP_MS
    fire = rng.random((len(t), replicas)) < rate_hz * STEP_MS / 1000.0
    steps, idx = np.nonzero(fire)
    inputs = {"in": (idx.astype(np.int32), t[steps])}
    topo = build_topology(cfg)
    w = np.linspace(*weights_nS, replicas).astype(np.float32)
    topo.sparse[0].w[:] = w[topo.sparse[0].post - replicas]
    cx, _ = run_cerebx(cfg, inputs, ms, sparse_w=topo.sparse[0].w)
    export(cfg, out, to=("nest",), inputs=inputs, topo=topo)
    ne, _ = run_nest(out, ms, python=python)
    row = compare(cfg, cx, ne, ms, window_ms=1.0, populations=["n"])[0]
    return {"dt_ms": dt_ms, "rate_cerebx_hz": row.rate_cerebx_hz, "rate_nest_hz": row.rate_nest_hz,
            "rate_diff": row.rate_diff, "count_corr": row.count_corr, "matched_same_step": row.matched_step,
            "matched_1ms": row.matched}


@dataclass
class Speed:
    """Wall time of one run of ``ms`` in each simulator and pace (one thread each, same network and input)."""

    simulator: str
    pace: str
    wall_s: float
    cpu_s: float
    per_step_ms: float  # CPU time per 2 ms of simulated time
    build_s: float | None = None


def speed(cfg: NetworkConfig, out: Path, ms: float, seed: int = 0, python: str | None = None) -> list[Speed]:
    """cerebx in 2 ms ``step`` calls (the 500 Hz loop's pace) and in one ``step_packed`` call; NEST (the export in
    ``out``, written here) in ``Simulate(2.0)`` slices, in ``Run(2.0)`` slices inside one ``RunManager``, and in one
    ``Simulate``. What NEST cannot express is left out of both, as in :func:`crosscheck`, and plasticity is off in
    both."""
    p = plan(cfg, static=True, approximate=True)
    cfg_run = without(cfg, [k for k in p.dropped if not cfg.projections[k].teaching]) if p.dropped else cfg
    cfg_run = static_weights(cfg_run, [k for k, x in cfg_run.projections.items() if x.plasticity is not None])
    inputs = seeded_inputs(cfg_run, ms, seed)
    n = ms / STEP_MS
    rows = []
    warm = seeded_inputs(cfg_run, 20.0, seed)  # numba's kernels loaded (or compiled) before anything is timed
    run_cerebx(cfg_run, warm, 20.0, sliced=True)
    run_cerebx(cfg_run, warm, 20.0, sliced=False)
    cpu: list[float] = []
    t0 = time.perf_counter()
    _, sliced = run_cerebx(cfg_run, inputs, ms, sliced=True, cpu=cpu)
    rows.append(Speed("cerebx", "step() per 2 ms", sliced, cpu[-1], 1000 * cpu[-1] / n,
                      time.perf_counter() - t0 - sliced))
    _, once = run_cerebx(cfg_run, inputs, ms, sliced=False, cpu=cpu)
    rows.append(Speed("cerebx", "one step_packed() call", once, cpu[-1], 1000 * cpu[-1] / n))
    export(cfg_run, out, to=("nest",), static=True, approximate=True, inputs=inputs)
    for slice_ms, mode, pace in ((STEP_MS, "simulate", "Simulate(2.0) per 2 ms"),
                                 (STEP_MS, "run", "Run(2.0) per 2 ms in one RunManager"),
                                 (0.0, "simulate", "one Simulate()")):
        _, timing = run_nest(out, ms, slice_ms, mode, python=python)
        rows.append(Speed("NEST", pace, timing["sim_s"], timing["sim_cpu_s"], 1000 * timing["sim_cpu_s"] / n,
                          timing["build_s"]))
    return rows


def speed_table(rows: list[Speed], ms: float) -> str:
    """The rows as a Markdown table: CPU time (what the machine's other load disturbs least) and wall time."""
    lines = ["| simulator | pace | CPU (s) | wall (s) | CPU per 2 ms step (ms) | real-time factor (CPU) | build (s) |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        b = "" if r.build_s is None else f"{r.build_s:.1f}"
        lines.append(f"| {r.simulator} | {r.pace} | {r.cpu_s:.3f} | {r.wall_s:.3f} | {r.per_step_ms:.3f} | "
                     f"{ms / 1000 / r.cpu_s:.2f}× | {b} |")
    by = {(r.simulator, r.pace): r.per_step_ms for r in rows}
    cx = by[("cerebx", "step() per 2 ms")] - by[("cerebx", "one step_packed() call")]
    ne = by[("NEST", "Simulate(2.0) per 2 ms")] - by[("NEST", "one Simulate()")]
    nr = by[("NEST", "Run(2.0) per 2 ms in one RunManager")] - by[("NEST", "one Simulate()")]
    lines.append("")
    lines.append(f"Per-step overhead (CPU, sliced minus one call, per 2 ms step): cerebx {1000 * cx:.0f} µs, "
                 f"NEST Simulate {1000 * ne:.0f} µs, NEST Run {1000 * nr:.0f} µs.")
    return "\n".join(lines)


def stdp_synapses(pre: tuple[np.ndarray, np.ndarray], drive: tuple[np.ndarray, np.ndarray], n: int, ms: float,
                  out: Path, rule: dict[str, Any] | None = None, delay_ms: Any = 1.0, drive_nS: float = 60.0,
                  python: str | None = None) -> tuple[Drift, dict[str, Any]]:
    """``n`` plastic synapses (pair STDP, ``delay: dendritic``, w0 0.5 of [0, 1] nS), one per post neuron, each
    fed by its own input fibre (``pre``: local fibre, time in ms) while a strong synapse from ``drive`` (0.5 ms,
    ``drive_nS``) makes its post neuron (the thesis network's PC) fire; cerebx against NEST's stdp_synapse.
    Returns the drift row and per synapse (table order) ``d``, ``w0``, ``w_cerebx``, ``w_nest``, with both
    simulators' post spikes (``post_cerebx``, ``post_nest``)."""
    from cerebx.snn.presets import PC

    one = {"kind": "one_to_one"}
    syn = {"pre": "pre", "post": "post", "rule": one, "receptor": "ampa", "synapses": n, "weight_nS": 0.5,
           "weight_range_nS": [0.0, 1.0], "delay_ms": delay_ms,
           "plasticity": {"kind": "pair_stdp", "delay": "dendritic", **(rule or {})}}
    drv = {"pre": "drv", "post": "post", "rule": one, "receptor": "ampa", "synapses": n, "weight_nS": drive_nS,
           "delay_ms": 0.5}
    fibres = {"size": n, "neuron": {"kind": "input"}}
    cfg = NetworkConfig.model_validate({
        "name": "stdp_synapses", "dt_ms": 0.5, "neurons": {},
        "populations": {"pre": fibres, "drv": fibres, "post": {"size": n, "neuron": PC}},
        "projections": {"syn": syn, "drive": drv},
        "io": {"mossy": "pre", "climbing": "drv", "output": "post", "purkinje": ["post"], "granule": "post"}})
    inputs = {"pre": pre, "drv": drive}
    w_cx: dict[str, np.ndarray] = {}
    cx, _ = run_cerebx(cfg, inputs, ms, learn=True, weights=w_cx)
    topo = build_topology(cfg)
    p = export(cfg, out, to=("nest",), inputs=inputs, topo=topo)
    w_ne: dict[str, np.ndarray] = {}
    ne, _ = run_nest(out, ms, python=python, weights=w_ne)
    t0 = synapse_tables(topo)["syn"]
    row, w_nest = _drift(p.projections["syn"], "syn", t0, w_cx["syn"], w_ne, ne, ms)
    return row, {"d": t0["d"], "w0": t0["w"], "w_cerebx": w_cx["syn"], "w_nest": w_nest, "post_cerebx": cx["post"],
                 "post_nest": ne["post"]}
