"""Every subcommand that ``cerebx --help`` lists prints its usage and exits 0 with ``--help`` or ``-h``."""

from __future__ import annotations

import re

import pytest

from cerebx.cli import COMMANDS, USAGE, main


def _code(args: list[str]) -> int:
    try:
        return main(args)
    except SystemExit as ex:  # argparse and Hydra end --help with SystemExit(0)
        return 0 if ex.code is None else int(ex.code)


def test_the_usage_lists_every_command():
    listed = re.findall(r"^  ([a-z]+) ", USAGE.split("groups:")[0], flags=re.M)
    assert set(listed) == set(COMMANDS)


@pytest.mark.parametrize("flag", ["--help", "-h"])
@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_command_prints_its_usage(command, flag, in_tmp, capsys):
    assert _code([command, flag]) == 0
    out = capsys.readouterr().out
    assert re.search(rf"usage: cerebx {command}\b", out, flags=re.I), out[:400]
    assert not (in_tmp / "runs").exists()


@pytest.mark.integration
def test_the_process_exits_with_the_commands_code_and_all_its_output(tmp_path):
    """``python -m cerebx`` leaves without tearing the interpreter down (``cli.console``): its exit code, every
    line it printed (a whole composed config, piped) and the files of a run are as a normal exit leaves them."""
    import json
    import subprocess
    import sys

    def cerebx(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "cerebx", *args], cwd=tmp_path, capture_output=True, text=True)

    assert cerebx("--version").stdout.startswith("cerebx ")
    bad = cerebx("validate", "+task=nowhere")
    assert bad.returncode == 2 and bad.stderr.startswith("task: unknown option 'nowhere'")
    assert cerebx("run", "--help").returncode == 0  # Hydra's help ends in SystemExit(0)
    shown = cerebx("run", "+experiment=demo", "--cfg", "job")
    assert shown.returncode == 0 and shown.stdout.rstrip().splitlines()[-1].startswith("  ")  # to the last line
    done = cerebx("run", "+experiment=demo", "trials=1", "recording.progress=off", "hydra.run.dir=one")
    assert done.returncode == 0, done.stderr
    assert json.loads((tmp_path / "one" / "summary.json").read_text())["status"] == "completed"
    from cerebx.recording.reader import channel_counts, has_summary

    assert has_summary(tmp_path / "one") and channel_counts(tmp_path / "one")["/trial_metrics"] == 1
