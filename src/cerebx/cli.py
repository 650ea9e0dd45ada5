"""``cerebx`` command: run | validate | inspect | bench | report.

``run`` is a Hydra application (multirun, launchers, --cfg, completion); the other commands
compose the same config with Hydra's compose API. Input problems print one ``path: message``
line each and exit with code 2, before any run folder is created.
"""

from __future__ import annotations

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
  tune [--out PATH] OVERRIDES...                       Ziegler-Nichols PD gains on the simulated plant

groups: task (required, +task=), controller (snn), plant (baxter), delay (none),
        network (thesis_ch3), experiment (presets: +experiment=NAME)
"""

COMMANDS = ("run", "validate", "inspect", "bench", "report", "tune")
_PASS_THROUGH = ("--cfg", "-c", "--help", "-h", "--hydra-help", "--info", "-i", "--resolve",
                 "--package", "-p", "-sc", "--shell-completion", "--config-dir", "-cd",
                 "--config-name", "-cn", "--config-path", "-cp", "--experimental-rerun")


def _fail(lines: list[str]) -> int:
    for line in lines:
        print(line, file=sys.stderr)
    return 2


def _run(args: list[str]) -> int:
    from cerebx.config import check

    multirun = any(a in ("-m", "--multirun") for a in args)
    if not any(a.split("=")[0] in _PASS_THROUGH for a in args):
        problems = check([a for a in args if not a.startswith("-")], multirun=multirun)
        if problems:
            return _fail(problems)
    from cerebx.app import run_app

    sys.argv = [sys.argv[0]] + args
    run_app()
    return 0


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
    from cerebx.recording.reader import channel_counts, mcap_path, read_summary
    from cerebx.report.console import format_summary

    if len(args) != 1:
        return _fail(["inspect: give one run folder or .mcap file"])
    p = Path(args[0])
    if not p.exists():
        return _fail([f"{p}: no such file or folder"])
    run_dir = p if p.is_dir() else p.parent
    try:
        if (run_dir / "summary.json").exists():
            print(format_summary(read_summary(run_dir), run_dir))
        counts = channel_counts(mcap_path(p))
    except CerebxError as err:
        return _fail([str(err)])
    width = max(map(len, counts), default=10)
    print(f"\n{mcap_path(p)}")
    for topic, n in counts.items():
        print(f"  {topic:<{width}}  {n:>9,}")
    return 0


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
    """Hydra's completion, with the subcommand word removed from the line it completes."""
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


def main(argv: list[str] | None = None) -> int:
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
                "tune": _tune}
    if cmd not in handlers:
        return _fail([f"{cmd}: unknown command (choose from {', '.join(COMMANDS)})"])
    try:
        return handlers[cmd](rest)
    except CerebxError as err:
        return _fail([str(err)])


if __name__ == "__main__":
    sys.exit(main())
