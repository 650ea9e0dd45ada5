"""What runs on the robot side after the C2R channel: the torque filter and the watchdog."""

from __future__ import annotations

from collections import deque

import numpy as np

from cerebx.controllers.base import TorqueMsg
from cerebx.schema import controller as schema


class HoldFilter:
    """Applies the newest arrived sample (zero until the first one arrives)."""

    def __init__(self, n: int):
        self.tau = np.zeros(n)

    def __call__(self, arrived: list[TorqueMsg], t_s: float) -> np.ndarray:
        if arrived:
            self.tau = arrived[-1].tau
        return self.tau


class MeanFilter:
    """Mean of the last ``taps`` arrived samples (Eq. 2.18), kept as a running sum (recomputed
    exactly every 1000 samples so rounding cannot drift)."""

    def __init__(self, n: int, taps: int):
        self.buf = np.zeros((taps, n))
        self.sum = np.zeros(n)
        self.count = 0
        self.taps = taps
        self.tau = np.zeros(n)

    def __call__(self, arrived: list[TorqueMsg], t_s: float) -> np.ndarray:
        for m in arrived:
            i = self.count % self.taps
            self.sum += m.tau - self.buf[i]
            self.buf[i] = m.tau
            self.count += 1
            if self.count % 1000 == 0:
                self.sum = self.buf.sum(0)
        if self.count:
            self.tau = self.sum / min(self.count, self.taps)
        return self.tau


class FuturePastFilter:
    """Eq. 3.6 with the original's safe stop (facts §7).

    Samples are stamped with their application time. Each tick, F = min(#future, n + 1); with
    F >= min_future + 1 the torque is the mean of the F nearest future samples and the
    min(F - 1, #past) newest past ones; otherwise the previous torque decays by ``decay``.
    """

    def __init__(self, n_joints: int, cfg: schema.FuturePastFilter, step_s: float = 0.002):
        self.n, self.cfg, self.step_s = n_joints, cfg, step_s
        self.future: list[TorqueMsg] = []
        self.past: deque[TorqueMsg] = deque(maxlen=cfg.past_samples)
        self.tau = np.zeros(n_joints)

    def __call__(self, arrived: list[TorqueMsg], t_s: float) -> np.ndarray:
        eps = 1e-9
        self.future.extend(arrived)
        self.future.sort(key=lambda m: m.stamp_s)
        while self.future and self.future[0].stamp_s < t_s - eps:
            self.past.append(self.future.pop(0))
        n = self.cfg.past_samples
        f = min(len(self.future), n + 1)
        if f >= self.cfg.min_future_samples + 1:
            chosen = [m.tau for m in self.future[:f]]
            k = min(f - 1, len(self.past))
            if k:
                chosen += [m.tau for m in list(self.past)[-k:]]
            self.tau = np.mean(chosen, axis=0)
        else:
            self.tau = self.tau * self.cfg.decay_per_step
        return self.tau


def make_filter(cfg: schema.NoFilter | schema.MeanFilter | schema.FuturePastFilter, n: int):
    if isinstance(cfg, schema.MeanFilter):
        return MeanFilter(n, cfg.taps)
    if isinstance(cfg, schema.FuturePastFilter):
        return FuturePastFilter(n, cfg)
    return HoldFilter(n)


class Supervisor:
    """Watchdog PD that acts only while a joint is outside [lo, hi] (facts §4)."""

    def __init__(self, cfg: schema.Supervisor, lo: np.ndarray, hi: np.ndarray):
        self.kp, self.kd = np.asarray(cfg.kp), np.asarray(cfg.kd)
        self.ramp = cfg.ramp_per_step
        self.lo, self.hi = lo - cfg.margin_rad, hi + cfg.margin_rad
        self.s = np.zeros_like(self.kp)

    def __call__(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        below, above = q < self.lo, q > self.hi
        outside = below | above
        self.s = np.where(outside, np.minimum(self.s + self.ramp, 1.0), 0.0)
        bound = np.where(below, self.lo, self.hi)
        return np.where(outside, self.kp * (bound - q) - self.s * self.kd * qd, 0.0)
