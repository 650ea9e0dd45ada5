"""``cerebx`` command: run | validate | inspect | bench | report.

``run`` is a Hydra application (multirun, launchers, --cfg, completion); the other commands
compose the same config with Hydra's compose API. Input problems print one ``path: message``
line each and exit with code 2, before any run folder is created.
"""

from __future__ import annotations

import importlib
import json
import os
import re
import sys
from pathlib import Path

from cerebx.errors import CerebxError

USAGE = """usage: cerebx COMMAND [args]

commands:
  run +task=NAME [group=option ...] [key=value ...]   run one experiment (-m for a sweep)
  validate +task=NAME [...]                            check a config without running; print it
  inspect RUN_DIR|FILE.mcap                            a run's summary and its MCAP channels
  bench [--seconds S] [--networks a,b]                 speed of plant, network and closed loop (JSON)
  bench --lwpr                                         LWPR updates per second (cross benchmark)
  report [RUN_DIR ...]                                 build reports/ from run logs
  summarize MULTIRUN_DIR                               one table of a sweep's jobs (CSV, Markdown, plot)
  tune [--out PATH] OVERRIDES...                       Ziegler-Nichols PD gains on the simulated plant
  robot [--run-dir DIR] OVERRIDES...                   the robot side of a wall-clock run (link=zenoh|udp clock=wall)
  relay [--out DIR] OVERRIDES...                       the delay relay on a real link's path
  delays RUN_DIR [--out trace.csv] [--raw]             measured link delays: vs the model, as a delay=trace file

groups: task (required, +task=), controller (snn), plant (baxter), delay (none),
        network (thesis_ch3), experiment (presets: +experiment=NAME)
"""

COMMANDS = ("run", "validate", "inspect", "bench", "report", "tune", "summarize", "robot", "relay", "delays")
BY_NAME = {"robot": "cerebx.loop.robot_side:main", "relay": "cerebx.link.relay:main",
           "delays": "cerebx.link.trace:main"}
"""Commands whose module is loaded by name when used (they bring the link's transports)."""
_PASS_THROUGH = ("--cfg", "-c", "--help", "-h", "--hydra-help", "--info", "-i", "--resolve",
                 "--package", "-p", "-sc", "--shell-completion", "--config-dir", "-cd",
                 "--config-name", "-cn", "--config-path", "-cp", "--experimental-rerun")
_INFO = ("--cfg", "-c", "--help", "-h", "--hydra-help", "--info", "-i", "-sc", "--shell-completion")


def _fail(lines: list[str]) -> int:
    for line in lines:
        print(line, file=sys.stderr)
    return 2


def _run(args: list[str]) -> int:
    from cerebx.config import check, check_output_dir
    from cerebx.guard import check_args
    from cerebx.loop.resume import expand_args

    problems = check_args(args)  # before Hydra reads any of it, whatever the flags
    if problems:
        return _fail(problems)
    args = expand_args(args)  # resume=RUN_DIR: that run's overrides (checked like the given ones)
    problems = check_args(args)
    if problems:
        return _fail(problems)
    multirun = any(a in ("-m", "--multirun") for a in args)
    runs = not any(a.split("=")[0] in _INFO for a in args)  # --help, --cfg ... make no folder
    if runs:
        problems = check_output_dir(args, multirun)
        if problems:
            return _fail(problems)
    if not any(a.split("=")[0] in _PASS_THROUGH for a in args):
        estimates: list = []
        problems = check([a for a in args if not a.startswith("-")], multirun=multirun, estimates=estimates)
        problems += _size_problems(estimates, args, multirun)
        if problems:
            return _fail(problems)
    from cerebx.app import run_app

    root = None
    if multirun and runs:
        from cerebx.sweep import sweep_dir

        root, args = sweep_dir(args)
    sys.argv = [sys.argv[0]] + args
    if any(a in ("--help", "-h") for a in args):
        _hide_internal_groups()
    run_app()
    if root is None:
        return 0
    from cerebx.report.sweep import report

    try:
        text, code = report(root)
    except CerebxError as err:  # no job folder at all (every job refused before Hydra made one)
        return _fail([str(err)])
    print(text, file=sys.stderr if code else sys.stdout)
    return code


INTERNAL_GROUPS = ("report",)
"""Config groups read by cerebx itself (the report's study list), not options of a run."""


def _hide_internal_groups() -> None:
    """Leave cerebx's internal config groups out of ``cerebx run --help``."""
    from hydra._internal.hydra import Hydra

    listed = Hydra.list_all_config_groups

    def public(self, parent: str = "") -> list[str]:
        return [g for g in listed(self, parent) if g.split("/")[0] not in INTERNAL_GROUPS]

    Hydra.list_all_config_groups = public


def _size_problems(estimates: list, args: list[str], multirun: bool) -> list[str]:
    """Print the disk and time estimate of the command; one line if it does not fit on the disk."""
    from cerebx.config import output_root
    from cerebx.estimate import disk_problem, total

    if not estimates:
        return []
    total = total(estimates)
    what = f"sweep of {len(estimates)} jobs" if multirun else "run"
    print(f"{what}: {total.line()}", file=sys.stderr)
    why = disk_problem(total.mcap_bytes + total.state_bytes, output_root(args, multirun), what)
    return [why] if why else []


def _summarize(args: list[str]) -> int:
    from cerebx.report.sweep import main as summarize_main

    return summarize_main(args)


def _validate(args: list[str]) -> int:
    from cerebx.config import load
    from cerebx.errors import ConfigError

    try:
        exp, plain = load(args)
    except ConfigError as err:
        return _fail(err.problems)
    import yaml

    print(yaml.safe_dump(plain, sort_keys=False, default_flow_style=None, width=120), end="")
    net = exp.network
    print(f"# valid: task={exp.task.kind} controller={exp.controller.kind} plant={exp.plant.kind} "
          f"delay={exp.delay.kind} network={net.name} ({net.n_neurons:,} neurons, "
          f"{net.n_synapses:,} synapses, {net.n_plastic:,} plastic)")
    return 0


def _inspect(args: list[str]) -> int:
    """The run's summary and its channels; a bad summary or log is one line each, the other still shown."""
    from cerebx.recording.reader import channel_counts, has_summary, read_summary
    from cerebx.recording.segments import segments
    from cerebx.report.console import format_summary

    if len(args) != 1:
        return _fail(["inspect: give one run folder or .mcap file"])
    p = Path(args[0])
    if not p.exists():
        return _fail([f"{p}: no such file or folder"])
    run_dir = p if p.is_dir() else p.parent
    problems: list[str] = []
    if (run_dir / "summary.json").exists() or p.is_dir():
        try:
            print(format_summary(read_summary(run_dir), run_dir))
        except CerebxError as err:
            problems.append(str(err))
    log = p
    try:
        files = [s.path for s in segments(p)] if p.is_dir() else [p]
        log = files[-1]
        counts = channel_counts(p)
        width = max(map(len, counts), default=10)
        closed = all(has_summary(f) for f in files)
        print("\n" + " + ".join(str(f) for f in files)
              + ("" if closed else "  (no summary section: counted by scanning up to the last "
                                   "complete record; the run was killed or is still going)"))
        for topic, n in counts.items():
            print(f"  {topic:<{width}}  {n:>9,}")
        robot = run_dir / "robot"
        if p.is_dir() and (robot / "run.mcap").exists():  # the robot side of a wall-clock run
            log = robot / "run.mcap"
            counts = channel_counts(robot)
            width = max(map(len, counts), default=10)
            print(f"\n{log}  (robot side: {read_summary(robot)['status']})")
            for topic, n in counts.items():
                print(f"  {topic:<{width}}  {n:>9,}")
    except (CerebxError, OSError) as err:
        problems.append(str(err) if isinstance(err, CerebxError) else f"{log}: {err.strerror}")
    return _fail(problems) if problems else 0


def _bench(args: list[str]) -> int:
    from cerebx.bench_cli import main as bench_main

    print(json.dumps(bench_main(args), indent=2))
    return 0


def _report(args: list[str]) -> int:
    from cerebx.report.build import main as report_main

    return report_main(args)


def _tune(args: list[str]) -> int:
    from cerebx.tuning import main as tune_main

    return tune_main(args)


def _completion(argv: list[str]) -> int:
    """Hydra's completion, with the subcommand word removed from the line it completes; ``install=bash``
    (and uninstall) print Hydra's script, which calls ``cerebx -sc query=bash`` back."""
    if not any(a.startswith("query=") for a in argv):
        from cerebx.app import run_app

        sys.argv = [sys.argv[0]] + argv
        run_app()
        return 0
    line = os.environ.get("COMP_LINE", "")
    words = line.split()
    if len(words) <= 1 or (len(words) == 2 and not line.endswith(" ")):
        prefix = words[1] if len(words) == 2 else ""
        print(" ".join(c for c in COMMANDS if c.startswith(prefix)))
        return 0
    os.environ["COMP_LINE"] = re.sub(r"^(\s*\S+)\s+(?:run|validate)\b", r"\1", line)
    from cerebx.app import run_app

    sys.argv = [sys.argv[0]] + argv
    run_app()
    return 0


def _default_numba_cache() -> None:
    """Compiled numba kernels go to one cache folder (``cerebx.jobenv.numba_cache_dir``), never into
    ``src/.../__pycache__``, also when ``cerebx`` is run directly."""
    from cerebx.jobenv import numba_cache_dir

    if "NUMBA_CACHE_DIR" not in os.environ:
        os.environ["NUMBA_CACHE_DIR"] = str(numba_cache_dir())


def main(argv: list[str] | None = None) -> int:
    _default_numba_cache()
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv and argv[0] in ("-sc", "--shell-completion"):
        return _completion(argv)
    if not argv or argv[0] in ("-h", "--help", "help"):
        print(USAGE)
        return 0
    if argv[0] in ("--version", "-V"):
        from cerebx import __version__

        print(f"cerebx {__version__}")
        return 0
    cmd, rest = argv[0], argv[1:]
    handlers = {"run": _run, "validate": _validate, "inspect": _inspect, "bench": _bench, "report": _report,
                "tune": _tune, "summarize": _summarize}
    if cmd not in handlers and cmd not in BY_NAME:
        return _fail([f"{cmd}: unknown command (choose from {', '.join(COMMANDS)})"])
    if cmd in BY_NAME:
        module, _, attr = BY_NAME[cmd].partition(":")
        handlers[cmd] = getattr(importlib.import_module(module), attr)
    try:
        return handlers[cmd](rest)
    except CerebxError as err:
        return _fail([str(err)])


if __name__ == "__main__":
    sys.exit(main())
