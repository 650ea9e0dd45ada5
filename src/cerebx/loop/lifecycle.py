"""One owner of a run's lifecycle, for the simulated loop (``loop/runner.py``) and both sides of a real link
(``loop/brain_side.py``, ``loop/robot_side.py``).

Opening: ``summary.json`` saying ``running``, the sentinel that finishes the files if the process is
hard-killed, the log (``run.mcap``) with the run's version, overrides and config in its metadata. Closing,
whatever ended the run: the exception (if any) becomes the summary's status and error, a run still
``running`` is ``failed``, the closing steps the caller registered run in order (trial totals, timing,
the controller state, a goodbye to the other side), then the summary goes into the log, the log is
closed and ``summary.json`` written. ``Exception`` and ``KeyboardInterrupt`` end here (the caller's
exit code follows the status); anything else (``SystemExit``) is recorded and raised again.

    with RunLifecycle(cfg, run_dir, ...) as life:
        @life.on_close
        def _totals() -> None: ...
        for trial in range(cfg.trials):
            ...
            life.progress(metrics, sim_seconds)
        life.completed()
"""

from __future__ import annotations

import json
import logging
import time
from collections.abc import Callable
from pathlib import Path
from types import TracebackType
from typing import Any

from cerebx import __version__, phase_clock, runfiles
from cerebx.errors import outcome
from cerebx.recording.recorder import Recorder
from cerebx.recording.sentinel import Sentinel
from cerebx.recording.summary import finish_run, new_summary, trial_fields, write_summary

log = logging.getLogger("cerebx")


class RunLifecycle:
    """A run's files from ``running`` to its last status; a context manager (see the module docstring).

    Parameters
    ----------
    cfg
        The validated experiment config (its task, controller, seed... start the summary).
    run_dir
        The run's folder (made if missing).
    log_path
        Where the MCAP log goes (default ``run_dir/run.mcap``; a continued run writes a new segment).
    compression
        The log's chunk compression (default ``cfg.recording.compression``).
    overrides
        The command-line overrides (in the summary and the log's metadata).
    resolved
        The config as recorded in the log (default: ``cfg.model_dump(mode="json")``).
    fields
        More keys of the starting summary (``presets``, ``side``).
    metadata
        More metadata records of the log, by name (e.g. ``link``).
    live
        A live view the recorder feeds (stopped when the run's files are finished).
    """

    def __init__(self, cfg: Any, run_dir: Path, *, log_path: Path | None = None, compression: str | None = None,
                 overrides: list[str] | None = None, resolved: dict | None = None,
                 fields: dict[str, Any] | None = None, metadata: dict[str, dict[str, str]] | None = None,
                 live: Any = None):
        self.cfg = cfg
        self.run_dir = Path(run_dir)
        self.run_dir.mkdir(parents=True, exist_ok=True)
        self.wall0 = time.perf_counter()
        self.cpu0 = time.process_time()
        self.error: BaseException | None = None
        self._closing: list[Callable[[], None]] = []
        self._live = live
        overrides = list(overrides or [])
        self.summary: dict[str, Any] = new_summary(cfg, version=__version__, overrides=overrides,
                                                   started_at=time.time(), **(fields or {}))
        write_summary(self.run_dir, self.summary)
        self.sentinel = Sentinel(self.run_dir)  # finishes the log and summary.json if this process is hard-killed
        self.rec = Recorder(log_path or self.run_dir / runfiles.MCAP, chunk_size_kb=cfg.recording.chunk_size_kb,
                            compression=compression or cfg.recording.compression, live=live)
        self.rec.metadata("cerebx", {"version": __version__, "overrides": json.dumps(overrides)})
        self.rec.metadata("config", {"json": json.dumps(resolved if resolved is not None
                                                        else cfg.model_dump(mode="json"))})
        for name, record in (metadata or {}).items():
            self.rec.metadata(name, record)

    @property
    def status(self) -> str:
        return self.summary["status"]

    def on_close(self, step: Callable[[], None]) -> Callable[[], None]:
        """Register a closing step (run in the order registered, after the status is known, before the log
        is closed); usable as a decorator."""
        self._closing.append(step)
        return step

    def progress(self, metrics: list[Any], sim_seconds: float, **more: Any) -> None:
        """The trials so far into ``summary.json`` (atomically: a kill leaves the last whole one)."""
        self.summary.update(trial_fields(metrics, sim_seconds), **more)
        write_summary(self.run_dir, self.summary)

    def completed(self) -> None:
        """Every trial ran: the run ends ``completed`` (unless a closing step raises)."""
        self.summary["status"] = "completed"

    def save_state(self, controller: Any) -> None:
        """The controller's learned state into ``run_dir/state`` when the config asks for it. The state is a
        bonus: a failure is logged and kept in the summary as ``state_error``, and the run's files are still
        finished."""
        if not self.cfg.recording.save_state:
            return
        try:
            with phase_clock.span("save_state"):
                controller.save_state(self.run_dir / runfiles.STATE)
        except Exception as err:
            log.error("could not save controller state: %s", err)
            self.summary["state_error"] = str(err)

    def __enter__(self) -> RunLifecycle:
        return self

    def __exit__(self, kind: type[BaseException] | None, err: BaseException | None,
                 tb: TracebackType | None) -> bool:
        if err is not None:
            self.error = err
            self.summary.update(outcome(err))
        if self.summary["status"] == "running":
            self.summary["status"] = "failed"
        try:
            for step in self._closing:
                step()
        finally:
            try:
                finish_run(self.rec, self.run_dir, self.summary, self.sentinel)
            finally:
                if self._live is not None:
                    self._live.stop()
        return isinstance(err, (Exception, KeyboardInterrupt))
