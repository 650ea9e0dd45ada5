"""``cerebx run``: one experiment, or a sweep with ``-m``, through the Hydra application (``cerebx.app``).

Everything the command line asks for is checked before Hydra starts and before any folder is made: code in
the config, the overrides of a resumed run, the output folder, every job of a sweep, and whether the logs
fit on the disk. A sweep ends with its per-job table (``cerebx summarize``) and exits with the number of
failed jobs."""

from __future__ import annotations

import os
import re
import sys

from cerebx import sweep
from cerebx.app import run_app
from cerebx.commands import COMMANDS, run_command
from cerebx.commands.common import fail
from cerebx.compile_progress import show_progress
from cerebx.config import check, check_output_dir, output_root, split_args
from cerebx.estimate import disk_problem, total
from cerebx.guard import check_args
from cerebx.loop.resume import expand_args
from cerebx.numba_cache import ColdKernels, cold_kernels

PASS_THROUGH = ("--cfg", "-c", "--help", "-h", "--hydra-help", "--info", "-i", "--resolve",
                "--package", "-p", "-sc", "--shell-completion",
                "--config-name", "-cn", "--config-path", "-cp", "--experimental-rerun")
INFO = ("--cfg", "-c", "--help", "-h", "--hydra-help", "--info", "-i", "-sc", "--shell-completion")
NOT_WITH_MULTIRUN = ("--cfg", "-c", "--info", "-i", "-sc", "--shell-completion")  # Hydra does one of these or -m

def main(args: list[str]) -> int:
    problems = check_args(args)  # before Hydra reads any of it, whatever the flags
    if problems:
        return fail(problems)
    args = expand_args(args)  # resume=RUN_DIR: that run's overrides (checked like the given ones)
    problems = check_args(args)
    if problems:
        return fail(problems)
    multirun = any(a in ("-m", "--multirun") for a in args)
    exclusive = [a.split("=")[0] for a in args if a.split("=")[0] in NOT_WITH_MULTIRUN]
    if multirun and exclusive:
        return fail([f"{exclusive[0]}: cannot be combined with -m (drop -m to see one job's config)"])
    runs = not any(a.split("=")[0] in INFO for a in args)  # --help, --cfg ... make no folder
    if runs:
        problems = check_output_dir(args, multirun)
        if problems:
            return fail(problems)
    if not any(a.split("=")[0] in PASS_THROUGH for a in args):
        estimates: list = []
        valid: list = []
        overrides, config_dir = split_args(args)
        problems = check(overrides, multirun=multirun, estimates=estimates, config_dir=config_dir, valid=valid)
        cold = cold_kernels([exp for _, exp, _ in valid])
        problems += size_problems(estimates, args, multirun, cold)
        if problems:
            return fail(problems)
        if cold.reported:
            show_progress(cold.kernels)
    root = None
    if multirun and runs:
        root, args = sweep.sweep_dir(args)
    sys.argv = [sys.argv[0]] + args
    run_app()
    if root is None:
        return 0
    return run_command("summarize", [str(root), "--end-of-sweep"])


def size_problems(estimates: list, args: list[str], multirun: bool, cold: ColdKernels | None = None) -> list[str]:
    """Print the disk and time estimate of the command (with the compiling of numba kernels not in the cache
    yet, ``cold``, and a line saying so); one line if it does not fit on the disk."""
    if not estimates:
        return []
    both = total(estimates)
    what = f"sweep of {len(estimates)} jobs" if multirun else "run"
    if cold is not None and cold.reported:
        print(cold.line(), file=sys.stderr)
        both = both.with_compiling(cold.seconds)
    print(f"{what}: {both.line()}", file=sys.stderr)
    why = disk_problem(both.mcap_bytes + both.state_bytes, output_root(args, multirun), what)
    return [why] if why else []


def completion(argv: list[str]) -> int:
    """Hydra's completion, with the subcommand word removed from the line it completes; ``install=bash``
    (and uninstall) print Hydra's script, which calls ``cerebx -sc query=bash`` back."""
    if any(a.startswith("query=") for a in argv):
        line = os.environ.get("COMP_LINE", "")
        words = line.split()
        if len(words) <= 1 or (len(words) == 2 and not line.endswith(" ")):
            prefix = words[1] if len(words) == 2 else ""
            print(" ".join(c for c in COMMANDS if c.startswith(prefix)))
            return 0
        os.environ["COMP_LINE"] = re.sub(r"^(\s*\S+)\s+(?:run|validate)\b", r"\1", line)
    sys.argv = [sys.argv[0]] + argv
    run_app()
    return 0
