"""Compile the kernels and solve the task paths `make test` needs, once, on every core, before pytest starts.

On a fresh clone numba's cache and the IK cache are empty. Left to the tests, pytest's workers and the runs they
start as subprocesses compile the same kernels side by side (the spiking network's chunk kernel, ~50 s, was
compiled by a worker and by a killed-and-resumed run at the same time); here each family is compiled once, the
families spread over the cores. With warm caches this takes a few seconds (loads only).

Usage: ``python tests/warm.py [JOBS]`` (default: every core); NUMBA_CACHE_DIR and CEREBX_CACHE as the tests use.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path


def _snn() -> None:
    """The small network's closed loop, timed and then with its cost profile (both run the same chunk kernels),
    on the chunk server and then on the network thread (shed chunks and the tests that watch that thread run
    its kernels: left to the tests, a worker compiled them in the middle of the run).
    (The sparse-rule kernels are left to the tests: compiled here they cost the same ~8 s of each core.)"""
    from cerebx.controllers.snn.controller import SNNControllerImpl
    from cerebx.loop.timing import closed_loop_rt

    for served in (True, False):
        SNNControllerImpl.serve_chunks = served
        closed_loop_rt(["+task=circle", "+experiment=small_snn"], seconds=0.05, warmup_s=0.05, parts=True)


def _one_step() -> None:
    """A network stepped one step at a time (``Network.step``, its own kernel: the tests of neurons, connectors and
    rules call it; left to them, both workers compiled it at once, ~19 s each)."""
    import numpy as np

    from cerebx.config import load
    from cerebx.snn.network import Network

    cfg = load(["+task=circle", "+experiment=small_snn"])[0]
    Network(cfg.controller.network, parallel=False).step(np.zeros(0, np.int32))


def _lwpr(n_in: int, n_out: int) -> None:
    """LWPR's entry points for one model shape (numba compiles one version per shape)."""
    import numpy as np

    from cerebx.lwpr import LWPR

    m = LWPR(n_in, n_out)
    m.update_many(np.zeros((2, n_in)), np.zeros((2, n_out)))
    m.predict_many(np.zeros((2, n_in)))


def _capolei() -> None:
    """The Capolei circuit's LWPR shape, as its stage contract test builds it."""
    from cerebx.build import build_components
    from cerebx.config import load

    build_components(load(["+experiment=capolei2020_arch3", "trials=1"])[0])


def _task(kind: str) -> None:
    """A Cartesian task's joint paths (IK, cached under CEREBX_CACHE)."""
    from types import SimpleNamespace

    from cerebx import registry
    from cerebx.registry import load_plugins
    from cerebx.schema import task as T

    load_plugins()
    cfg = {"circle_eight": T.CircleEightTask(), "inclined_circle": T.InclinedCircleTask(), "eight": T.EightTask()}[kind]
    registry.tasks.build(cfg, SimpleNamespace(cache_dir=Path(os.environ["CEREBX_CACHE"]), plant=None))


# longest first, so the pool ends about together
JOBS = [(_snn, ()), (_one_step, ()), (_task, ("circle_eight",)), (_capolei, ()), (_task, ("eight",)),
        (_lwpr, (1, 1)), (_lwpr, (2, 1)), (_lwpr, (2, 2)), (_task, ("inclined_circle",))]


def main(jobs: int) -> int:
    import conftest  # noqa: F401  (the tests' cache folders, stale kernels dropped: before any process loads one)

    t0 = time.monotonic()
    with ProcessPoolExecutor(jobs, mp_context=mp.get_context("spawn")) as pool:
        for f in [pool.submit(fn, *args) for fn, args in JOBS]:
            f.result()  # a failure here is the tests' failure too: say it now
    print(f"warm: kernels and task paths ready in {time.monotonic() - t0:.0f} s ({jobs} processes)")
    return 0


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else os.cpu_count() or 1))
