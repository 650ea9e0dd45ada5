"""The delay relay: a separate process on the real path that holds each data packet for a delay drawn
from a cerebx delay model, as the original's delay-generator nodes did (docs/provenance.md#original-delays).

It receives hop 0 of both paths and sends hop 1. Each SENSOR (``r2c``) and COMMAND (``c2r``) packet is
held for ``delay.r2c.next_ms()`` / ``delay.c2r.next_ms()`` (the samplers ``delay=`` builds, seeded from
the run's seed exactly as in simulated time, so the i-th packet gets the i-th draw) and never released
before the packet ahead of it on its path. Every other packet (pairing, pings, trial metrics) passes at
once. ``link.drop_fraction`` drops that fraction of data packets (seeded) to test lossy links. The relay
never decodes or checks a packet (it has no key): it reads the kind byte of the header only.

Measured delay = the drawn delay + the transport's own (two hops) + how late the relay woke to release.
On exit it writes ``summary.json`` (counts, held-time statistics) and ``injected.csv`` (path, seq, drawn
and actually held ms per packet) into its output folder.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import threading
import time
from collections import deque
from pathlib import Path
from typing import Any

import numpy as np

from cerebx import registry, runfiles
from cerebx.build import BuildContext
from cerebx.config import load
from cerebx.errors import CerebxError
from cerebx.link.clock import now_ns, realtime_process
from cerebx.link.stats import describe
from cerebx.link.transport import Transport
from cerebx.link.wire import DATA_KINDS, Kind, peek_kind, peek_seq

LINGER_S = 1.0  # after the robot side's BYE passed


class Relay:
    def __init__(self, cfg: Any, transport: Transport):
        self.transport = transport
        delay = registry.delays.build(cfg.delay, BuildContext(cfg=cfg))
        self.samplers = {"r2c": delay.r2c, "c2r": delay.c2r}
        self.drop = cfg.link.drop_fraction
        self.rng = BuildContext(cfg=cfg).rng("link.relay.drop")
        self.queues: dict[str, deque] = {"r2c": deque(), "c2r": deque()}
        self.last_release = {"r2c": 0, "c2r": 0}
        self.rows: list[tuple[str, int, float, float]] = []  # path, seq, drawn ms, held ms
        self.counts = {p: {"forwarded": 0, "dropped": 0, "control": 0} for p in ("r2c", "c2r")}
        self.stop = threading.Event()
        self.ended_at: float | None = None

    def _arrive(self, path: str, data: bytes, recv_ns: int) -> None:
        kind = peek_kind(data)
        if kind not in DATA_KINDS:
            self.transport.send(path, 1, data)
            self.counts[path]["control"] += 1
            if kind == Kind.BYE and path == "r2c" and self.ended_at is None:
                self.ended_at = time.monotonic()
            return
        if self.drop and self.rng.random() < self.drop:
            self.counts[path]["dropped"] += 1
            return
        drawn = float(self.samplers[path].next_ms())
        release = max(recv_ns + int(drawn * 1e6), self.last_release[path])
        self.last_release[path] = release
        self.queues[path].append((release, recv_ns, drawn, data))

    def _release_due(self) -> int | None:
        """Send every packet whose time has come; the next release time (ns) or None."""
        nxt = None
        for path, q in self.queues.items():
            now = now_ns()
            while q and q[0][0] <= now:
                _release, recv_ns, drawn, data = q.popleft()
                self.transport.send(path, 1, data)
                self.counts[path]["forwarded"] += 1
                self.rows.append((path, peek_seq(data) or 0, drawn, (now_ns() - recv_ns) / 1e6))
            if q and (nxt is None or q[0][0] < nxt):
                nxt = q[0][0]
        return nxt

    def run(self) -> None:
        inbox = self.transport.inbox
        while not self.stop.is_set():
            nxt = self._release_due()
            wait = 0.05 if nxt is None else max(0.0, (nxt - now_ns()) / 1e9)
            if wait > 0:
                inbox.wait(min(wait, 0.05))
            for item in inbox.take():
                if item.hop == 0:
                    self._arrive(item.path, item.data, item.recv_ns)
            if self.ended_at is not None and time.monotonic() - self.ended_at > LINGER_S:
                break
        self._release_due()

    def summary(self) -> dict[str, Any]:
        out: dict[str, Any] = {"counts": self.counts}
        for path in ("r2c", "c2r"):
            drawn = np.array([r[2] for r in self.rows if r[0] == path])
            held = np.array([r[3] for r in self.rows if r[0] == path])
            out[path] = {"drawn_ms": describe(drawn), "held_ms": describe(held),
                         "late_release_ms": describe(held - drawn)}
        return out

    def write(self, out: Path) -> None:
        out.mkdir(parents=True, exist_ok=True)
        (out / runfiles.SUMMARY).write_text(json.dumps(self.summary(), indent=2))
        with open(out / runfiles.INJECTED, "w") as fh:
            fh.write("# path,seq,drawn_ms,held_ms\n")
            for path, seq, drawn, held in self.rows:
                fh.write(f"{path},{seq},{drawn:.4f},{held:.4f}\n")


def _watch_parent(stop: threading.Event) -> None:
    """Started by ``cerebx run``: stop when its end of our stdin pipe closes (it finished or died)."""
    try:
        while os.read(0, 4096):
            pass
    except OSError:
        pass
    stop.set()


def _setup_line() -> list[str]:
    """Started by ``cerebx run``: the addresses come as one JSON line on stdin, not on the command line."""
    line = b""
    while not line.endswith(b"\n"):
        chunk = os.read(0, 1)
        if not chunk:
            break
        line += chunk
    try:
        return [str(o) for o in json.loads(line)["overrides"]]
    except (ValueError, KeyError, TypeError):
        raise CerebxError("relay: --parent-pipe: no setup line on stdin") from None


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(prog="cerebx relay", description="hold each data packet for a drawn delay")
    ap.add_argument("--out", help="folder for summary.json and injected.csv")
    ap.add_argument("--parent-pipe", action="store_true", help=argparse.SUPPRESS)
    args, overrides = ap.parse_known_args(argv)
    if args.parent_pipe:
        overrides = overrides + _setup_line()
    cfg, _ = load(overrides)
    if not cfg.link.real:
        raise CerebxError("relay: needs a real link (link=zenoh or link=udp)")
    why = realtime_process(cfg.link.rt_priority, "relay")
    if why:
        print(f"relay: {why}", file=sys.stderr)
    transport = registry.links.build(cfg.link, "relay", True)
    relay = Relay(cfg, transport)
    signal.signal(signal.SIGTERM, lambda *_: relay.stop.set())
    if args.parent_pipe:
        threading.Thread(target=_watch_parent, args=(relay.stop,), daemon=True).start()
    try:
        relay.run()
    except KeyboardInterrupt:
        pass
    finally:
        transport.close()
        if args.out:
            relay.write(Path(args.out))
    return 0
