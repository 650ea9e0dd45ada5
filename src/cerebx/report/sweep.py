"""One table for a sweep (``cerebx summarize MULTIRUN_DIR``, and at the end of every ``cerebx run -m``).

Each job folder of the sweep (``0/``, ``1/`` …) gives one row: the values of the swept overrides (the
keys whose value differs between jobs, from each job's ``.hydra/overrides.yaml``), then its status,
trials done, final MAE (rad) and real-time factor from ``summary.json``. A job that left no summary is
a row with status ``missing``. Written beside the job folders as ``sweep_summary.csv`` and
``sweep_summary.md``, with ``sweep_summary.png``: final MAE against each swept numeric parameter.
"""

from __future__ import annotations

import csv
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from hydra.experimental.callback import Callback

from cerebx.errors import CerebxError

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


def _overrides(job_dir: Path) -> dict[str, str]:
    path = job_dir / ".hydra" / "overrides.yaml"
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


def _job_row(job_dir: Path) -> JobRow:
    try:
        s: dict[str, Any] = json.loads((job_dir / "summary.json").read_text())
    except (OSError, json.JSONDecodeError):
        s = {"status": "missing"}
    done, total = s.get("trials_completed"), s.get("trials")
    return JobRow(job_dir.name, _overrides(job_dir), str(s.get("status", "unknown")),
                  f"{done}/{total}" if total is not None else "", s.get("final_mae"), s.get("rt_factor"))


def job_dirs(sweep_dir: Path) -> list[Path]:
    """The job folders of a sweep, in job order (Hydra names them by job number)."""
    dirs = [p for p in sweep_dir.iterdir() if p.is_dir() and not p.name.startswith(".")
            and ((p / "summary.json").exists() or (p / ".hydra").is_dir())]
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

    def table(self) -> list[list[str]]:
        head = ["job", *self.keys, *RESULT_COLUMNS]
        body = [[r.folder, *(r.overrides.get(k, "") for k in self.keys), r.status, r.trials,
                 _fmt(r.final_mae_rad), _fmt(r.rt_factor)] for r in self.rows]
        return [head, *body]

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
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

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


def report(sweep_dir: Path | str) -> str:
    """Summarize, write the files, and return what to print."""
    s = summarize(sweep_dir)
    paths = write(s)
    return s.markdown() + "written: " + ", ".join(str(p) for p in paths)


def main(args: list[str]) -> int:
    if len(args) != 1:
        print("summarize: give one sweep folder (the multirun dir holding 0/, 1/ …)")
        return 2
    print(report(args[0]))
    return 0


class PrintSweepSummary(Callback):
    """Hydra callback (registered by ``cerebx.app`` in code): the sweep's table when a multirun ends."""

    def on_multirun_end(self, config: Any, **kwargs: Any) -> None:
        try:
            print(report(config.hydra.sweep.dir), flush=True)
        except CerebxError as err:
            print(f"sweep summary: {err}", flush=True)
