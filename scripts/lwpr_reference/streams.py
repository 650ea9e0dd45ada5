"""Write the training streams and test sets of ``cerebx bench --lwpr`` (``cerebx.lwpr.bench``) for ``drive.c``,
and time cerebx's LWPR on the same streams (``run_task`` of ``cerebx bench --lwpr``, best of five, as
``drive.c`` does), printing one JSON line a task.

Usage: ``python streams.py OUT_DIR``. File layout (little-endian): int32 n, n_in, n_test, 0; float64 init_D,
init_alpha, w_gen, penalty (-1: the library's default); x (n x n_in), y (n), x_test (n_test x n_in), y_test.
"""

from __future__ import annotations

import json
import struct
import sys
from pathlib import Path

import numpy as np

from cerebx.lwpr.bench import cross_task, run_task, sine_task


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    for t in (cross_task(1), sine_task(1)):
        p = t.params
        with open(out / f"{t.name}.bin", "wb") as f:
            f.write(struct.pack("<iiii", t.x_train.shape[0], t.x_train.shape[1], t.x_test.shape[0], 0))
            f.write(struct.pack("<dddd", p["init_D"], p["init_alpha"], p.get("w_gen", -1.0), p.get("penalty", -1.0)))
            for a in (t.x_train, t.y_train[:, 0], t.x_test, t.y_test[:, 0]):
                f.write(np.ascontiguousarray(a, np.float64).tobytes())
        runs = [run_task(t) for _ in range(5)]
        print(json.dumps({"task": t.name, "receptive_fields": int(runs[0]["receptive_fields"]), "nmse": runs[0]["nmse"],
                          "update_many_per_s": max(r["update_many_per_s"] for r in runs),
                          "update_per_s": max(r["updates_per_s"] for r in runs),
                          "update_per_cpu_s": max(r["updates_per_cpu_s"] for r in runs)}))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
