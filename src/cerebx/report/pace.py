"""How long a profile's remaining runs will take at the pace its finished runs went.

``cerebx.estimate`` gives a run's time on a quiet 2-core machine from fixed rates. A report runs ``--jobs``
runs at once, each with two threads, on whatever machine it has, and its evaluation runs (delays, full
recording) go slower than learning runs of the same network: the quiet-machine rates were 2-5 times too
optimistic for the full profile. Here each remaining run takes the median pace (simulated seconds per wall
second) of the finished runs of its kind in the same profile folder — the same controller, network, plant and
whether the link delays — and the runs share the machine ``jobs`` at a time. A kind with no finished run yet
falls back to the quiet estimate slowed by the median slow-down of the kinds that have one. A run resumed from a
checkpoint is counted for the trials it has left.

Other profiles' folders are not consulted: the full profile's paces were measured while the machine also ran
tests and other studies, and the quick profile measured from an empty folder took 18.6 min of runs against
~28 min at those paces and ~17 min from the quiet rates (2026-11-28).
"""

from __future__ import annotations

import json
import statistics
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cerebx import runfiles
from cerebx.estimate import estimate
from cerebx.recording.summary import network_name

Kind = tuple[str, str, str, bool]


def kind_of(controller: str, network: str | None, plant: str, delay: str) -> Kind:
    """What a run's pace depends on most: its controller, network, plant and whether its link delays."""
    return controller, network or "-", plant, delay != "none"


@dataclass(frozen=True)
class Pace:
    """Median pace per kind of finished run, and the median slow-down against the quiet estimate."""

    per_kind: dict[Kind, float]
    slowdown: float
    runs: int

    def wall_s(self, exp: Any, left: float = 1.0) -> float:
        """The wall time of one run of ``exp`` at this pace, alone on the machine's share it gets; ``left``: the
        fraction of its trials still to run."""
        quiet = estimate(exp)
        key = kind_of(exp.controller.kind, network_name(exp.controller), exp.plant.kind, exp.delay.kind)
        rate = self.per_kind.get(key)
        return left * (quiet.sim_s / rate if rate else quiet.wall_s * self.slowdown)


def measured_pace(summaries: Iterable[tuple[dict[str, Any], float]]) -> Pace:
    """The pace of finished runs, given as (summary, its quiet-machine estimate in wall seconds)."""
    rates: dict[Kind, list[float]] = {}
    slow: list[float] = []
    n = 0
    for s, quiet_wall in summaries:
        wall, sim = float(s.get("wall_seconds") or 0.0), float(s.get("sim_seconds") or 0.0)
        if s.get("status") != "completed" or wall <= 0 or sim <= 0:
            continue
        n += 1
        rates.setdefault(kind_of(s["controller"], s.get("network"), s["plant"], s["delay"]), []).append(sim / wall)
        if quiet_wall > 0:
            slow.append(wall / quiet_wall)
    return Pace({k: statistics.median(v) for k, v in rates.items()},
                statistics.median(slow) if slow else 1.0, n)


def profile_pace(folder: Path, quiet_wall: dict[Path, float]) -> Pace:
    """The pace of the finished runs under a profile's folder (``quiet_wall``: each run folder's quiet estimate,
    where known)."""
    found = []
    for summary in Path(folder).glob(f"*/*/{runfiles.SUMMARY}"):
        try:
            s = json.loads(summary.read_text())
        except (OSError, json.JSONDecodeError):
            continue
        found.append((s, quiet_wall.get(summary.parent, 0.0)))
    return measured_pace(found)


def left_fraction(run_dir: Path, trials: int) -> float:
    """The fraction of a run's ``trials`` still to run: 1, or less when ``run_dir`` holds a checkpoint it resumes."""
    head = Path(run_dir) / runfiles.CHECKPOINT_HEAD
    try:
        done = int(json.loads(head.read_text()).get("trials_done", 0))
    except (OSError, ValueError, json.JSONDecodeError, AttributeError):
        return 1.0
    return max(0.0, 1.0 - done / trials) if trials > 0 else 1.0


def remaining_wall_s(pace: Pace, exps: list[Any], jobs: int, left: list[float] | None = None) -> float:
    """Wall seconds for ``exps`` run ``jobs`` at a time at ``pace`` (their summed time shared out); ``left``: the
    fraction of each one's trials still to run (default: all)."""
    left = left if left is not None else [1.0] * len(exps)
    return sum(pace.wall_s(e, f) for e, f in zip(exps, left, strict=True)) / max(1, jobs)
