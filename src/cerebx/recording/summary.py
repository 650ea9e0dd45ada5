"""``summary.json``: one schema for the runner that writes it and every reader (inspect, report, studies).

The runner writes it with status ``running`` before the first trial and rewrites it (atomically) after
every trial, so a run that is hard-killed (SIGKILL, an OOM kill, power loss) still has one. A reader
that finds ``running`` whose process is gone shows the run as ``killed`` with the trials it finished.
Extra keys are kept (other tools add their own, e.g. segments of a resumable run).
"""

from __future__ import annotations

import json
import os
import socket
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from cerebx import runfiles
from cerebx.errors import CerebxError
from cerebx.metrics import final_mae

SUMMARY_FILE = runfiles.SUMMARY

Status = Literal["running", "completed", "interrupted", "diverged", "failed", "killed"]


class RunSummary(BaseModel):
    """What a run folder says about its run; the per-trial lists have one entry per finished trial."""

    model_config = ConfigDict(extra="allow")

    status: Status = Field(description="running while the process lives; killed: it died without a word")
    task: str = Field(description="task kind")
    controller: str = Field(description="controller kind")
    plant: str = Field(description="plant kind")
    delay: str = Field(description="delay kind")
    network: str | None = Field(None, description="name of the controller's spiking network (null: it has none)")
    seed: int = Field(ge=0)
    trials: int = Field(ge=1, description="trials asked for")
    warmup_trials: int = Field(0, ge=0)
    trials_completed: int = Field(0, ge=0)
    mae_per_trial: list[float] = Field(default_factory=list, description="mean absolute joint error per trial, rad")
    final_mae: float | None = Field(None, description="mean MAE of the last 10 % of trials, rad")
    sim_seconds: float = Field(0.0, ge=0, description="simulated time, s")
    wall_seconds: float = Field(0.0, ge=0, description="wall-clock time, s")
    rt_factor: float | None = Field(None, description="simulated seconds per wall second")
    cpu_seconds: float | None = Field(None, ge=0, description="CPU time of the run's process from the run's start, "
                                      "all threads, s (a continued run: of its last process)")
    error: str | None = None
    mae_per_joint_per_trial: list[list[float]] = Field(default_factory=list, description="rad, per trial and joint")
    vel_mae_per_trial: list[float] = Field(default_factory=list, description="rad/s")
    torque_variability_per_trial: list[float] = Field(default_factory=list, description="N·m/ms")
    ee_error_per_trial: list[float | None] = Field(default_factory=list, description="end-effector error, m")
    presets: dict[str, str] = Field(default_factory=dict, description="option chosen in each config group")
    overrides: list[str] = Field(default_factory=list, description="command-line overrides")
    controller_info: dict[str, Any] = Field(default_factory=dict, description="static facts of the controller")
    version: str | None = None
    started_at: float | None = Field(None, description="Unix time the run started, s")
    pid: int | None = Field(None, ge=1, description="process that writes the run (to tell running from killed)")
    host: str | None = Field(None, description="host of that process")


def network_name(controller: Any) -> str | None:
    """The name of the spiking network a controller (or a part of a composite one) runs, or None."""
    net = getattr(controller, "network", None)
    if net is not None:
        return net.name
    names = [n for part in getattr(controller, "parts", ()) if (n := network_name(part))]
    return names[0] if names else None


def new_summary(cfg: Any, **fields: Any) -> dict[str, Any]:
    """The summary a run starts with: status running, nothing done yet."""
    return {"status": "running", "task": cfg.task.kind, "controller": cfg.controller.kind,
            "plant": cfg.plant.kind, "delay": cfg.delay.kind, "network": network_name(cfg.controller), "seed": cfg.seed,
            "trials": cfg.trials, "warmup_trials": cfg.warmup_trials, "trials_completed": 0,
            "mae_per_trial": [], "final_mae": None, "sim_seconds": 0.0, "wall_seconds": 0.0, "rt_factor": None,
            "error": None, "pid": os.getpid(), "host": socket.gethostname(), **fields}


def write_summary(run_dir: Path, summary: dict[str, Any]) -> None:
    """Write atomically: a reader (or a kill) never sees half a file."""
    path = Path(run_dir) / SUMMARY_FILE
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(summary, indent=2))
    os.replace(tmp, path)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except PermissionError:  # someone else's process
        return True
    except (OSError, OverflowError):  # no such process (or no possible one)
        return False
    return True


def is_killed(s: dict[str, Any]) -> bool:
    """A ``running`` summary whose process (on this host) no longer exists."""
    if s.get("status") != "running" or s.get("host") != socket.gethostname():
        return False
    pid = s.get("pid")
    return isinstance(pid, int) and not _alive(pid)


def validate_summary(data: Any, where: Path | str) -> dict[str, Any]:
    """The checked summary as a plain dict (extra keys kept); one line naming the first problem if not."""
    try:
        s = RunSummary.model_validate(data).model_dump()
    except ValidationError as err:
        e = err.errors()[0]
        # a key from the file may hold line breaks or control characters: shown escaped, on one line
        loc = ".".join(str(p) if str(p).isprintable() else repr(str(p))[1:-1] for p in e["loc"]) or "<root>"
        more = f" (+{err.error_count() - 1} more)" if err.error_count() > 1 else ""
        raise CerebxError(f"{where}: {loc}: {e['msg']}{more}") from None
    if is_killed(s):
        s["status"] = "killed"
        s["error"] = s.get("error") or "the process ended without finishing the run (SIGKILL, OOM kill or power loss)"
    return s


def read_summary(run_dir: Path | str) -> dict[str, Any]:
    """Read and validate ``RUN_DIR/summary.json``; a missing, unreadable or wrong-shaped file is one line.

    Parameters
    ----------
    run_dir : Path or str
        The run folder.

    Returns
    -------
    dict
        The summary (a ``running`` one whose process is gone reads as ``killed``).
    """
    p = Path(run_dir) / SUMMARY_FILE
    try:
        text = p.read_text()
    except FileNotFoundError:
        raise CerebxError(f"{p}: no such file (not a cerebx run folder?)") from None
    except (OSError, UnicodeDecodeError) as err:
        raise CerebxError(f"{p}: cannot be read ({type(err).__name__})") from None
    try:
        data = json.loads(text)
    except json.JSONDecodeError as err:
        raise CerebxError(f"{p}: not valid JSON ({err})") from None
    return validate_summary(data, p)


def trial_fields(metrics: list[Any], sim_seconds: float) -> dict[str, Any]:
    """The per-trial lists and totals of a summary from the loop's trial metrics so far."""
    mae = [m.mae for m in metrics]
    return {"trials_completed": len(metrics), "mae_per_trial": mae,
            "mae_per_joint_per_trial": [list(m.mae_per_joint) for m in metrics],
            "vel_mae_per_trial": [m.vel_mae for m in metrics],
            "torque_variability_per_trial": [m.torque_variability_Nm_per_ms for m in metrics],
            "ee_error_per_trial": [m.ee_error_m for m in metrics],
            "final_mae": final_mae(mae), "sim_seconds": sim_seconds}


def finish_run(rec: Any, run_dir: Path, summary: dict[str, Any], sentinel: Any) -> None:
    """The last step of every run, whatever ended it: the summary into the log's metadata, the log closed
    (its summary and footer written), ``summary.json`` written, the sentinel told the run ended itself."""
    try:
        rec.metadata("summary", {"json": json.dumps(summary)})
    finally:
        rec.close()
        write_summary(run_dir, summary)
        sentinel.done()
