"""Instructions per control step of a closed loop, per thread, counted by callgrind: on a host whose speed drifts
within seconds (docs/guide/speed.md), the one measure of the loop's work that repeats (to ~0.2 %).

    scripts/instructions_per_step.py +task=circle                   # the full network's closed loop
    scripts/instructions_per_step.py +task=circle controller=pd     # the same plant with PD

Builds the loop, runs two untimed trials, then counts one trial: natively first (numba's cache filled for a
fixed CPU, ``NUMBA_CPU_NAME=haswell``, whose code valgrind runs), then under ``valgrind --tool=callgrind`` with
the instrumentation switched on for that trial only (``callgrind_control``). Prints each thread's instructions
per step, the loop's thread first. ``--cache`` adds callgrind's cache and branch simulation (a 512 kB last
level, the size of one core's L2 here; the threads share the simulated caches): misses per step.
Needs valgrind. The counts depend on the build (numba, MuJoCo, numpy) as well as on cerebx: compare builds on
one machine.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = "CEREBX_COUNT_INSIDE"


def _inside(overrides: list[str]) -> None:
    """The measured process: build, two trials, then one trial with callgrind's instrumentation on."""
    import threading

    from cerebx.build import build_components
    from cerebx.config import load
    from cerebx.loop.loop import ClosedLoop

    ctx = build_components(load(overrides)[0])
    loop = ClosedLoop(ctx, None)
    loop.start()
    under = os.environ[HERE] == "valgrind"
    for trial in range(2):
        loop.run_trial(trial)
    loop.settle()
    if under:
        subprocess.run(["callgrind_control", "-i", "on", str(os.getpid())], check=True, capture_output=True)
    loop.run_trial(2)
    loop.settle()
    if under:
        subprocess.run(["callgrind_control", "-i", "off", str(os.getpid())], check=True, capture_output=True)
    print(f"steps {ctx.task.steps_per_trial} loop-thread {threading.get_native_id()}", flush=True)


def main(argv: list[str]) -> int:
    cache = "--cache" in argv
    overrides = [a for a in argv if a != "--cache"]
    env = dict(os.environ, NUMBA_CPU_NAME="haswell", PYTHONDONTWRITEBYTECODE="1")
    env.setdefault("NUMBA_CACHE_DIR", str(Path(tempfile.gettempdir()) / "cerebx-numba-haswell"))
    me = [sys.executable, __file__, *overrides]
    subprocess.run(me, env=dict(env, **{HERE: "native"}), check=True, stdout=subprocess.DEVNULL)
    with tempfile.TemporaryDirectory() as out:
        tool = ["valgrind", "--tool=callgrind", "--instr-atstart=no", "--separate-threads=yes",
                f"--callgrind-out-file={out}/cg.%p"]
        if cache:
            tool += ["--cache-sim=yes", "--LL=524288,8,64", "--branch-sim=yes"]
        proc = subprocess.run([*tool, *me], env=dict(env, **{HERE: "valgrind"}), capture_output=True, text=True,
                              check=True)
        m = re.search(r"steps (\d+) loop-thread (\d+)", proc.stdout)
        if m is None:
            print(proc.stdout + proc.stderr, file=sys.stderr)
            return 1
        steps, loop_tid = int(m.group(1)), m.group(2)
        rows = []
        for f in sorted(Path(out).glob("cg.*")):
            text = f.read_text()
            events = re.search(r"^events: (.*)$", text, re.M)
            totals = re.search(r"^totals: (.*)$", text, re.M)
            if not (events and totals) or totals.group(1).strip() in ("", "0"):
                continue
            values = dict(zip(events.group(1).split(), map(int, totals.group(1).split())))
            # valgrind numbers threads from 1, the process's first: the loop's
            thread = "loop" if f.name == f"cg.{loop_tid}-01" else f"thread {f.name.rsplit('-', 1)[-1]}"
            rows.append((thread != "loop", thread, values))
        for _, thread, values in sorted(rows, key=lambda r: (r[0], -r[2]["Ir"])):
            per_step = {k: round(v / steps) for k, v in values.items()}
            l2 = sum(per_step.get(k, 0) for k in ("ILmr", "DLmr", "DLmw"))
            extra = (f"  L2-sized misses {l2:,}  branch mispredictions {per_step['Bcm'] + per_step['Bim']:,}"
                     if cache else "")
            print(f"{thread:10s} {per_step['Ir']:>10,} instructions a step{extra}")
    return 0


if __name__ == "__main__":
    if os.environ.get(HERE):
        _inside(sys.argv[1:])
    else:
        sys.exit(main(sys.argv[1:]))
