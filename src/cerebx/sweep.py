"""A ``cerebx run -m`` sweep that survives a bad job: every job runs, a failing one leaves its folder with
status ``failed`` and a one-line reason, and the sweep ends with a per-job table and an exit code equal to
the number of failed jobs (capped at 100; 0 when all completed).

The command line fixes the sweep folder itself (``hydra.sweep.dir``, the same pattern as Hydra's default)
so that it can read every job's folder afterwards, whichever launcher ran the jobs; the table itself is
``cerebx.report.sweep`` (also ``cerebx summarize``).
"""

from __future__ import annotations

import datetime as _dt
from pathlib import Path

MAX_EXIT_CODE = 100
OK_STATUSES = ("completed", "diverged")  # diverging is a result of the experiment, not a failure of the job


def sweep_dir(args: list[str]) -> tuple[Path | None, list[str]]:
    """The sweep folder of a ``-m`` command, and the arguments with ``hydra.sweep.dir`` set to it (None when
    the user's own folder is only known after Hydra resolves it: then no table is printed)."""
    for a in args:
        if a.lstrip("+").startswith("hydra.sweep.dir="):
            value = a.split("=", 1)[1].strip("'\"")
            return (None if "${" in value else Path(value)), args
    now = _dt.datetime.now()
    d = Path("runs") / "multirun" / now.strftime("%Y-%m-%d") / now.strftime("%H-%M-%S-%f")
    return d, [*args, f"hydra.sweep.dir={d}"]
