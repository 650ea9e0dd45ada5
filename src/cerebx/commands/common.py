"""What every command shares: problems print one ``path: message`` line each and exit with code 2."""

from __future__ import annotations

import sys


def fail(lines: list[str]) -> int:
    for line in lines:
        print(line, file=sys.stderr)
    return 2
