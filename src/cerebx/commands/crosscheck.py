"""``cerebx crosscheck``: the same seeded mossy- and climbing-fibre spike trains drive a network in cerebx and in
NEST (its ``cerebx export``, plasticity off); prints per population the firing rates, their difference, the
per-neuron spike-count correlation, the spikes matched on the same step and within a window, and the output's
correlation, and writes the table as CSV and Markdown; with ``--plastic`` the pair-STDP projections learn in both
and their weight drift is compared. NEST runs in a subprocess of a Python that has it (this
one, or ``--nest-python`` / ``$CEREBX_NEST_PYTHON``)."""

from __future__ import annotations

import csv
from dataclasses import asdict
from pathlib import Path

from cerebx.commands.common import Parser
from cerebx.errors import CerebxError


def parser() -> Parser:
    ap = Parser("cerebx crosscheck", "run a network in cerebx and in NEST on the same input spike trains and "
                "compare rates, spike counts, spike times and output")
    ap.add_argument("network", help="a network preset (small, full, thesis_ch3, ...) or a YAML file holding one")
    ap.add_argument("overrides", nargs="*", help="key=value overrides: of a preset as for cerebx run; of a file, keys "
                    "of its network (dt_ms=0.1)")
    ap.add_argument("--ms", type=float, default=1000.0, help="simulated time (ms, default 1000)")
    ap.add_argument("--seed", type=int, default=0, help="seed of the input spike trains")
    ap.add_argument("--layer", default="", help="simulate only these populations in NEST (e.g. pc,dcn), fed with "
                    "the spikes of cerebx's others")
    ap.add_argument("--window-ms", type=float, default=1.0, help="spike-time agreement window (ms)")
    ap.add_argument("--out", help="folder for the export and the table (default: crosscheck_NETWORK)")
    ap.add_argument("--nest-python", help="a Python with NEST (default: this one, or $CEREBX_NEST_PYTHON)")
    ap.add_argument("--plastic", action="store_true", help="plasticity on where NEST expresses the rule (pair STDP, "
                    "delay: dendritic): both learn, and the weight drift is compared synapse by synapse")
    ap.add_argument("--speed", action="store_true", help="instead: the speed of both on the same network and input, "
                    "sliced in 2 ms as in the 500 Hz loop and in one call (speed.md)")
    return ap


def main(args: list[str]) -> int:
    ns = parser().parse_intermixed_args(args)
    if ns.ms <= 0 or ns.ms % 2.0:
        raise CerebxError("cerebx crosscheck: --ms: must be a positive multiple of 2")
    from cerebx.export.crosscheck import crosscheck, nest_python, speed, speed_table, table
    from cerebx.export.drift import drift_table
    from cerebx.export.source import load_network

    python = ns.nest_python or nest_python()
    cfg = load_network(ns.network, ns.overrides)
    out = Path(ns.out or f"crosscheck_{cfg.name}")
    layer = [x for x in ns.layer.split(",") if x] or None
    if ns.speed:
        md = speed_table(speed(cfg, out, ns.ms, ns.seed, python), ns.ms)
        print(f"{cfg.name}: {ns.ms:g} ms, seed {ns.seed}, one thread each")
        print(md)
        (out / "speed.md").write_text(md + "\n")
        return 0
    res = crosscheck(cfg, out, ms=ns.ms, seed=ns.seed, layer=layer, window_ms=ns.window_ms, python=python,
                     plastic=ns.plastic)
    md = table(res.rows, ns.window_ms)
    if res.drift:
        md += "\n\nWeight drift under plasticity (cerebx's weights at the end; NEST's at the same instant):\n\n"
        md += drift_table(res.drift)
    elif ns.plastic:
        res.notes.append("no projection learns in both (no pair_stdp with delay: dendritic)")
    print(f"{res.network}: {ns.ms:g} ms, seed {ns.seed}; cerebx {res.cerebx_s:.2f} s, NEST {res.nest_s:.2f} s "
          f"(+ build {res.nest_build_s:.2f} s), one thread each")
    print(md)
    for note in res.notes:
        print(f"note: {note}")
    with open(out / "crosscheck.csv", "w", newline="") as f:
        rows = [asdict(r) for r in res.rows]
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    (out / "crosscheck.md").write_text(md + "\n\n" + "\n".join(f"- {n}" for n in res.notes) + "\n")
    return 0
