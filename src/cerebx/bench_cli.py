"""``cerebx bench``: speed of the plant with PD, of each network alone, of the closed loop, and of learning runs
as users make them (``bench_learning.py``).

Each network is measured in a fresh subprocess so build time (numba cache warm) and peak RSS
belong to that network alone, and its closed loop in another, as a run meets it.
Output is JSON. Numbers are simulated seconds per wall second; ``per_step_us`` says where a control step's time
goes, in microseconds per part (the PD loop's and each closed loop's main thread by phase, each network's kernels by
part: :func:`cerebx.loop.timing.per_step_parts`), from extra timed steps after the untimed ones that give the
factors. ``versus`` beside each closed loop: its speed over the PD loop's, the two timed trial by trial in turns in
one process (steady on a host whose speed drifts within seconds). ``beside_busy_core`` under the PD loop: its speed
beside a core kept busy in compiled code over its speed alone, in turns
(:func:`cerebx.loop.timing.beside_busy_core`): below 1 on a host whose cores slow each other, which bounds
``versus`` (a closed loop's network thread keeps the other core busy). ``load_average`` and ``vector_bits``: the
host's load around the measurements and the kernels' vector width (``cerebx.vectors``).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from typing import Any

from cerebx.bench import bench_network, peak_rss_mb
from cerebx.bench_learning import bench_learning
from cerebx.config import load
from cerebx.loop.timing import closed_loop_rt
from cerebx.lwpr.bench import bench_lwpr
from cerebx.vectors import vector_bits

DEFAULT_NETWORKS = ("full", "multikernel")
PD_LOOP = ["+task=circle", "controller=pd"]  # the plant's loop with PD, which a closed loop is timed against
BUSY_ROUNDS = 40  # trials of the PD loop alone and beside a busy core, in turns


def _one_network(name: str, seconds: float, warmup: float, parallel: bool, started: float) -> dict[str, Any]:
    """Network alone, then the closed loop with the MuJoCo Baxter (circle task, plasticity on). ``started``:
    when the parent launched this process (its start-up, interpreter and imports, is measured from it)."""
    startup_s = time.time() - started
    load_start = _load()
    exp, _ = load(["+task=circle", f"network={name}"])
    out = bench_network(exp.controller.network, seconds=seconds, warmup=warmup, parallel=parallel)
    out["startup_s"] = round(startup_s, 3)
    out["peak_rss_mb"] = round(peak_rss_mb(), 1)
    # the closed loop in a process of its own, as `cerebx run` meets it: after the network alone in the same
    # process it ran up to a fifth faster than any run does (numba had then loaded the step kernel from
    # Python, which the pipelined loop never does)
    loop_overrides = ["+task=circle", f"network={name}", f"controller.parallel={str(parallel).lower()}"]
    cmd = [sys.executable, "-m", "cerebx.cli", "bench", "--loop", json.dumps(loop_overrides), "--seconds", str(seconds),
           "--warmup", str(warmup), "--parts", "--versus", json.dumps(PD_LOOP)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        out["closed_loop"] = {"error": (proc.stderr.strip().splitlines() or ["failed"])[-1]}
        return out
    loop = json.loads(proc.stdout)
    keys = ("build_s", "rt_factor", "cpu_rt_factor", "us_per_step", "cpu_us_per_step", "per_step_us", "versus")
    out["closed_loop"] = {k: loop[k] for k in keys}
    out["load_average"] = {"start": load_start, "end": _load()}
    return out


def _plant_pd(seconds: float) -> dict[str, Any]:
    rows = {}
    for label, extra in (("baxter_pd", []), ("baxter_pd_physics_1ms", ["plant.physics_dt_ms=1.0"]),
                         ("baxter_sea_pd", ["plant=baxter_sea"])):
        r = closed_loop_rt([*PD_LOOP, *extra], seconds=seconds, warmup_s=1.0, parts=not extra,
                           beside_busy=0 if extra else BUSY_ROUNDS)
        rows[label] = {k: r[k] for k in ("rt_factor", "us_per_step", "cpu_us_per_step", "per_step_us",
                                         "beside_busy_core") if k in r}
    return rows


def main(argv: list[str]) -> dict[str, Any]:
    ap = argparse.ArgumentParser(prog="cerebx bench", description=__doc__)
    ap.add_argument("--seconds", type=float, default=4.0, help="simulated seconds timed per measurement")
    ap.add_argument("--warmup", type=float, default=1.0, help="simulated seconds before timing starts")
    ap.add_argument("--networks", default=",".join(DEFAULT_NETWORKS), help="comma-separated network presets")
    ap.add_argument("--serial", action="store_true", help="one thread in the network kernels")
    ap.add_argument("--lwpr", action="store_true", help="only LWPR on the reference library's 2-D cross and 1-D "
                    "examples (updates, predictions per second, nMSE, receptive fields)")
    ap.add_argument("--learning", default=None, help="comma-separated learning runs to time (default: every "
                    "registered one, e.g. make_run; '' for none)")
    ap.add_argument("--trials", type=int, default=20, help="trials of each learning run")
    ap.add_argument("--rounds", type=int, default=1, help="rounds of learning runs and their closed loops (medians)")
    ap.add_argument("--one", help=argparse.SUPPRESS)
    ap.add_argument("--loop", help=argparse.SUPPRESS)
    ap.add_argument("--parts", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--versus", help=argparse.SUPPRESS)
    ap.add_argument("--started", type=float, default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.lwpr:
        return {"lwpr": bench_lwpr()}
    if args.loop:
        versus = json.loads(args.versus) if args.versus else None
        return closed_loop_rt(json.loads(args.loop), seconds=args.seconds, warmup_s=args.warmup, parts=args.parts,
                              versus=versus)
    if args.one:
        return _one_network(args.one, args.seconds, args.warmup, not args.serial, args.started or time.time())
    report: dict[str, Any] = {"cpus": os.cpu_count(), "vector_bits": vector_bits(),
                              "load_average": {"start": _load()}, "plant_pd": _plant_pd(args.seconds), "networks": {}}
    for name in filter(None, args.networks.split(",")):
        cmd = [sys.executable, "-m", "cerebx.cli", "bench", "--one", name, "--seconds", str(args.seconds),
               "--warmup", str(args.warmup), "--started", repr(time.time())] + (["--serial"] if args.serial else [])
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            report["networks"][name] = {"error": (proc.stderr.strip().splitlines() or ["failed"])[-1]}
        else:
            report["networks"][name] = json.loads(proc.stdout)
    if args.learning != "":
        names = [n for n in (args.learning or "").split(",") if n]
        report["learning"] = bench_learning(names, args.trials, args.rounds, args.seconds, args.warmup)
    report["load_average"]["end"] = _load()
    return report


def _load() -> list[float]:
    """The host's load averages (1, 5, 15 min) now: how busy it was around a measurement (this host's speed, and
    so every factor, moves with what else it runs)."""
    return [round(x, 2) for x in os.getloadavg()]
