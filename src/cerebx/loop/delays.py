"""Delay models: per-message delay samplers for the two directions of the link (``delay_channel.py``).

Each delay kind has its own builder, registered with its schema in ``schema/builtin.py``; a plugin
adds a kind the same way.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from cerebx.builders import BuildContext
from cerebx.errors import CerebxError
from cerebx.schema import delay as schema

STEP_MS = 2.0


@dataclass
class Constant:
    ms: float

    def next_ms(self) -> float:
        return self.ms


class Gamma:
    """Gamma(shape, scale) + offset per message, with the original's monotonic limiter."""

    def __init__(self, p: schema.GammaParams, monotonic: bool, rng: np.random.Generator):
        self.p, self.monotonic, self.rng = p, monotonic, rng
        self.prev: float | None = None

    def next_ms(self) -> float:
        g = self.rng.gamma(self.p.shape, self.p.scale_ms)
        if self.p.inverted:
            g = 2 * self.p.shape * self.p.scale_ms - g
        d = max(g + self.p.offset_ms, 0.0)
        if self.monotonic and self.prev is not None and d < self.prev:
            d = max(self.prev - STEP_MS, 0.0)
        self.prev = d
        return d


class HalfRoundTrip:
    """The original symmetric delay (docs/provenance.md#original-delays): one limited round-trip sample
    per step, half on each path. The R2C message of a step is sent first and draws; the C2R one reuses the draw."""

    def __init__(self, round_trip: Gamma):
        self.round_trip = round_trip
        self.half = 0.0

    def draw(self) -> float:
        self.half = self.round_trip.next_ms() / 2.0
        return self.half


@dataclass
class _View:
    source: HalfRoundTrip
    draws: bool

    def next_ms(self) -> float:
        return self.source.draw() if self.draws else self.source.half


class Trace:
    """Replays a recorded delay series (ms per message), looping at the end if asked."""

    def __init__(self, values: np.ndarray, loop: bool):
        self.values, self.loop, self.i = values, loop, 0

    def next_ms(self) -> float:
        if self.i >= len(self.values):
            if not self.loop:
                return float(self.values[-1])
            self.i = 0
        v = float(self.values[self.i])
        self.i += 1
        return v


class Percentiles:
    """Inverse-CDF sampling of a distribution given by (percentile, ms) points."""

    def __init__(self, points: list[tuple[float, float]], rng: np.random.Generator):
        self.p = np.array([p for p, _ in points]) / 100.0
        self.v = np.array([v for _, v in points])
        self.rng = rng

    def next_ms(self) -> float:
        return float(np.interp(self.rng.random(), self.p, self.v))


@dataclass
class DelayModel:
    """One sampler per direction."""

    r2c: Any
    c2r: Any


def load_trace(path: str) -> np.ndarray:
    try:
        data = np.loadtxt(Path(path), delimiter=None if not str(path).endswith(".csv") else ",", ndmin=2)
    except (OSError, ValueError) as err:
        raise CerebxError(f"delay.path: cannot read delay trace {path!r} ({err})") from None
    if data.size == 0 or not np.all(np.isfinite(data)) or np.any(data < 0):
        raise CerebxError(f"delay.path: {path!r} must hold finite, non-negative delays in ms")
    return data


def no_delay(cfg: schema.NoDelay, ctx: BuildContext) -> DelayModel:
    return DelayModel(Constant(0.0), Constant(0.0))


def constant_delay(cfg: schema.ConstantDelay, ctx: BuildContext) -> DelayModel:
    r2c, c2r = cfg.per_direction()
    return DelayModel(Constant(r2c), Constant(c2r))


def gamma_delay(cfg: schema.GammaDelay, ctx: BuildContext) -> DelayModel:
    rng_r2c, rng_c2r = ctx.rng("delay.r2c"), ctx.rng("delay.c2r")
    if cfg.symmetric:
        shared = HalfRoundTrip(Gamma(cfg.r2c, cfg.monotonic, rng_r2c))
        return DelayModel(_View(shared, draws=True), _View(shared, draws=False))
    return DelayModel(Gamma(cfg.r2c, cfg.monotonic, rng_r2c), Gamma(cfg.c2r, cfg.monotonic, rng_c2r))


def trace_delay(cfg: schema.TraceDelay, ctx: BuildContext) -> DelayModel:
    data = load_trace(str(cfg.file()))
    r2c = data[:, 0]
    c2r = data[:, 1] if data.shape[1] > 1 else data[:, 0]
    return DelayModel(Trace(r2c, cfg.loop), Trace(c2r, cfg.loop))


def percentile_delay(cfg: schema.PercentileDelay, ctx: BuildContext) -> DelayModel:
    return DelayModel(Percentiles(cfg.r2c_percentiles, ctx.rng("delay.r2c")),
                      Percentiles(cfg.c2r_percentiles, ctx.rng("delay.c2r")))
