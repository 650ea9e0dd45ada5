"""``cerebx bench``: speed of the plant, the networks and the closed loop, printed as JSON."""

from __future__ import annotations

import json

from cerebx.bench_cli import main as bench_main


def main(args: list[str]) -> int:
    print(json.dumps(bench_main(args), indent=2))
    return 0
