"""Speed of LWPR on the reference library's cross benchmark: updates and predictions per second."""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from cerebx.lwpr.model import LWPR


def cross(x: np.ndarray) -> np.ndarray:
    """The 2-D "cross" test function of the LWPR library (facts §3.2)."""
    return np.maximum.reduce([np.exp(-10 * x[..., 0] ** 2), np.exp(-50 * x[..., 1] ** 2),
                              1.25 * np.exp(-5 * (x[..., 0] ** 2 + x[..., 1] ** 2))])


def bench_lwpr(n_updates: int = 20000, seed: int = 1) -> dict[str, Any]:
    """cross.c protocol (init_D 50, init_alpha 250, w_gen 0.2, noise U(-0.05, 0.05)); the first
    update (JIT compile or cache load) is timed separately."""
    rng = np.random.default_rng(seed)
    xs = rng.uniform(-1, 1, (n_updates, 2))
    ys = cross(xs) + rng.uniform(-0.05, 0.05, n_updates)
    model = LWPR(2, 1, init_D=50.0, init_alpha=250.0, w_gen=0.2)
    t0 = time.perf_counter()
    model.update(xs[0], ys[:1])
    model.predict(xs[0])
    first_s = time.perf_counter() - t0
    t1 = time.perf_counter()
    for i in range(1, n_updates):
        model.update(xs[i], ys[i : i + 1])
    upd_s = time.perf_counter() - t1
    grid = np.linspace(-1, 1, 41)
    test = np.array([[a, b] for a in grid for b in grid])
    t2 = time.perf_counter()
    pred = np.array([model.predict(x)[0] for x in test])
    pred_s = time.perf_counter() - t2
    return {
        "updates": n_updates,
        "receptive_fields": model.n_receptive_fields[0],
        "nmse": round(float(np.mean((pred - cross(test)) ** 2) / np.var(cross(test))), 4),
        "first_call_s": round(first_s, 3),
        "updates_per_s": round((n_updates - 1) / upd_s),
        "predictions_per_s": round(len(test) / pred_s),
    }
