"""The sample outputs on the getting-started pages are what the commands print today: runs are deterministic, so
every line of a shown run that does not depend on the clock (setup, trials, MAE, windows, per joint) must be
printed again, digit for digit, by the command shown above it (or, for ``cerebx inspect``, by the run of the same
setup and trials shown elsewhere). Runs of more than ``QUICK_TRIALS`` trials are checked by the slow tier."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from cerebx.cli import main

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[2]
PAGES = sorted((ROOT / "docs" / "getting-started").glob("*.md"))
BLOCK = re.compile(r"```(\w+)\n(.*?)```", re.S)
STABLE = ("setup", "trials", "MAE", "windows", "per joint")
QUICK_TRIALS = 10
ALIASES = {"make run": "cerebx run +experiment=default"}  # the Makefile's RUN_ARGS default


def _stable(text: str) -> list[str]:
    """The output's lines that do not depend on the clock or the folder."""
    return [" ".join(line.split()) for line in text.splitlines() if line.startswith(STABLE)]


def _samples() -> list[tuple[str, str, list[str]]]:
    """(page, command, stable lines) of every shown run output, with the command that printed it."""
    found = []
    for page in PAGES:
        blocks = BLOCK.findall(page.read_text())
        for (lang, code), (next_lang, out) in zip(blocks, blocks[1:], strict=False):
            stable = _stable(out)
            if lang != "bash" or next_lang != "text" or not any(s.startswith("setup") for s in stable):
                continue
            command = ALIASES.get(code.strip().splitlines()[0].split("#")[0].strip(), code.strip().splitlines()[0])
            found.append((page.name, command.split("#")[0].strip(), stable))
    return found


def _by_setup(samples) -> dict[tuple[str, str], str]:
    """The ``cerebx run`` command of each (setup, trials) shown, for the ``cerebx inspect`` samples."""
    out = {}
    for _, command, stable in samples:
        key = tuple(s for s in stable if s.startswith(("setup", "trials")))
        if command.startswith("cerebx run"):
            out.setdefault(key, command)
    return out


SAMPLES = _samples()
RUNS = _by_setup(SAMPLES)


def _trials(stable: list[str]) -> int:
    return int(next(s for s in stable if s.startswith("trials")).split()[1].split("/")[1])


def _run_args(command: str, stable: list[str]) -> list[str]:
    if command.startswith("cerebx inspect"):
        command = RUNS[tuple(s for s in stable if s.startswith(("setup", "trials")))]
    args = shlex.split(command)[2:]
    return [a for a in args if not a.startswith(("live.", "hydra.run.dir"))]


@pytest.fixture(scope="module")
def printed(tmp_path_factory):
    """What each distinct command prints (run once per module)."""
    cache: dict[tuple[str, ...], list[str]] = {}

    def run(args: list[str], capsys) -> list[str]:
        if tuple(args) not in cache:
            folder = tmp_path_factory.mktemp("run")
            capsys.readouterr()
            assert main(["run", *args, f"hydra.run.dir={folder / 'run'}", "recording.progress=off"]) == 0
            cache[tuple(args)] = _stable(capsys.readouterr().out)
        return cache[tuple(args)]

    return run


def test_the_pages_show_runs_to_check():
    assert len(SAMPLES) >= 4 and any(c.startswith("cerebx inspect") for _, c, _ in SAMPLES)


@pytest.mark.parametrize(("page", "command", "shown"), [
    pytest.param(*s, id=f"{s[0]}:{s[1]}", marks=[pytest.mark.slow] if _trials(s[2]) > QUICK_TRIALS else [])
    for s in SAMPLES])
def test_a_shown_output_is_what_the_command_prints(page, command, shown, printed, capsys):
    got = printed(_run_args(command, shown), capsys)
    assert shown == [line for line in got if line.startswith(tuple(s.split()[0] for s in shown))], (
        f"docs/getting-started/{page}: the output shown for `{command}` differs from what it prints now")
