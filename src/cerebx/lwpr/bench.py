"""Speed and accuracy of LWPR on the reference library's own examples (Klanke & Vijayakumar, LWPR v1.2;
docs/provenance.md#lwpr-benchmark): the 2-D cross of ``example_c/cross.c`` and the 1-D function of
``matlab/test_lwpr_1D.m``, each with that example's parameters, noise and number of samples."""

from __future__ import annotations

import time
from typing import Any, NamedTuple

import numpy as np

from cerebx.lwpr.model import LWPR


class Task(NamedTuple):
    """A training stream, a noise-free test set and the model parameters of one reference example."""

    name: str
    params: dict[str, float]
    x_train: np.ndarray
    y_train: np.ndarray
    x_test: np.ndarray
    y_test: np.ndarray


def cross(x: np.ndarray) -> np.ndarray:
    """The 2-D "cross" test function of the LWPR library (docs/provenance.md#lwpr-benchmark)."""
    return np.maximum.reduce([np.exp(-10 * x[..., 0] ** 2), np.exp(-50 * x[..., 1] ** 2),
                              1.25 * np.exp(-5 * (x[..., 0] ** 2 + x[..., 1] ** 2))])


def sine(x: np.ndarray) -> np.ndarray:
    """The 1-D test function of ``test_lwpr_1D.m`` (without its offset 5)."""
    return 10 * np.sin(7.8 * np.log(1 + x)) / (1 + 0.1 * x**2)


def cross_task(seed: int = 1) -> Task:
    """``cross.c``: 20 x 1000 fresh samples in [-1, 1]^2 with U(-0.05, 0.05) noise, init_D 50, init_alpha
    250, w_gen 0.2; tested on the 41 x 41 grid of step 0.05."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(-1, 1, (20000, 2))
    y = cross(x) + rng.uniform(-0.05, 0.05, 20000)
    grid = np.linspace(-1, 1, 41)
    test = np.array([[a, b] for b in grid for a in grid])
    return Task("cross_2d", {"init_D": 50.0, "init_alpha": 250.0, "w_gen": 0.2}, x, y[:, None], test,
                cross(test)[:, None])


def sine_task(seed: int = 1) -> Task:
    """``test_lwpr_1D.m``: 500 points x ~ U(0, 10), y = 5 + sine(x) + 0.1 x N(0, 1), shown in 20 shuffled
    epochs; init_D 20, init_alpha 40, penalty 1e-4; tested noise-free on 500 points spanning [0, 10]."""
    rng = np.random.default_rng(seed)
    x = 10 * rng.random(500)
    y = 5 + sine(x) + 0.1 * rng.standard_normal(500) * x
    order = np.concatenate([rng.permutation(500) for _ in range(20)])
    test = np.linspace(0, 10, 500)
    return Task("sine_1d", {"init_D": 20.0, "init_alpha": 40.0, "penalty": 1e-4}, x[order, None], y[order, None],
                test[:, None], 5 + sine(test)[:, None])


def run_task(task: Task) -> dict[str, Any]:
    """Updates and predictions per second one sample at a time (``update``, ``predict``: what a controller
    calls; updates also per second of the process's CPU time, steadier on a shared host) and for the whole
    stream at once (``update_many``, ``predict_many``); the first calls (JIT compile or cache load) are timed
    separately, on a model that is then dropped."""
    xs, ys, xt = task.x_train, task.y_train, task.x_test
    t0 = time.perf_counter()
    warm = LWPR(xs.shape[1], ys.shape[1], **task.params)
    warm.update(xs[0], ys[0])
    warm.predict(xt[0])
    warm.update_many(xs[:2], ys[:2])
    warm.predict_many(xt[:2])
    first_s = time.perf_counter() - t0

    model = LWPR(xs.shape[1], ys.shape[1], **task.params)
    t1, c1 = time.perf_counter(), time.process_time()
    for x, y in zip(xs, ys):
        model.update(x, y)
    upd_s, upd_cpu_s = time.perf_counter() - t1, time.process_time() - c1
    t2 = time.perf_counter()
    pred = np.array([model.predict(x) for x in xt])
    pred_s = time.perf_counter() - t2

    batch = LWPR(xs.shape[1], ys.shape[1], **task.params)
    t3 = time.perf_counter()
    batch.update_many(xs, ys)
    upd_many_s = time.perf_counter() - t3
    t4 = time.perf_counter()
    pred_many = batch.predict_many(xt)
    pred_many_s = time.perf_counter() - t4
    if not np.array_equal(pred, pred_many) or batch.n_receptive_fields != model.n_receptive_fields:
        raise RuntimeError(f"LWPR bench {task.name}: update_many and update learned different models")
    return {
        "updates": len(xs),
        "receptive_fields": model.n_receptive_fields[0],
        "nmse": round(float(np.mean((pred - task.y_test) ** 2) / np.var(task.y_test)), 4),
        "first_call_s": round(first_s, 3),
        "updates_per_s": round(len(xs) / upd_s),
        "updates_per_cpu_s": round(len(xs) / max(upd_cpu_s, 1e-9)),
        "predictions_per_s": round(len(xt) / pred_s),
        "update_many_per_s": round(len(xs) / upd_many_s),
        "predict_many_per_s": round(len(xt) / pred_many_s),
    }


def bench_lwpr(seed: int = 1) -> dict[str, dict[str, Any]]:
    """Both reference examples with one seed."""
    return {task.name: run_task(task) for task in (cross_task(seed), sine_task(seed))}
