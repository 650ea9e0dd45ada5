"""``cerebx`` command: run | validate | inspect | plot | bench | report | summarize | tune | robot | relay | delays |
export | crosscheck.

``run`` is a Hydra application (multirun, launchers, --cfg, completion); the other commands
compose the same config with Hydra's compose API. Input problems print one ``path: message``
line each and exit with code 2, before any run folder is created. Each command is a module of
``cerebx.commands`` loaded by name when it is chosen (the one import made by name here), so a command
costs only the imports it needs.
"""

from __future__ import annotations

import atexit
import importlib
import os
import sys
import threading

from cerebx import __version__, vectors
from cerebx.commands import COMMANDS, run_command
from cerebx.commands.common import fail
from cerebx.jobenv import numba_cache_dir

USAGE = """usage: cerebx COMMAND [args]

commands:
  run +task=NAME [group=option ...] [key=value ...]   run one experiment (-m for a sweep)
  validate +task=NAME [...]                            check a config without running; print it (-m: a sweep)
  inspect RUN_DIR|FILE.mcap                            a run's summary and its MCAP channels
  plot RUN_DIR [--out FILE.png]                        a run's learning curve and per-joint errors
  bench [--seconds S] [--networks a,b]                 speed of plant, network and closed loop (JSON)
  bench --lwpr                                         LWPR updates per second (the reference's examples)
  report [RUN_DIR ...]                                 build reports/ from run logs
  summarize MULTIRUN_DIR                               one table of a sweep's jobs (CSV, Markdown, plot)
  tune [--out PATH] OVERRIDES...                       Ziegler-Nichols PD gains on the simulated plant
  robot [--run-dir DIR] OVERRIDES...                   the robot side of a wall-clock run (link=zenoh|udp clock=wall)
  relay [--out DIR] OVERRIDES...                       the delay relay on a real link's path
  delays RUN_DIR [--out trace.csv] [--raw]             measured link delays: vs the model, as a delay=trace file
  export NETWORK --to nest|pynn --out DIR              a network's exact synapses and a NEST / PyNN script
  crosscheck NETWORK [--layer pc,dcn]                  the same input through cerebx and NEST: rates, spikes

groups: task (required, +task=), controller (snn), plant (baxter), delay (none),
        experiment (presets: +experiment=NAME); network (full), with controller=snn
every command: cerebx COMMAND --help
"""

def console() -> None:
    """The ``cerebx`` command as a process (the console script and ``python -m cerebx``): :func:`main`, then exit
    the way the interpreter's shutdown would (the threading module's exit hooks, every non-daemon thread joined,
    the ``atexit`` functions, the standard streams flushed) but without tearing every module and object down one
    by one, which took 0.3-0.35 s after each run. Every file a command writes is closed before it returns."""
    try:
        code = main()
    except SystemExit as stop:  # what the interpreter would make of it (argparse's --help, a library's exit)
        code = stop.code
        if code is not None and not isinstance(code, int):
            print(code, file=sys.stderr)
            code = 1
    shutdown = getattr(threading, "_shutdown", None)  # how the interpreter waits for threads at exit
    if shutdown is not None:
        shutdown()
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a reader gone (`| head`), or a stream closed
            pass
    os._exit(code or 0)


def main(argv: list[str] | None = None) -> int:
    try:
        return _main(argv)
    except BrokenPipeError:  # the output was piped into a reader that stopped (e.g. `| head`): no traceback
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141


def _main(argv: list[str] | None) -> int:
    # compiled numba kernels go to one cache folder, never into src/.../__pycache__
    os.environ.setdefault("NUMBA_CACHE_DIR", str(numba_cache_dir()))
    from pathlib import Path

    from cerebx.numba_cache import retire_stale

    retire_stale(Path(os.environ["NUMBA_CACHE_DIR"]))
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in ("-sc", "--shell-completion"):
        return importlib.import_module(COMMANDS["run"]).completion(argv)
    if not argv or argv[0] in ("-h", "--help", "help"):
        print(USAGE)
        return 0
    if argv[0] in ("--version", "-V"):
        print(f"cerebx {__version__}")
        return 0
    if argv[0] not in COMMANDS:
        return fail([f"{argv[0]}: unknown command (choose from {', '.join(COMMANDS)})"])
    if (bad := vectors.problem()) is not None:
        return fail([bad])
    return run_command(argv[0], argv[1:])


if __name__ == "__main__":  # `python -m cerebx.cli` (the bench's own subprocesses) as `python -m cerebx`
    console()
