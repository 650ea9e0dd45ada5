"""``cerebx summarize``: one table of a sweep's jobs (CSV, Markdown, and a plot over numeric swept keys);
printed to standard error when a job failed. Its exit code is the number of failed jobs."""

from __future__ import annotations

import sys

from cerebx.commands.common import fail
from cerebx.report.sweep import report


def main(args: list[str]) -> int:
    if len(args) != 1:
        return fail(["summarize: give one sweep folder (the multirun dir holding 0/, 1/ …)"])
    text, code = report(args[0])
    print(text, file=sys.stderr if code else sys.stdout)
    return code
