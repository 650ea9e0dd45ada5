"""``cerebx bench``'s learning runs: ``cerebx run`` as users run it (default recording and checkpoints, the
learned state at the end), timed from outside, next to closed loops without recording in the same session.

Each round measures, in fresh processes: the bench's closed loop (the ``full`` network on the circle), then per
run (registered with :func:`cerebx.registry.add_bench_run`) the same config's closed loop without recording or
checkpoints, the learning run, and the learning run again with ``recording.phase_times`` (where the time went;
its per-call timers cost a few microseconds per step, so the factors come from the untimed run). Rounds
alternate the cases, so a change in the host's load hits all of them alike; the numbers are medians over rounds.

Factors are simulated seconds per second: ``rt_factor`` what ``cerebx run`` prints (from the run's start to the
end of its last trial: build, trials, checkpoints; the learned state written after it and the log's closing
are not in it); ``process_rt_factor`` from the launch of the command to its exit (start-up, the learned state
and exit included); ``cpu_rt_factor`` per CPU second of the run (all threads), which depends
much less on what else the host is running than the wall-clock factors.
"""

from __future__ import annotations

import json
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from cerebx import registry, runfiles
from cerebx.errors import CerebxError

BENCH_LOOP = ["+task=circle", "network=full"]
"""The closed loop of ``cerebx bench``'s network table, the reference of every ratio."""


def _child_cpu_s() -> float:
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def closed_loop(overrides: list[str], seconds: float, warmup: float) -> dict[str, Any]:
    """``closed_loop_rt`` of ``overrides`` in a fresh process (no recording, no checkpoints)."""
    cmd = [sys.executable, "-m", "cerebx.cli", "bench", "--loop", json.dumps(overrides), "--seconds", str(seconds),
           "--warmup", str(warmup)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise CerebxError(f"bench: closed loop {overrides}: {(proc.stderr.strip().splitlines() or ['failed'])[-1]}")
    return json.loads(proc.stdout)


def learning_run(overrides: list[str], trials: int, run_dir: Path, timed: bool) -> dict[str, Any]:
    """``cerebx run OVERRIDES trials=N`` into ``run_dir``; its factors and, when ``timed``, its phases."""
    cmd = [sys.executable, "-m", "cerebx.cli", "run", *overrides, f"trials={trials}", "recording.progress=off",
           f"recording.phase_times={str(timed).lower()}", f"hydra.run.dir={run_dir}"]
    cpu0, launched, t0 = _child_cpu_s(), time.time(), time.perf_counter()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall, cpu = time.perf_counter() - t0, _child_cpu_s() - cpu0
    if proc.returncode != 0:
        raise CerebxError(f"bench: cerebx run {' '.join(overrides)}: "
                          f"{(proc.stderr.strip().splitlines() or ['failed'])[-1]}")
    s = json.loads((run_dir / runfiles.SUMMARY).read_text())
    sim = s["sim_seconds"]
    out = {"sim_s": sim, "rt_factor": round(s["rt_factor"], 3), "cpu_rt_factor": round(sim / s["cpu_seconds"], 3),
           "process_rt_factor": round(sim / wall, 3), "process_cpu_rt_factor": round(sim / cpu, 3),
           "run_wall_s": round(s["wall_seconds"], 3), "run_cpu_s": round(s["cpu_seconds"], 3),
           "startup_s": round(s["started_at"] - launched, 3),
           "exit_s": round(wall - (s["started_at"] - launched) - s["wall_seconds"], 3),
           "process_wall_s": round(wall, 3), "process_cpu_s": round(cpu, 3)}
    if timed:
        out["phase_times"] = s["phase_times"]
    return out


def _median(rows: list[dict], key: str) -> float:
    return round(statistics.median(r[key] for r in rows), 3)


def _phases(timed: list[dict]) -> dict[str, Any]:
    """Median seconds per phase of the timed runs, and each phase's share of the run's wall time."""
    walls = [r["phase_times"]["wall_s"] for r in timed]
    names = sorted({k for w in walls for k in w})
    wall = {k: round(statistics.median(w.get(k, 0.0) for w in walls), 4) for k in names}
    total = sum(wall.values())
    cpus = [r["phase_times"]["cpu_s"] for r in timed]
    background: dict[str, dict[str, float]] = {}
    for name in sorted({k for r in timed for k in r["phase_times"]["background"]}):
        rows = [r["phase_times"]["background"].get(name, {"wall_s": 0.0, "cpu_s": 0.0}) for r in timed]
        background[name] = {f: round(statistics.median(x[f] for x in rows), 4) for f in ("wall_s", "cpu_s")}
    return {"wall_s": wall, "share": {k: round(v / total, 4) for k, v in wall.items()} if total else {},
            "cpu_s": {k: round(statistics.median(c.get(k, 0.0) for c in cpus), 4) for k in sorted({k for c in cpus
                                                                                                      for k in c})},
            "background": background,
            "startup_s": _median(timed, "startup_s"), "exit_s": _median(timed, "exit_s"),
            "rt_factor_timed": _median(timed, "rt_factor")}


def bench_learning(names: list[str], trials: int, rounds: int, seconds: float, warmup: float) -> dict[str, Any]:
    """The learning runs ``names`` (all registered ones when empty), ``rounds`` rounds of ``trials`` trials."""
    registry.load_plugins()
    unknown = [n for n in names if n not in registry.bench_runs]
    if unknown:
        raise CerebxError(f"bench: unknown learning run {unknown[0]!r} (registered: "
                          f"{', '.join(registry.bench_runs) or 'none'})")
    runs = {n: list(registry.bench_runs[n]) for n in (names or registry.bench_runs)}
    reference: list[dict] = []
    rows: dict[str, dict[str, list[dict]]] = {n: {"loop": [], "plain": [], "timed": []} for n in runs}
    out = Path(tempfile.mkdtemp(prefix="cerebx-bench-"))
    try:
        for r in range(rounds):
            reference.append(closed_loop(BENCH_LOOP, seconds, warmup))
            for name, overrides in runs.items():
                rows[name]["loop"].append(closed_loop(overrides, seconds, warmup))
                rows[name]["plain"].append(learning_run(overrides, trials, out / f"{name}.{r}", timed=False))
                rows[name]["timed"].append(learning_run(overrides, trials, out / f"{name}.{r}.timed", timed=True))
    finally:
        shutil.rmtree(out, ignore_errors=True)
    ref = {"overrides": BENCH_LOOP, "rt_factor": _median(reference, "rt_factor"),
           "cpu_rt_factor": _median(reference, "cpu_rt_factor")}
    result: dict[str, Any] = {"trials": trials, "rounds": rounds, "closed_loop": ref, "runs": {}}
    for name, overrides in runs.items():
        plain, loop = rows[name]["plain"], rows[name]["loop"]
        factors = {k: _median(plain, k) for k in ("rt_factor", "cpu_rt_factor", "process_rt_factor",
                                                  "process_cpu_rt_factor")}
        # ratios per round (both numbers of a ratio come from the same round), then their median
        ratio = {
            "rt_factor": round(statistics.median(p["rt_factor"] / c["rt_factor"]
                                                 for p, c in zip(plain, reference)), 3),
            "cpu_rt_factor": round(statistics.median(p["cpu_rt_factor"] / c["cpu_rt_factor"]
                                                     for p, c in zip(plain, reference)), 3),
            "process_rt_factor": round(statistics.median(p["process_rt_factor"] / c["rt_factor"]
                                                         for p, c in zip(plain, reference)), 3),
        }
        same = {"rt_factor": round(statistics.median(p["rt_factor"] / c["rt_factor"] for p, c in zip(plain, loop)), 3),
                "cpu_rt_factor": round(statistics.median(p["cpu_rt_factor"] / c["cpu_rt_factor"]
                                                         for p, c in zip(plain, loop)), 3)}
        result["runs"][name] = {
            "overrides": overrides, "sim_s": plain[0]["sim_s"], **factors,
            "ratio_to_closed_loop": ratio,
            "closed_loop_same_config": {"rt_factor": _median(loop, "rt_factor"),
                                        "cpu_rt_factor": _median(loop, "cpu_rt_factor"), "ratio": same},
            "phases": _phases(rows[name]["timed"]),
            "rounds": plain,
        }
    return result
