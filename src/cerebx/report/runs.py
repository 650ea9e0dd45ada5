"""Run folders as the report sees them: summary, resolved config and log, selected by content.

Figures never look at folder names: they ask for "circle runs of the snn controller under a constant
delay" and get whatever runs match, so any past run folder can be re-plotted. Where a study was learned from
several seeds, the figure's curves are drawn from the lowest seed (:meth:`RunSet.best` prefers it) and its
headline numbers are taken over every seed (:meth:`RunSet.seeds`).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from cerebx import runfiles
from cerebx.errors import CerebxError
from cerebx.metrics import torque_variability_of_mean
from cerebx.recording.reader import read_messages, read_metadata, read_summary
from cerebx.schema.legacy import upgrade
from cerebx.schema.window import TrialWindow


@dataclass
class Run:
    """One run folder as the report reads it: its summary, and its config and log read on first use.

    Parameters
    ----------
    dir : Path
        The run folder.
    summary : dict
        Its ``summary.json`` (:meth:`Run.load` reads both).
    """
    dir: Path
    summary: dict[str, Any]
    _config: dict[str, Any] | None = field(default=None, repr=False)
    _cache: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    @classmethod
    def load(cls, run_dir: Path | str) -> Run:
        d = Path(run_dir)
        return cls(d, read_summary(d))

    # ---- the resolved configuration (recorded as MCAP metadata) ------------------------------
    @cached_property
    def config(self) -> dict[str, Any]:
        if self._config is not None:
            return self._config
        try:
            return upgrade(json.loads(read_metadata(self.dir)["config"]["json"]))
        except (CerebxError, KeyError, OSError, json.JSONDecodeError):
            return {}

    def get(self, dotted: str, default: Any = None) -> Any:
        node: Any = self.config
        for part in dotted.split("."):
            if not isinstance(node, dict) or part not in node:
                return default
            node = node[part]
        return node

    # ---- what the figures select on ----------------------------------------------------------
    @property
    def name(self) -> str:
        return self.dir.name

    @property
    def task(self) -> str:
        return self.summary["task"]

    @property
    def seed(self) -> int:
        return int(self.summary.get("seed") or 0)

    @property
    def controller(self) -> str:
        return self.summary["controller"]

    @property
    def controller_preset(self) -> str:
        return (self.summary.get("presets") or {}).get("controller", self.controller)

    @property
    def delay(self) -> str:
        """The delay kind (none, constant, gamma, percentiles, trace)."""
        return self.summary["delay"]

    @property
    def delay_preset(self) -> str:
        return (self.summary.get("presets") or {}).get("delay", self.delay)

    @property
    def delay_total_ms(self) -> float | None:
        """The constant round-trip delay, 0 without delay, None for random delays."""
        if self.delay == "none":
            return 0.0
        if self.delay == "constant":
            total = self.get("delay.total_ms")  # None when the log's config cannot be read
            return None if total is None else float(total)
        return None

    @property
    def network(self) -> str:
        return self.summary.get("network", "")

    @property
    def kernel_peaks_ms(self) -> list[float]:
        """Peak (ms) of every plastic projection's PF-PC kernel, in network order."""
        projections = self.get("controller.network.projections", {}) or {}
        return [float(p["plasticity"]["kernel_peak_ms"]) for p in projections.values()
                if isinstance(p, dict) and (p.get("plasticity") or {}).get("kind") == "kernel_stdp"]

    @property
    def learned_from(self) -> str | None:
        return self.get("init_from")

    def learned_from_dirs(self) -> list[Path]:
        """Where the run folder it started from may be: ``init_from`` as recorded, or, when relative (to
        where the run was started), below each folder above this run, nearest first."""
        if not self.learned_from:
            return []
        p = Path(self.learned_from)
        return [p] if p.is_absolute() else [*(a / p for a in self.dir.absolute().parents), p]

    @property
    def events(self) -> list[dict[str, Any]]:
        return self.get("events", []) or []

    @property
    def is_factory_position(self) -> bool:
        """The stand-in for the factory position controller: preset ``position_factory`` or, for a run that
        recorded no preset, a position controller without velocity feed-forward (the stiff servo has it)."""
        return self.controller == "position" and (self.controller_preset == "position_factory"
                                                  or self.get("controller.velocity_feedforward") is False)

    @property
    def completed(self) -> bool:
        return self.summary.get("status") == "completed"

    @property
    def trials(self) -> int:
        return int(self.summary.get("trials_completed") or 0)

    @property
    def period_s(self) -> float:
        return self.summary["sim_seconds"] / max(self.trials, 1)

    @property
    def warmup(self) -> int:
        """Leading trials in which a learned controller settled onto the path (not measured)."""
        return int(self.summary.get("warmup_trials") or 0)

    @property
    def n_measured(self) -> int:
        return max(0, self.trials - self.warmup)

    def series(self, key: str) -> np.ndarray:
        """A per-trial list from the summary (mae_per_trial, torque_variability_per_trial, ...), without
        the warm-up trials."""
        return np.asarray(self.summary.get(key) or [], dtype=float)[self.warmup:]

    @property
    def mae(self) -> np.ndarray:
        return self.series("mae_per_trial")

    def messages(self, topics: list[str], t0: float | None = None, t1: float | None = None) -> Iterator:
        """(topic, t in s, message) of the run's log between t0 and t1 seconds."""
        lo = None if t0 is None else int(round(t0 * 1e9))
        hi = None if t1 is None else int(round(t1 * 1e9))
        for topic, t, msg in read_messages(self.dir, topics, start_ns=lo, end_ns=hi):
            yield topic, t / 1e9, msg

    @property
    def window(self) -> TrialWindow | None:
        """The trials whose control steps the log holds (``recording.trials``); None: every trial."""
        value = self.get("recording.trials")
        if value in (None, "all"):
            return None
        try:
            return TrialWindow.model_validate({} if value == "none" else value)
        except ValueError:
            return TrialWindow()

    def holds_steps(self, trials: Iterable[int]) -> bool:
        """Whether the log holds the control steps of every one of ``trials``."""
        w = self.window
        n = int(self.get("trials") or self.summary.get("trials") or self.trials)
        return w is None or all(w.holds(k, n) for k in trials)

    def applied_torque(self) -> tuple[np.ndarray, float] | None:
        """The applied joint torque of the measured trials as trials x steps x joints (from
        /joint_states/actual), with the recorded step in ms; None when joint states were not recorded, also
        when the log's window (``recording.trials``) leaves out a measured trial."""
        if self.n_measured == 0 or not self.holds_steps(range(self.warmup, self.trials)):
            return None
        t0 = self.warmup * self.period_s
        rows = [[j["effort"] for j in msg["joints"]] for _, _, msg in
                self.messages(["/joint_states/actual"], t0 - 1e-6, self.trials * self.period_s - 1e-6)]
        if not rows or any(v is None for v in rows[0]):
            return None
        per_trial = len(rows) // self.n_measured
        if per_trial < 2:
            return None
        tau = np.asarray(rows[: per_trial * self.n_measured], float).reshape(self.n_measured, per_trial, -1)
        return tau, 1000.0 * self.period_s / per_trial

    def torque_variability_of_mean(self) -> float | None:
        """Torque variability of the trial-averaged applied torque (Eq. 3.13-3.15, N·m/ms) over this run's
        measured trials, or None; read from the log once per run (a figure and its checks both ask)."""
        if "tv_of_mean" not in self._cache:
            got = self.applied_torque()
            self._cache["tv_of_mean"] = None if got is None else torque_variability_of_mean(*got)
        return self._cache["tv_of_mean"]

    def control(self, keys: Iterable[str], t0: float | None = None, t1: float | None = None,
                every: int = 1) -> dict[str, np.ndarray]:
        """Columns of /control (e.g. ee, ee_des, r2c_ms, c2r_ms, trial) as arrays, every n-th step."""
        keys = list(keys)
        cols: dict[str, list] = {k: [] for k in ["t", *keys]}
        for i, (_, t, msg) in enumerate(self.messages(["/control"], t0, t1)):
            if i % every:
                continue
            if any(k not in msg for k in keys):
                continue
            cols["t"].append(t)
            for k in keys:
                cols[k].append(msg[k])
        return {k: np.asarray(v, dtype=float) for k, v in cols.items()}



class RunSet(list):
    """A list of runs with content filters (``where``), the best of several (``best``), the seeds of a study
    (``seeds``) and the run a state was learned in (``origin``); made like a list, from runs.
    """

    def where(self, pred: Callable[[Run], bool] | None = None, **eq: Any) -> RunSet:
        def ok(r: Run) -> bool:
            return all(getattr(r, k) == v for k, v in eq.items()) and (pred is None or pred(r))
        return RunSet(r for r in self if ok(r))

    def origin(self, run: Run, depth: int = 8) -> Run | None:
        """The run that learned ``run``'s state from scratch: ``run`` itself when it started from scratch, else
        the origin of the run it started from (a run of this set, else read from disk); None when that run
        cannot be found."""
        for _ in range(depth):
            if not run.learned_from:
                return run
            run = self._find(run.learned_from_dirs())
            if run is None:
                return None
        return None

    def _find(self, candidates: list[Path]) -> Run | None:
        """The first of ``candidates`` that is a run of this set or a readable run folder."""
        mine = {r.dir.absolute(): r for r in self}
        for c in candidates:
            if c.absolute() in mine:
                return mine[c.absolute()]
            if (c / runfiles.SUMMARY).exists():
                try:
                    return Run.load(c)
                except CerebxError:
                    return None
        return None

    def best(self) -> Run | None:
        """The run to show when several match: completed first, then the most trials, then the lowest seed
        (a study's first seed; its other seeds give the intervals), then the newest."""
        if not self:
            return None
        return max(self, key=lambda r: (r.completed, r.trials, -r.seed, _mtime(r.dir)))

    def seeds(self) -> dict[int, RunSet]:
        """The runs of each seed, sorted by seed."""
        groups: dict[int, RunSet] = {}
        for r in self:
            groups.setdefault(r.seed, RunSet()).append(r)
        return {k: groups[k] for k in sorted(groups)}

    def by(self, key: Callable[[Run], Any], pick: Callable[[RunSet], Run | None] | None = None) -> dict[Any, Run]:
        """One run for each value of ``key`` (runs where it is None are left out), sorted by value; ``pick``
        chooses among a value's runs (default: best)."""
        groups: dict[Any, RunSet] = {}
        for r in self:
            k = key(r)
            if k is not None:
                groups.setdefault(k, RunSet()).append(r)
        return {k: (pick or RunSet.best)(groups[k]) for k in sorted(groups)}


def _mtime(d: Path) -> float:
    try:
        return (d / runfiles.SUMMARY).stat().st_mtime
    except OSError:
        return 0.0


def find_run_dirs(root: Path) -> list[Path]:
    return sorted(p.parent for p in root.rglob(runfiles.SUMMARY))


def load_runs(dirs: Iterable[Path]) -> tuple[RunSet, list[str]]:
    """Every readable run of ``dirs``; each one that is not gives one line in the second list."""
    runs, problems = RunSet(), []
    for d in dirs:
        try:
            runs.append(Run.load(d))
        except CerebxError as err:
            problems.append(str(err))
    return runs, problems
