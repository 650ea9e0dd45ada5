"""``cerebx summarize``: one table of a sweep's jobs (CSV, Markdown, and a plot over numeric swept keys). Its
exit code is the number of failed jobs. ``--end-of-sweep`` (how ``cerebx run -m`` calls it) prints the table to
standard error when a job failed."""

from __future__ import annotations

import argparse
import sys

from cerebx.commands.common import Parser
from cerebx.report.sweep import report


def parser() -> Parser:
    """The command's one argument: a sweep folder."""
    ap = Parser("cerebx summarize", "one table of a sweep's jobs (CSV, Markdown, and a plot over numeric swept "
                "keys); the exit code is the number of failed jobs")
    ap.add_argument("folder", help="the sweep folder (MULTIRUN_DIR, holding the jobs' folders 0/, 1/ ...)")
    ap.add_argument("--end-of-sweep", action="store_true", help=argparse.SUPPRESS)
    return ap


def main(args: list[str]) -> int:
    ns = parser().parse_args(args)
    text, code = report(ns.folder)
    print(text, file=sys.stderr if code and ns.end_of_sweep else sys.stdout)
    return code
