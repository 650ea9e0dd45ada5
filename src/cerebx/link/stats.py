"""Small summaries of measured series (delays, lateness, compute time) for summary.json."""

from __future__ import annotations

from typing import Any

import numpy as np

QUANTILES = (5, 50, 95, 99)


def describe(values: Any, digits: int = 4) -> dict[str, float | int | None]:
    """n, mean, std, min, the :data:`QUANTILES` and max of ``values`` (NaN ignored); None for an empty series."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    out: dict[str, float | int | None] = {"n": int(v.size)}
    if v.size == 0:
        out.update({k: None for k in ("mean", "std", "min", *(f"p{q}" for q in QUANTILES), "max")})
        return out
    out.update({"mean": round(float(v.mean()), digits), "std": round(float(v.std()), digits),
                "min": round(float(v.min()), digits)})
    for q, x in zip(QUANTILES, np.percentile(v, QUANTILES)):
        out[f"p{q}"] = round(float(x), digits)
    out["max"] = round(float(v.max()), digits)
    return out
