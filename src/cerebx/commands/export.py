"""``cerebx export``: a network (a preset or a YAML file) as ``network.npz`` (cerebx's exact synapses, neuron
parameters, optionally seeded input spike trains) and a standalone NEST and/or PyNN script that builds it. Kinds
the targets cannot express are refused in one line naming them (``--static``: plastic projections exported with
static weights; ``--approximate``: what the target model lacks left out, each said; ``--weights RUN``: the weights
a run learned, from its saved state)."""

from __future__ import annotations

from pathlib import Path

from cerebx.commands.common import Parser
from cerebx.errors import CerebxError


def parser() -> Parser:
    ap = Parser("cerebx export", "write a network for NEST or PyNN: its exact synapse lists, weights, delays and "
                "neuron parameters (network.npz) and a script that builds it")
    ap.add_argument("network", nargs="?", help="a network preset (full, small, thesis_ch3, ...) or a YAML file "
                    "holding one (with --weights RUN: default the run's network)")
    ap.add_argument("overrides", nargs="*", help="key=value overrides: of a preset as for cerebx run; of a file, keys "
                    "of its network (dt_ms=0.1)")
    ap.add_argument("--to", default="nest", help="nest, pynn or nest,pynn (default: nest)")
    ap.add_argument("--out", required=True, help="the folder to write")
    ap.add_argument("--static", action="store_true",
                    help="export plastic projections whose rule NEST cannot express with static weights")
    ap.add_argument("--approximate", action="store_true",
                    help="leave out what the target model lacks (e.g. NMDA receptors), each said in a note")
    ap.add_argument("--inputs-ms", type=float, default=0.0,
                    help="also store seeded input spike trains of this many ms (mossy box-coded, climbing 5 Hz)")
    ap.add_argument("--seed", type=int, help="the run's seed: it draws the random connectors, weights and "
                    "delays (as `cerebx run seed=N` does) and the input spike trains (default 0; with --weights RUN "
                    "the run's)")
    ap.add_argument("--weights", metavar="RUN", help="a run folder (or its controller_state.npz): export the weights "
                    "it learned instead of the initial ones")
    return ap


def main(args: list[str]) -> int:
    ns = parser().parse_intermixed_args(args)
    from cerebx.export.crosscheck import seeded_inputs
    from cerebx.export.learned import load_learned, recorded_network
    from cerebx.export.source import load_network, validate_network
    from cerebx.export.writer import TARGETS, count_and_sum, export, synapse_tables
    from cerebx.snn.topology import build_topology

    to = tuple(t.strip() for t in ns.to.split(",") if t.strip())
    bad = [t for t in to if t not in TARGETS] or ([] if to else [ns.to])
    if bad:
        raise CerebxError(f"cerebx export: --to: unknown target {bad[0]!r} (choose from {', '.join(TARGETS)})")
    if ns.inputs_ms < 0:
        raise CerebxError("cerebx export: --inputs-ms: must be >= 0")
    if ns.network is None and ns.weights is None:
        raise CerebxError("cerebx export: name a network (a preset or a YAML file), or a run with --weights RUN")
    seed = ns.seed
    if ns.network is not None:
        cfg = load_network(ns.network, ns.overrides)
    if ns.weights is not None and (ns.network is None or (seed is None and Path(ns.weights).is_dir())):
        network, run_seed = recorded_network(Path(ns.weights))
        seed = run_seed if seed is None else seed
        if ns.network is None:
            cfg = validate_network(network, f"{ns.weights}: its network")
    seed = 0 if seed is None else seed
    topo = build_topology(cfg, seed=seed)
    if ns.weights is not None:
        print(f"weights: learned, from {load_learned(cfg, topo, Path(ns.weights))} (seed {seed})")
    inputs = seeded_inputs(cfg, ns.inputs_ms, seed) if ns.inputs_ms > 0 else None
    out = Path(ns.out)
    plan = export(cfg, out, to=to, static=ns.static, approximate=ns.approximate, inputs=inputs, topo=topo)
    sums = count_and_sum(synapse_tables(topo))
    kept = {k: v for k, v in sums.items() if k in plan.projections}
    n_syn = sum(n for n, _ in kept.values())
    w_sum = sum(w for _, w in kept.values())
    print(f"{cfg.name}: {sum(p.size for p in plan.populations.values()):,} neurons, {n_syn:,} synapses "
          f"(weight sum {w_sum:.6g} nS) in {len(plan.projections)} projections -> {out}/network.npz, "
          + ", ".join(TARGETS[t] for t in to))
    for name in plan.dropped:
        print(f"left out: projections.{name} ({plan.dropped[name]})")
    for note in plan.notes:
        print(f"note: {note}")
    return 0
