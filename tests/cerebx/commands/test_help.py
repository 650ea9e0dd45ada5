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
