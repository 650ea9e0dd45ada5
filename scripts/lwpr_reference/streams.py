"""Write the training streams and test sets of ``cerebx bench --lwpr`` (``cerebx.lwpr.bench``) for ``drive.c``,
and time cerebx's LWPR on the same streams (best of five, as ``drive.c`` does), printing one JSON line a task.

Usage: ``python streams.py OUT_DIR``. File layout (little-endian): int32 n, n_in, n_test, 0; float64 init_D,
init_alpha, w_gen, penalty (-1: the library's default); x (n x n_in), y (n), x_test (n_test x n_in), y_test.
"""

from __future__ import annotations

import json
import struct
import sys
import time
from pathlib import Path

import numpy as np

from cerebx.lwpr.bench import cross_task, sine_task
from cerebx.lwpr.model import LWPR


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    for t in (cross_task(1), sine_task(1)):
        p = t.params
        with open(out / f"{t.name}.bin", "wb") as f:
            f.write(struct.pack("<iiii", t.x_train.shape[0], t.x_train.shape[1], t.x_test.shape[0], 0))
            f.write(struct.pack("<dddd", p["init_D"], p["init_alpha"], p.get("w_gen", -1.0), p.get("penalty", -1.0)))
            for a in (t.x_train, t.y_train[:, 0], t.x_test, t.y_test[:, 0]):
                f.write(np.ascontiguousarray(a, np.float64).tobytes())
        warm = LWPR(t.x_train.shape[1], 1, **p)
        warm.update_many(t.x_train[:2], t.y_train[:2])
        warm.update(t.x_train[0], t.y_train[0])
        best_many = best_one = float("inf")
        for _ in range(5):
            m = LWPR(t.x_train.shape[1], 1, **p)
            t0 = time.perf_counter()
            m.update_many(t.x_train, t.y_train)
            best_many = min(best_many, time.perf_counter() - t0)
            one = LWPR(t.x_train.shape[1], 1, **p)
            t0 = time.perf_counter()
            for x, y in zip(t.x_train, t.y_train):
                one.update(x, y)
            best_one = min(best_one, time.perf_counter() - t0)
        pred = m.predict_many(t.x_test)
        n = len(t.x_train)
        print(json.dumps({"task": t.name, "receptive_fields": int(m.n_receptive_fields[0]),
                          "nmse": round(float(np.mean((pred - t.y_test) ** 2) / np.var(t.y_test)), 4),
                          "update_many_per_s": round(n / best_many), "update_per_s": round(n / best_one)}))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
