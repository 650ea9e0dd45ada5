"""``cerebx summarize``: one table of a sweep's jobs (CSV, Markdown, and a plot over numeric swept keys). Its
exit code is the number of failed jobs. ``--end-of-sweep`` (how ``cerebx run -m`` calls it) prints the table to
standard error when a job failed."""

from __future__ import annotations

import sys

from cerebx.commands.common import fail
from cerebx.report.sweep import report


def main(args: list[str]) -> int:
    end_of_sweep = "--end-of-sweep" in args
    folders = [a for a in args if a != "--end-of-sweep"]
    if len(folders) != 1:
        return fail(["summarize: give one sweep folder (the multirun dir holding 0/, 1/ …)"])
    text, code = report(folders[0])
    print(text, file=sys.stderr if code and end_of_sweep else sys.stdout)
    return code
