"""A ``cerebx run -m`` sweep that survives a bad job: every job runs, a failing one leaves its folder with
status ``failed`` and a one-line reason, and the sweep ends with a per-job table and an exit code equal to
the number of failed jobs (capped at 100; 0 when all completed).

The command line fixes the sweep folder itself (``hydra.sweep.dir``, the same pattern as Hydra's default)
so that it can read every job's folder afterwards, whichever launcher ran the jobs.
"""

from __future__ import annotations

import datetime as _dt
from pathlib import Path

import yaml

from cerebx.errors import CerebxError
from cerebx.recording.summary import read_summary

ERROR_FILE = "error.txt"
"""Written into a job folder when the job failed before its run could start (its config was refused)."""

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


def _job_overrides(job: Path) -> str:
    try:
        return " ".join(yaml.safe_load((job / ".hydra" / "overrides.yaml").read_text()) or [])
    except (OSError, yaml.YAMLError, TypeError):
        return ""


def _job_row(job: Path) -> tuple[list[str], bool]:
    """(table row, whether the job failed) of one job folder."""
    over = _job_overrides(job)
    if (job / ERROR_FILE).exists():
        return [job.name, "failed", "-", "-", over, (job / ERROR_FILE).read_text().strip().splitlines()[0]], True
    try:
        s = read_summary(job)
    except CerebxError as err:
        return [job.name, "failed", "-", "-", over, str(err)], True
    mae = s.get("final_mae")
    row = [job.name, s["status"], f"{s['trials_completed']}/{s['trials']}", "-" if mae is None else f"{mae:.4f}",
           over, (s.get("error") or "").splitlines()[0] if s.get("error") else ""]
    return row, s["status"] not in OK_STATUSES


def table(root: Path) -> tuple[list[str], int]:
    """The per-job table of a finished sweep (one line per job) and the number of jobs that failed."""
    jobs = sorted((p for p in root.iterdir() if p.is_dir() and p.name.isdigit()), key=lambda p: int(p.name)) \
        if root.is_dir() else []
    rows = [["job", "status", "trials", "final MAE (rad)", "overrides", "reason"]]
    failed = 0
    for job in jobs:
        row, bad = _job_row(job)
        rows.append(row)
        failed += bad
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]) - 1)]
    lines = ["  ".join(c.ljust(w) for c, w in zip(r, widths)) + "  " + r[-1] for r in rows]
    lines.append(f"sweep {root}: {len(jobs) - failed} of {len(jobs)} jobs completed"
                 + (f", {failed} failed (exit code {min(failed, MAX_EXIT_CODE)})" if failed else ""))
    return [ln.rstrip() for ln in lines], failed
