"""The brain side's watchdog: sheds work in steps as the brain side falls behind the wall clock, after
the original implementation's real-time restriction (docs/provenance.md#edlut-watchdog).

The original let the network run ahead of the wall clock by at most ``0.9 x`` the pathway delay and
measured how much of that lead was left. Here the lead of a tick is that maximum less how late the
brain side finished the tick (its finish time minus the tick's start on the robot's clock): a brain side
that keeps up has the whole lead, one that falls behind eats into it. With the lead below 0.30 of the
maximum plasticity is turned off, below 0.10 spikes are no longer propagated, below 0.05 every
non-essential event stops too (spike recording, weight summaries). A level is entered at once and left
only after the lead stayed above its threshold for ``recover_ms``.

A brain stage (or the controller behind it) takes part by offering ``shed(level)`` and
``pathway_delay_ms``; a brain side with none (a PD controller) has nothing to shed.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from cerebx.link.schema import SheddingConfig

LEVELS = ("all_on", "plasticity_off", "spikes_off", "all_off")


def brain_parts(brain: list[Any]) -> list[Any]:
    """The brain stages and, behind them, their controllers and parts."""
    out: list[Any] = []
    todo = list(brain)
    while todo:
        obj = todo.pop(0)
        out.append(obj)
        todo += list(getattr(obj, "parts", []))
        inner = getattr(obj, "controller", None)
        if inner is not None and inner is not obj:
            todo.append(inner)
    return out


def shed_targets(brain: list[Any]) -> list[Any]:
    """The parts of the brain side that can shed work (``shed`` and a pathway delay)."""
    return [p for p in brain_parts(brain)
            if callable(getattr(p, "shed", None)) and getattr(p, "pathway_delay_ms", None)]


def prepare_real_time(brain: list[Any]) -> None:
    """Before the first tick: every part that compiles on first use, or has work a paced loop cannot afford,
    prepares itself (``prepare_real_time()``)."""
    for p in brain_parts(brain):
        if callable(getattr(p, "prepare_real_time", None)):
            p.prepare_real_time()


@dataclass(frozen=True)
class LevelChange:
    t_s: float
    level: int
    name: str
    lead_ratio: float
    lag_ms: float


class Watchdog:
    """Chooses the shedding level from each tick's lag and applies it to the targets."""

    def __init__(self, cfg: SheddingConfig, targets: list[Any]):
        self.cfg = cfg
        self.targets = targets if cfg.enabled else []
        delays = [float(t.pathway_delay_ms) for t in self.targets]
        self.max_lead_ms = cfg.max_lead_fraction * min(delays) if delays else 0.0
        self.level = 0
        self.changes: list[LevelChange] = []
        self._below_since: float | None = None
        self.max_level = 0

    @property
    def active(self) -> bool:
        return bool(self.targets) and self.max_lead_ms > 0

    def ratio(self, lag_ms: float) -> float:
        return (self.max_lead_ms - max(lag_ms, 0.0)) / self.max_lead_ms

    def _wanted(self, ratio: float) -> int:
        c = self.cfg
        if ratio > c.plasticity_off_below:
            return 0
        if ratio > c.spikes_off_below:
            return 1
        if ratio > c.all_off_below:
            return 2
        return 3

    def update(self, lag_ms: float, t_s: float) -> LevelChange | None:
        """The level after a tick that finished ``lag_ms`` late (at simulated time ``t_s``); the change, if any."""
        if not self.active:
            return None
        ratio = self.ratio(lag_ms)
        wanted = self._wanted(ratio)
        if wanted > self.level:
            self._below_since = None
            return self._set(wanted, ratio, lag_ms, t_s)
        if wanted < self.level:
            if self._below_since is None:
                self._below_since = t_s
            if (t_s - self._below_since) * 1000.0 >= self.cfg.recover_ms:
                self._below_since = None
                return self._set(wanted, ratio, lag_ms, t_s)
        else:
            self._below_since = None
        return None

    def _set(self, level: int, ratio: float, lag_ms: float, t_s: float) -> LevelChange:
        self.level = level
        self.max_level = max(self.max_level, level)
        for t in self.targets:
            t.shed(level)
        change = LevelChange(t_s, level, LEVELS[level], ratio, lag_ms)
        self.changes.append(change)
        return change
