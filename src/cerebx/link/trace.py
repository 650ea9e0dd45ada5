"""``cerebx delays RUN_DIR [--out trace.csv] [--raw]``: a wall-clock run's measured link delays, set
beside the delay model that was injected, and written as a file ``delay=trace`` replays in simulated
time.

Each data message's one-way delay was measured from its stamps when it arrived (``/delays/r2c`` on the
brain side, ``/delays/c2r`` on the robot side). The trace has one row per message (``r2c_ms,c2r_ms``, the
i-th sensor and command message), in one of two forms:

- ticks (the default): the delay the loop met on the tick grid, (tick used - tick sent) x 2 ms; replayed
  by ``delay=trace`` each message is used at the very tick it was in the wall-clock run;
- ``--raw``: the measured delays in ms (drawn delay + transport + relay wake-up), which the tick-grid
  channel rounds up to whole ticks.

A message that never arrived (lost) takes the previous message's delay; a command the robot side used
before its tick (the robot side was running late, catching up) gets 0; the header says how many of each.
The model's distribution is drawn from the run's own delay config and seed, as the relay drew it; the
relay's own log (``relay/injected.csv``) gives the delay it drew for each message, so the transport's
share of each measured delay (measured - drawn: two hops and the relay's wake-up) is shown too.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from cerebx import registry, runfiles
from cerebx.build import BuildContext
from cerebx.errors import CerebxError
from cerebx.link.stats import describe
from cerebx.recording.reader import read_messages, read_metadata
from cerebx.schema.experiment import validate

PATHS = ("r2c", "c2r")
STEP_MS = 2.0


def measured(run_dir: Path) -> dict[str, dict[str, np.ndarray]]:
    """Per path: arrays indexed by sequence number (NaN where no message arrived) of the raw delay (ms)
    and the tick-grid delay (ms)."""
    rows: dict[str, list[tuple[int, float, float]]] = {p: [] for p in PATHS}
    for topic, _t, msg in read_messages(run_dir, topics=[f"/delays/{p}" for p in PATHS]):
        rows[topic.rsplit("/", 1)[1]].append((int(msg["seq"]), float(msg["delay_ms"]),
                                              (int(msg["used_tick"]) - int(msg["tick"])) * STEP_MS))
    out = {}
    for path, r in rows.items():
        n = max((s for s, _, _ in r), default=-1) + 1
        raw, grid = np.full(n, np.nan), np.full(n, np.nan)
        for s, d, g in r:
            raw[s], grid[s] = d, g
        out[path] = {"raw": raw, "grid": grid}
    if not any(len(v["raw"]) for v in out.values()):
        raise CerebxError(f"{run_dir}: no measured delays (/delays/r2c, /delays/c2r): not a wall-clock run?")
    return out


def model_draws(run_dir: Path, n: int) -> tuple[dict[str, np.ndarray], str]:
    """``n`` delays per path from the run's delay model, seeded and ordered as the relay drew them."""
    meta = read_metadata(run_dir)
    try:
        cfg = validate({k: v for k, v in json.loads(meta["config"]["json"]).items() if k != "init_from"})
    except (KeyError, ValueError) as err:
        raise CerebxError(f"{run_dir}: no readable config in the log ({err})") from None
    model = registry.delays.build(cfg.delay, BuildContext(cfg=cfg))
    r2c, c2r = np.zeros(n), np.zeros(n)
    for i in range(n):
        r2c[i] = model.r2c.next_ms()
        c2r[i] = model.c2r.next_ms()
    return {"r2c": r2c, "c2r": c2r}, cfg.delay.kind


def _fill(v: np.ndarray, n: int) -> tuple[np.ndarray, int]:
    """``v`` extended to ``n`` rows, each missing value taking the one before it (or the first known); the
    number of messages lost among ``v``'s."""
    out = np.full(n, np.nan)
    out[:len(v)] = v
    missing = int(np.isnan(v).sum())
    known = out[np.isfinite(out)]
    prev = known[0] if known.size else 0.0
    for i in range(n):
        if np.isnan(out[i]):
            out[i] = prev
        prev = out[i]
    return out, missing


def injected(run_dir: Path) -> dict[str, np.ndarray] | None:
    """The delays the relay drew, per path indexed by sequence number (NaN: never reached it), from its log."""
    path = Path(run_dir) / runfiles.RELAY / runfiles.INJECTED
    if not path.exists():
        return None
    rows: dict[str, list[tuple[int, float]]] = {p: [] for p in PATHS}
    for line in path.read_text().splitlines():
        if line.startswith("#") or not line.strip():
            continue
        p, seq, drawn, _held = line.split(",")
        rows[p].append((int(seq), float(drawn)))
    out = {}
    for p, r in rows.items():
        v = np.full(max((s for s, _ in r), default=-1) + 1, np.nan)
        for s, d in r:
            v[s] = d
        out[p] = v
    return out


def compare(run_dir: Path) -> dict[str, Any]:
    """Measured (raw and on the tick grid) against the model's distribution, per path; with the relay's log,
    the transport's own share per message (measured - the delay the relay drew for that very message)."""
    m = measured(run_dir)
    n = max(len(v["raw"]) for v in m.values())
    model, kind = model_draws(run_dir, n)
    drawn = injected(run_dir)
    out: dict[str, Any] = {"delay": kind, "messages": n}
    for path in PATHS:
        raw = m[path]["raw"]
        k = len(raw)
        row = {"measured_ms": describe(raw), "ticks_ms": describe(m[path]["grid"]),
               "model_ms": describe(model[path][:k]), "lost": int(np.isnan(raw).sum())}
        if drawn is not None:
            d = np.full(k, np.nan)
            j = min(k, len(drawn[path]))
            d[:j] = drawn[path][:j]
            row["injected_ms"] = describe(d)
            row["transport_ms"] = describe(raw - d)
        out[path] = row
    return out


def write_trace(run_dir: Path, out: Path, raw: bool) -> dict[str, int]:
    m = measured(run_dir)
    n = max(len(v["raw"]) for v in m.values())
    key = "raw" if raw else "grid"
    cols, missing, clamped = [], {}, {}
    for path in PATHS:
        col, miss = _fill(m[path][key], n)
        clamped[path] = int((col < 0).sum())
        cols.append(np.maximum(col, 0.0))
        missing[path] = miss
    out.parent.mkdir(parents=True, exist_ok=True)
    with open(out, "w") as fh:
        fh.write(f"# measured link delays of {run_dir} ({'raw, ms' if raw else 'on the 2 ms tick grid, ms'}); "
                 f"one row per message; filled (lost): r2c {missing['r2c']}, c2r {missing['c2r']}; raised to 0 "
                 f"(used before its tick: the robot side was late): r2c {clamped['r2c']}, c2r {clamped['c2r']}\n")
        fh.write("# r2c_ms,c2r_ms\n")
        for a, b in zip(*cols):
            fh.write(f"{a:.4f},{b:.4f}\n")
    return {"rows": n, **{f"filled_{p}": v for p, v in missing.items()},
            **{f"clamped_{p}": v for p, v in clamped.items()}}


def _table(cmp: dict[str, Any]) -> str:
    lines = [f"delay model: {cmp['delay']}, {cmp['messages']} messages per path",
             f"{'path':<5} {'series':<22} {'mean':>8} {'std':>7} {'p5':>7} {'p50':>7} {'p95':>7} {'p99':>7} {'max':>8}"]
    for path in PATHS:
        for name in ("measured_ms", "ticks_ms", "model_ms", "injected_ms", "transport_ms"):
            d = cmp[path].get(name)
            if d is None:
                continue
            if not d["n"]:
                continue
            lines.append(f"{path:<5} {name:<22} " + " ".join(
                f"{d[k]:>{w}.3f}" for k, w in (("mean", 8), ("std", 7), ("p5", 7), ("p50", 7), ("p95", 7),
                                               ("p99", 7), ("max", 8))))
        lines.append(f"{path:<5} lost {cmp[path]['lost']}")
    return "\n".join(lines)


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(prog="cerebx delays", description=__doc__.split("\n\n")[0])
    ap.add_argument("run", help="run folder of a wall-clock run (the brain side's)")
    ap.add_argument("--out", help="write the trace here (CSV: r2c_ms,c2r_ms)")
    ap.add_argument("--raw", action="store_true", help="measured ms instead of the delays met on the tick grid")
    ap.add_argument("--json", action="store_true", help="print the comparison as JSON")
    args = ap.parse_args(argv)
    run_dir = Path(args.run)
    cmp = compare(run_dir)
    print(json.dumps(cmp, indent=2) if args.json else _table(cmp))
    if args.out:
        info = write_trace(run_dir, Path(args.out), args.raw)
        print(f"wrote {args.out}: {info['rows']} rows (filled: r2c {info['filled_r2c']}, c2r {info['filled_c2r']}); "
              f"replay with delay=trace delay.path={args.out}")
    return 0
