"""What the live view costs a run: the same run with live off, with live on and no client, and with live on
and one client subscribed to every channel (tests/live_client.py), in rounds so that a change in the
machine's load falls on all three. Prints one JSON line per run and a summary.

    .venv/bin/python scripts/live_overhead.py --repeats 3 -- +task=circle trials=20
"""

from __future__ import annotations

import argparse
import json
import resource
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
from live_client import LiveClient  # noqa: E402


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def run(overrides: list[str], mode: str, out: Path) -> dict:
    args = [str(ROOT / ".venv" / "bin" / "cerebx"), "run", *overrides, "recording.progress=off",
            f"hydra.run.dir={out}"]
    client = None
    if mode != "off":
        port = free_port()
        args += ["live.enabled=true", f"live.port={port}"]
        if mode == "client":
            client = LiveClient(port, None).start()
    t0, ru0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    elapsed, ru1 = time.perf_counter() - t0, resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (ru1.ru_utime - ru0.ru_utime) + (ru1.ru_stime - ru0.ru_stime)  # all the run's threads, server's too
    summary = json.loads((out / "summary.json").read_text())
    row = {"mode": mode, "wall_seconds": round(summary["wall_seconds"], 2), "process_seconds": round(elapsed, 2),
           "cpu_seconds": round(cpu, 2),
           "rt_factor": round(summary["rt_factor"], 4), "final_mae": summary["final_mae"],
           "mcap_MB": round((out / "run.mcap").stat().st_size / 1e6, 1)}
    if client is not None:
        client.join(30)
        row["client_messages"] = len(client.messages)
        row["client_error"] = repr(client.error) if client.error else None
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=2, help="rounds of off / live / live with a client")
    ap.add_argument("--no-client", action="store_true", help="skip the runs with a client")
    ap.add_argument("overrides", nargs="*", default=["+task=circle", "trials=20"])
    a = ap.parse_args()
    modes = [m for _ in range(a.repeats) for m in ("off", "live", "client") if m != "client" or not a.no_client]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, mode in enumerate(modes):
            rows.append(run(a.overrides, mode, Path(tmp) / f"{i}_{mode}"))
            print(json.dumps(rows[-1]), flush=True)
    for key in ("wall_seconds", "cpu_seconds"):
        by = {m: [r[key] for r in rows if r["mode"] == m] for m in ("off", "live", "client")}
        off = statistics.mean(by["off"])
        print(json.dumps({key: {m: {"runs": v, "mean": round(statistics.mean(v), 2),
                                    "median": round(statistics.median(v), 2),
                                    "vs_off_percent": round(100 * (statistics.mean(v) / off - 1), 2)}
                                for m, v in by.items() if v}}))


if __name__ == "__main__":
    main()
