"""Receivers: what the robot applies each tick from the command samples the link delivered.

``hold`` applies the newest sample, ``mean`` the mean of the last n samples (Eq. 2.18), and
``future_past`` the mean of the nearest future and past stamped samples with a decaying safe stop
(Eq. 3.6). Each works on every signal the brain side sends (docs/models.md#receivers).
"""

from __future__ import annotations

from collections import deque
from typing import Any

import numba
import numpy as np

from cerebx.builders import BuildContext
from cerebx.schema import stages as schema
from cerebx.signals import Message, Signal
from cerebx.stages.base import Receiver


class Hold(Receiver):
    """Applies the newest arrived sample (zero until the first one arrives)."""

    name = "hold"

    def __init__(self, signals: tuple[Signal, ...]):
        super().__init__(signals)
        self.values = {s.name: np.zeros(s.size) for s in signals}

    def receive(self, arrived: list[Message], t_s: float) -> dict[str, np.ndarray]:
        if arrived:
            self.values = dict(arrived[-1].values)
        return self.values


@numba.njit(cache=True, boundscheck=False)
def _push_mean(buf, total, i, x, n, out):  # pragma: no cover - numba
    """``total += x - buf[i]; buf[i] = x``, element by element (the array form's doubles), and the mean
    ``total / n`` into ``out`` (the same doubles as numpy's division). (Returning a new array instead cost a
    call ~0.3 us more: numba boxes it through Python.)"""
    for j in range(total.size):
        total[j] += x[j] - buf[i, j]
        buf[i, j] = x[j]
        out[j] = total[j] / n


class _RunningMean:
    """Mean of the last ``taps`` samples of one signal, kept as a running sum (recomputed exactly
    every 1000 samples so rounding cannot drift)."""

    def __init__(self, n: int, taps: int):
        self.buf = np.zeros((taps, n))
        self.sum = np.zeros(n)
        self.count = 0
        self.taps = taps
        self.value = np.zeros(n)

    def push(self, x: np.ndarray) -> np.ndarray:
        """Add a sample; returns the new mean (also :attr:`value`), in one compiled call but every 1000th sample."""
        if x.shape != self.sum.shape:
            raise ValueError(f"mean filter: a sample of shape {x.shape}, the filter's is {self.sum.shape}")
        i = self.count % self.taps
        self.count += 1
        out = np.empty(self.sum.size)  # a new array each sample: a frame of the tick before may hold the last one
        _push_mean(self.buf, self.sum, i, x, min(self.count, self.taps), out)
        self.value = out
        if self.count % 1000 == 0:
            self.sum = self.buf.sum(0)
            self.value = self.sum / min(self.count, self.taps)
        return self.value

    def mean(self) -> np.ndarray:
        """The mean of the last ``taps`` samples (zeros before the first)."""
        return self.value


class MeanFilter(Receiver):
    """Mean of the last ``taps`` arrived samples (Eq. 2.18)."""

    name = "mean"

    def __init__(self, signals: tuple[Signal, ...], taps: int):
        super().__init__(signals)
        self.means = {s.name: _RunningMean(s.size, taps) for s in signals}

    def receive(self, arrived: list[Message], t_s: float) -> dict[str, np.ndarray]:
        for m in arrived:
            for name, rm in self.means.items():
                rm.push(m.values[name])
        return {name: rm.mean() for name, rm in self.means.items()}


class FuturePastFilter(Receiver):
    """Eq. 3.6 with the original's safe stop (docs/models.md#receiver-future-past).

    Samples are stamped with their application time. Each tick, F = min(#future, n + 1); with
    F >= min_future + 1 the output is the mean of the F nearest future samples and the
    min(F - 1, #past) newest past ones; otherwise the previous output decays by ``decay``.
    """

    name = "future_past"
    safe_stop = True

    def __init__(self, signals: tuple[Signal, ...], cfg: schema.FuturePastFilterConfig):
        super().__init__(signals)
        self.cfg = cfg
        self.future: list[Message] = []
        self.past: deque[Message] = deque(maxlen=cfg.past_samples)
        self.values = {s.name: np.zeros(s.size) for s in signals}

    def receive(self, arrived: list[Message], t_s: float) -> dict[str, np.ndarray]:
        eps = 1e-9
        self.future.extend(arrived)
        self.future.sort(key=lambda m: m.stamp_s)
        while self.future and self.future[0].stamp_s < t_s - eps:
            self.past.append(self.future.pop(0))
        n = self.cfg.past_samples
        f = min(len(self.future), n + 1)
        self.starved = f < self.cfg.min_future_samples + 1
        if not self.starved:
            chosen = self.future[:f]
            k = min(f - 1, len(self.past))
            if k:
                chosen = chosen + list(self.past)[-k:]
            self.values = {name: np.mean([m.values[name] for m in chosen], axis=0) for name in self.values}
        else:
            decay = self.cfg.decay_per_step
            self.values = {name: v * decay for name, v in self.values.items()}
        return self.values


def build_hold(cfg: Any, ctx: BuildContext, signals: tuple[Signal, ...]) -> Hold:
    return Hold(signals)


def build_mean(cfg: schema.MeanFilterConfig, ctx: BuildContext, signals: tuple[Signal, ...]) -> MeanFilter:
    return MeanFilter(signals, cfg.taps)


def build_future_past(cfg: schema.FuturePastFilterConfig, ctx: BuildContext,
                      signals: tuple[Signal, ...]) -> FuturePastFilter:
    return FuturePastFilter(signals, cfg)
