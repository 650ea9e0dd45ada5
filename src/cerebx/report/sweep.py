"""One table for a sweep (``cerebx summarize MULTIRUN_DIR``, and at the end of every ``cerebx run -m``).

Each job folder of the sweep (``0/``, ``1/`` …) gives one row: the values of the swept overrides (the
keys whose value differs between jobs, from each job's ``.hydra/overrides.yaml``), then its status,
trials done, final MAE (rad), real-time factor and, for a job that did not complete, its one-line
reason, from ``summary.json`` (read with the schema that writes it). A job refused before its run
started (``error.txt``), or whose summary is unreadable, is ``failed``; one that left nothing is
``missing``; one whose process is still alive (another multirun into the same folder) is ``running``
and not counted as failed. Written beside the job folders as ``sweep_summary.csv`` and ``sweep_summary.md``, with
``sweep_summary.png``: final MAE against each swept numeric parameter.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from cerebx import runfiles
from cerebx.errors import CerebxError
from cerebx.recording.summary import SUMMARY_FILE, read_summary
from cerebx.report.plot import plt
from cerebx.sweep import MAX_EXIT_CODE, OK_STATUSES

STEM = "sweep_summary"
RESULT_COLUMNS = ("status", "trials", "final_mae_rad", "rt_factor")


@dataclass(frozen=True)
class JobRow:
    folder: str
    overrides: dict[str, str]
    status: str
    trials: str
    final_mae_rad: float | None
    rt_factor: float | None
    reason: str = ""

    @property
    def failed(self) -> bool:
        """Not a result, and not a run still going in another process (``running`` after reading means its
        process is alive: a dead one reads as ``killed``), e.g. a sibling multirun writing to the same folder."""
        return self.status not in (*OK_STATUSES, "running")


def _overrides(job_dir: Path) -> dict[str, str]:
    path = job_dir / runfiles.OVERRIDES
    try:
        items = yaml.safe_load(path.read_text()) or []
    except (OSError, yaml.YAMLError):
        return {}
    out = {}
    for item in items:
        key, sep, value = str(item).partition("=")
        if sep:
            out[key.lstrip("+~")] = value
    return out


def _first_line(text: str | None) -> str:
    return text.strip().splitlines()[0] if text and text.strip() else ""


def _job_row(job_dir: Path) -> JobRow:
    over = _overrides(job_dir)
    if (job_dir / runfiles.ERROR).exists():  # refused before its run started
        return JobRow(job_dir.name, over, "failed", "", None, None, _first_line((job_dir / runfiles.ERROR).read_text()))
    if not (job_dir / SUMMARY_FILE).exists():
        return JobRow(job_dir.name, over, "missing", "", None, None, "the job left no summary.json")
    try:
        s: dict[str, Any] = read_summary(job_dir)
    except CerebxError as err:
        return JobRow(job_dir.name, over, "failed", "", None, None, str(err))
    return JobRow(job_dir.name, over, s["status"], f"{s['trials_completed']}/{s['trials']}", s["final_mae"],
                  s["rt_factor"], "" if s["status"] == "completed" else _first_line(s.get("error")))


def job_dirs(sweep_dir: Path) -> list[Path]:
    """The job folders of a sweep, in job order (Hydra names them by job number)."""
    dirs = [p for p in sweep_dir.iterdir() if p.is_dir() and not p.name.startswith(".")
            and ((p / runfiles.SUMMARY).exists() or (p / runfiles.HYDRA).is_dir())]
    return sorted(dirs, key=lambda p: (0, int(p.name), "") if p.name.isdigit() else (1, 0, p.name))


def swept_keys(rows: list[JobRow], sweep_dir: Path | None = None) -> list[str]:
    """The swept overrides: those given as a sweep (``a,b``, ``range(…)``, ``choice(…)``) in the sweep's
    ``multirun.yaml``, else those whose value is not the same in every job; in the order they appear."""
    keys: dict[str, None] = {}
    for r in rows:
        keys.update(dict.fromkeys(r.overrides))
    declared: set[str] = set()
    try:
        task = yaml.safe_load((sweep_dir / "multirun.yaml").read_text())["hydra"]["overrides"]["task"]
        for item in task or []:
            key, _, value = str(item).partition("=")
            if "," in value or value.startswith(("range(", "choice(", "interval(", "glob(")):
                declared.add(key.lstrip("+~"))
    except (TypeError, OSError, KeyError, yaml.YAMLError):
        pass
    return [k for k in keys if k in declared or len({r.overrides.get(k) for r in rows}) > 1]


def _number(text: str | None) -> float | None:
    try:
        v = float(str(text).strip("'\""))
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _fmt(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.4f}" if abs(v) < 1000 else f"{v:.1f}"
    return str(v)


@dataclass(frozen=True)
class SweepSummary:
    sweep_dir: Path
    keys: list[str]
    rows: list[JobRow]

    @property
    def failed(self) -> int:
        """Jobs that did not run to a result (diverging is a result of the experiment, not a failure)."""
        return sum(r.failed for r in self.rows)

    def exit_code(self) -> int:
        return min(self.failed, MAX_EXIT_CODE)

    def table(self) -> list[list[str]]:
        reasons = any(r.reason for r in self.rows)
        head = ["job", *self.keys, *RESULT_COLUMNS, *(["reason"] if reasons else [])]
        body = [[r.folder, *(r.overrides.get(k, "") for k in self.keys), r.status, r.trials,
                 _fmt(r.final_mae_rad), _fmt(r.rt_factor), *([r.reason] if reasons else [])] for r in self.rows]
        return [head, *body]

    def outcome(self) -> str:
        n = len(self.rows)
        running = sum(r.status == "running" for r in self.rows)
        line = f"sweep {self.sweep_dir}: {n - self.failed - running} of {n} jobs completed"
        line += f", {running} still running in another process" if running else ""
        return line + (f", {self.failed} failed (exit code {self.exit_code()})" if self.failed else "")

    def markdown(self) -> str:
        head, *body = self.table()
        lines = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
        lines += ["| " + " | ".join(row) + " |" for row in body]
        return "\n".join(lines) + "\n"

    def numeric_keys(self) -> list[str]:
        """Swept keys whose every value is a number (the ones worth a plot)."""
        return [k for k in self.keys if all(_number(r.overrides.get(k)) is not None for r in self.rows)]


def summarize(sweep_dir: Path | str) -> SweepSummary:
    sweep_dir = Path(sweep_dir)
    if not sweep_dir.is_dir():
        raise CerebxError(f"{sweep_dir}: no such folder")
    rows = [_job_row(d) for d in job_dirs(sweep_dir)]
    if not rows:
        raise CerebxError(f"{sweep_dir}: no job folders (expected 0/, 1/ … with summary.json)")
    return SweepSummary(sweep_dir, swept_keys(rows, sweep_dir), rows)


def write(summary: SweepSummary) -> list[Path]:
    """Write the CSV, the Markdown and (when a swept parameter is numeric) the plot; return their paths."""
    out = summary.sweep_dir
    paths = [out / f"{STEM}.csv", out / f"{STEM}.md"]
    with open(paths[0], "w", newline="") as fh:
        csv.writer(fh).writerows(summary.table())
    paths[1].write_text(summary.markdown())
    numeric = summary.numeric_keys()
    if numeric:
        paths.append(_plot(summary, numeric, out / f"{STEM}.png"))
    return paths


def _plot(summary: SweepSummary, keys: list[str], path: Path) -> Path:
    fig, axes = plt.subplots(1, len(keys), figsize=(4.2 * len(keys), 3.4), squeeze=False)
    for ax, key in zip(axes[0], keys):
        pts = sorted((_number(r.overrides.get(key)), r.final_mae_rad) for r in summary.rows
                     if r.final_mae_rad is not None)
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o", color="tab:blue")
        ax.set_xlabel(key)
        ax.set_ylabel("final MAE (rad)")
        ax.grid(alpha=0.3)
    fig.suptitle(str(summary.sweep_dir), fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def report(sweep_dir: Path | str) -> tuple[str, int]:
    """Summarize and write the files; return what to print and the exit code (the number of failed jobs)."""
    s = summarize(sweep_dir)
    paths = write(s)
    return s.markdown() + "written: " + ", ".join(str(p) for p in paths) + "\n" + s.outcome(), s.exit_code()


def main(args: list[str]) -> int:
    if len(args) != 1:
        print("summarize: give one sweep folder (the multirun dir holding 0/, 1/ …)")
        return 2
    text, code = report(args[0])
    print(text)
    return code
