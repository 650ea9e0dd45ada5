"""What every command shares: problems print one ``path: message`` line each and exit with code 2, and an
argument parser whose mistakes are such a line too."""

from __future__ import annotations

import argparse
import sys

from cerebx.errors import CerebxError


def fail(lines: list[str]) -> int:
    for line in lines:
        print(line, file=sys.stderr)
    return 2


class Parser(argparse.ArgumentParser):
    """``argparse`` for a subcommand: ``-h``/``--help`` print its usage (exit 0); a wrong argument is one
    ``cerebx COMMAND: problem`` line and exit code 2 (a :class:`CerebxError`), not a usage block."""

    def __init__(self, prog: str, description: str, **kwargs):
        super().__init__(prog=prog, description=description, allow_abbrev=False, **kwargs)

    def error(self, message: str):  # type: ignore[override]
        raise CerebxError(f"{self.prog}: {message}")
