"""``cerebx export``: a network (a preset or a YAML file) as ``network.npz`` (cerebx's exact synapses, neuron
parameters, optionally seeded input spike trains) and a standalone NEST and/or PyNN script that builds it. Kinds
the targets cannot express are refused in one line naming them (``--static``: plastic projections exported with
static weights; ``--approximate``: what the target model lacks left out, each said)."""

from __future__ import annotations

from pathlib import Path

from cerebx.commands.common import Parser
from cerebx.errors import CerebxError


def parser() -> Parser:
    ap = Parser("cerebx export", "write a network for NEST or PyNN: its exact synapse lists, weights, delays and "
                "neuron parameters (network.npz) and a script that builds it")
    ap.add_argument("network", help="a network preset (full, small, thesis_ch3, ...) or a YAML file holding one")
    ap.add_argument("overrides", nargs="*", help="key=value overrides of a preset (as for cerebx run)")
    ap.add_argument("--to", default="nest", help="nest, pynn or nest,pynn (default: nest)")
    ap.add_argument("--out", required=True, help="the folder to write")
    ap.add_argument("--static", action="store_true",
                    help="export plastic projections whose rule NEST cannot express with static weights")
    ap.add_argument("--approximate", action="store_true",
                    help="leave out what the target model lacks (e.g. NMDA receptors), each said in a note")
    ap.add_argument("--inputs-ms", type=float, default=0.0,
                    help="also store seeded input spike trains of this many ms (mossy box-coded, climbing 5 Hz)")
    ap.add_argument("--seed", type=int, default=0, help="the run's seed: it draws the random connectors, weights and "
                    "delays (as `cerebx run seed=N` does) and the input spike trains")
    return ap


def main(args: list[str]) -> int:
    ns = parser().parse_intermixed_args(args)
    from cerebx.export.crosscheck import seeded_inputs
    from cerebx.export.source import load_network
    from cerebx.export.writer import TARGETS, count_and_sum, export, synapse_tables

    to = tuple(t.strip() for t in ns.to.split(",") if t.strip())
    bad = [t for t in to if t not in TARGETS] or ([] if to else [ns.to])
    if bad:
        raise CerebxError(f"cerebx export: --to: unknown target {bad[0]!r} (choose from {', '.join(TARGETS)})")
    if ns.inputs_ms < 0:
        raise CerebxError("cerebx export: --inputs-ms: must be >= 0")
    cfg = load_network(ns.network, ns.overrides)
    from cerebx.snn.topology import build_topology

    topo = build_topology(cfg, seed=ns.seed)
    inputs = seeded_inputs(cfg, ns.inputs_ms, ns.seed) if ns.inputs_ms > 0 else None
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
