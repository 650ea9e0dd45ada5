"""``recording.trials``: which trials record the step-level channels (joint states, ``/control``, spikes, the 3-D
scene). Trial-level data (``/trial_metrics``, ``/events``, ``/weights``, ``summary.json``) are recorded for every
trial whatever the window.

A window is data: the first n trials, the last n, every n-th and explicit ``[start, stop)`` ranges, united;
``all`` (or null, the default) records every trial, ``none`` no trial. A study whose figures read the stage
trials of a 500-trial run records those and not the 500 (``studies.yaml``)."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BeforeValidator, Field, model_validator

from cerebx.schema.base import Strict

STEP_TOPICS = ("/joint_states/", "/control", "/spikes/", "/scene/")
"""Prefixes of the channels a window leaves out of the trials it does not hold (written at every control step)."""


class TrialWindow(Strict):
    """The trials whose control steps are recorded: the union of ``first``, ``last``, ``every`` and ``ranges``."""

    first: int = Field(0, ge=0, description="the first n trials (0 .. n-1)")
    last: int = Field(0, ge=0, description="the last n trials of the run (of `trials`)")
    every: int = Field(0, ge=0, description="every n-th trial (those whose index is a multiple of n); 0: none")
    ranges: tuple[tuple[int, int], ...] = Field(
        (), description="[start, stop) trial ranges, e.g. [[149, 160]] for trials 149-159")

    @model_validator(mode="after")
    def _ordered(self) -> TrialWindow:
        for start, stop in self.ranges:
            if not 0 <= start < stop:
                raise ValueError(f"ranges: [{start}, {stop}] is not a range of trials [start, stop) with "
                                 "0 <= start < stop")
        return self

    def holds(self, trial: int, n_trials: int) -> bool:
        """Whether trial ``trial`` (0-based) of a run of ``n_trials`` records its control steps."""
        if trial < self.first or self.last and trial >= n_trials - self.last:
            return True
        if self.every and trial % self.every == 0:
            return True
        return any(start <= trial < stop for start, stop in self.ranges)

    def trials(self, n_trials: int) -> list[int]:
        """The trials of a run of ``n_trials`` that record their control steps."""
        return [k for k in range(n_trials) if self.holds(k, n_trials)]

    def describe(self, n_trials: int) -> str:
        """The held trials as short ranges, e.g. ``0-9, 149-159, 489-499 (32 of 500)``."""
        held = self.trials(n_trials)
        spans: list[list[int]] = []
        for k in held:
            if spans and spans[-1][1] == k - 1:
                spans[-1][1] = k
            else:
                spans.append([k, k])
        text = ", ".join(f"{a}" if a == b else f"{a}-{b}" for a, b in spans) or "none"
        return f"{text} ({len(held)} of {n_trials})"


def _named(value: Any) -> Any:
    """``all`` is null (every trial), ``none`` the empty window."""
    if isinstance(value, str):
        if value in ("all", "none"):
            return None if value == "all" else {}
        raise ValueError(f"{value!r}: give all, none or a mapping {{first, last, every, ranges}}")
    return value


WindowValue = Annotated[TrialWindow | None, BeforeValidator(_named)]
"""The type of ``recording.trials``."""


def trial_window(value: TrialWindow | None) -> TrialWindow | None:
    """The window of a ``recording.trials`` value: None when every trial is recorded."""
    return value


def is_step_topic(topic: str) -> bool:
    """Whether ``topic`` is written at control steps (left out of trials outside the window)."""
    return topic.startswith(STEP_TOPICS)
