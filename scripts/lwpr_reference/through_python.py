"""Time the reference LWPR library through Python (``binding.c``, built by ``run.sh`` as ``lwpr_c``) and
cerebx's ``LWPR`` on the streams of ``cerebx bench --lwpr``, one sample at a time in the loop ``run_task`` times
cerebx's ``update`` in (``for x, y in zip(xs, ys): model.update(x, y)``): five fresh models of each, one of
each in turn (this host's speed drifts within seconds), best of five; one JSON line a task.

Usage: ``python through_python.py BUILD_DIR`` (the folder holding the built ``lwpr_c`` module).
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from cerebx.lwpr.bench import cross_task, sine_task
from cerebx.lwpr.model import LWPR


def main(build: str) -> None:
    sys.path.insert(0, build)
    import lwpr_c

    for t in (cross_task(1), sine_task(1)):
        p, xs, ys = t.params, t.x_train, t.y_train
        LWPR(xs.shape[1], ys.shape[1], **p).update(xs[0], ys[0])  # compiled (or loaded) before timing
        best, ours_best, model, ours = float("inf"), float("inf"), None, None
        for _ in range(5):
            model = lwpr_c.Model(xs.shape[1], p["init_D"], p["init_alpha"], p.get("w_gen", -1.0),
                                 p.get("penalty", -1.0))
            t0 = time.perf_counter()
            for x, y in zip(xs, ys):
                model.update(x, y)
            best = min(best, time.perf_counter() - t0)
            ours = LWPR(xs.shape[1], ys.shape[1], **p)
            t0 = time.perf_counter()
            for x, y in zip(xs, ys):
                ours.update(x, y)
            ours_best = min(ours_best, time.perf_counter() - t0)
        pred = np.array([model.predict(x) for x in t.x_test])
        nmse = float(np.mean((pred - t.y_test) ** 2) / np.var(t.y_test))
        print(json.dumps({"task": t.name, "receptive_fields": model.receptive_fields, "nmse": round(nmse, 4),
                          "update_per_s": round(len(xs) / best), "cerebx_update_per_s": round(len(xs) / ours_best),
                          "cerebx_receptive_fields": ours.n_receptive_fields[0]}))


if __name__ == "__main__":
    main(sys.argv[1])
