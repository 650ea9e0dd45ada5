"""Delay models for the robot-to-controller (R2C) and controller-to-robot (C2R) channels."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field, model_validator

from cerebx.schema.base import NonNegFloat, PositiveFloat, Strict


class NoDelay(Strict):
    """Messages arrive at the step they are sent."""

    kind: Literal["none"] = "none"


class ConstantDelay(Strict):
    """A fixed delay; ``total_ms`` split evenly unless r2c_ms/c2r_ms are given."""

    kind: Literal["constant"] = "constant"
    total_ms: NonNegFloat = 0.0
    r2c_ms: NonNegFloat | None = None
    c2r_ms: NonNegFloat | None = None

    @model_validator(mode="after")
    def _split(self) -> ConstantDelay:
        if (self.r2c_ms is None) != (self.c2r_ms is None):
            raise ValueError("give both r2c_ms and c2r_ms, or neither (then total_ms is split evenly)")
        if self.r2c_ms is not None and abs(self.r2c_ms + self.c2r_ms - self.total_ms) > 1e-9:
            raise ValueError(f"r2c_ms + c2r_ms ({self.r2c_ms + self.c2r_ms}) must equal total_ms ({self.total_ms})")
        return self

    def per_direction(self) -> tuple[float, float]:
        if self.r2c_ms is None:
            return self.total_ms / 2, self.total_ms / 2
        return self.r2c_ms, self.c2r_ms  # type: ignore[return-value]


class GammaParams(Strict):
    """d = Gamma(shape, scale) + offset (ms), floored at 0; ``inverted``: 2*k*theta - Gamma + offset."""

    shape: PositiveFloat
    scale_ms: PositiveFloat
    offset_ms: float = 0.0
    inverted: bool = False


class GammaDelay(Strict):
    """A new gamma-distributed delay each step per direction, with the monotonic limiter
    (docs/models.md#delay-gamma)."""

    kind: Literal["gamma"] = "gamma"
    r2c: GammaParams
    c2r: GammaParams
    monotonic: bool = Field(True, description="a delay may fall by at most one step per step")
    symmetric: bool = Field(
        False,
        description="the original's symmetric setup: one round-trip sample per step (r2c parameters), "
        "limited as a whole, half sent down each path; c2r must then equal r2c",
    )

    @model_validator(mode="after")
    def _symmetric_needs_one_distribution(self) -> GammaDelay:
        if self.symmetric and self.c2r != self.r2c:
            raise ValueError("symmetric: true draws one round-trip delay, so c2r must equal r2c")
        return self


SHIPPED_TRACES = Path(__file__).resolve().parents[1] / "data"
"""Where the delay traces that ship with cerebx are (``delays/example_trace.csv``)."""


class TraceDelay(Strict):
    """Replay a recorded series of per-step delays (ms) from a text/CSV file (one or two columns)."""

    kind: Literal["trace"] = "trace"
    path: str = Field(description="the trace file: absolute, or relative to the working directory, else to the "
                      "traces shipped with cerebx (delays/example_trace.csv)")
    loop: bool = True

    @model_validator(mode="after")
    def _file_exists(self) -> TraceDelay:
        self.file()
        return self

    def file(self) -> Path:
        """The trace file this path names (where the run reads it, from any working directory)."""
        given = Path(self.path)
        for candidate in (given, SHIPPED_TRACES / given):
            if candidate.is_file():
                return candidate
        raise ValueError(f"path: no such file {self.path!r} (looked in {Path.cwd()} and in cerebx's shipped "
                         f"traces, {SHIPPED_TRACES})")


class PercentileDelay(Strict):
    """Sample delays from a distribution given by (percentile, ms) points, linearly interpolated."""

    kind: Literal["percentiles"] = "percentiles"
    r2c_percentiles: list[tuple[float, NonNegFloat]]
    c2r_percentiles: list[tuple[float, NonNegFloat]]

    @model_validator(mode="after")
    def _monotone(self) -> PercentileDelay:
        for name in ("r2c_percentiles", "c2r_percentiles"):
            pts = getattr(self, name)
            ps = [p for p, _ in pts]
            vs = [v for _, v in pts]
            if len(pts) < 2 or ps[0] != 0 or ps[-1] != 100:
                raise ValueError(f"{name} must start at percentile 0 and end at 100")
            if any(b <= a for a, b in zip(ps, ps[1:])) or any(b < a for a, b in zip(vs, vs[1:])):
                raise ValueError(f"{name}: percentiles must increase and delays must not decrease")
        return self

