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
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path


def _snn() -> None:
    """The small network's closed loop, timed and then with its cost profile (both run the same chunk kernels),
    on the network thread (shed chunks and the tests that watch that thread run its kernels: left to the tests,
    a worker compiled them in the middle of the run) and on the chunk server; then a recorded run of two trials
    with a checkpoint after each (the checkpoint, weight-statistics and spike-message kernels: the resume tests
    start runs two at a time, which compiled them side by side); then :func:`_one_step`."""
    import tempfile

    from cerebx.config import load
    from cerebx.controllers.snn.controller import SNNControllerImpl
    from cerebx.loop.runner import run_experiment
    from cerebx.loop.timing import closed_loop_rt

    small = ["+task=circle", "+experiment=small_snn"]
    for served in (False, True):
        SNNControllerImpl.serve_chunks = served
        closed_loop_rt(small, seconds=0.05, warmup_s=0.05, parts=True)
    with tempfile.TemporaryDirectory() as tmp:
        cfg, plain = load([*small, "trials=2", "recording.checkpoint_every=1", "recording.progress=off"])
        run_experiment(cfg, Path(tmp) / "run", plain)
    _one_step()  # here, after the kernels it calls are compiled in this process (in a process of its own: 89 s)


def _one_step() -> None:
    """A network with a sparse plasticity rule stepped one step at a time (``Network.step``: its own kernel, a
    version per kind of learning state; the Golgi-layer and sparse-rule tests call it: left to them, both
    workers compiled it at once, 15-20 s each). The network is the Golgi-layer tests' own."""
    import numpy as np

    sys.path.insert(0, str(Path(__file__).parent / "cerebx" / "snn"))
    from test_golgi_layer import golgi_cfg

    from cerebx.snn.network import Network

    Network(golgi_cfg(), parallel=False, seed=1).step(np.zeros(0, np.int32))


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
JOBS = [(_snn, ()), (_task, ("circle_eight",)), (_capolei, ()), (_task, ("eight",)),
        (_lwpr, (1, 1)), (_lwpr, (2, 1)), (_lwpr, (2, 2)), (_task, ("inclined_circle",))]


def _timed(fn: Callable[..., None], *args: object) -> float:
    t0 = time.monotonic()
    fn(*args)
    return time.monotonic() - t0


def main(jobs: int) -> int:
    import conftest  # noqa: F401  (the tests' cache folders, stale kernels dropped: before any process loads one)

    t0 = time.monotonic()
    with ProcessPoolExecutor(jobs, mp_context=mp.get_context("spawn")) as pool:
        futures = [(fn, args, pool.submit(_timed, fn, *args)) for fn, args in JOBS]
        took = [(f.result(), fn.__name__, args) for fn, args, f in futures]  # a failure is the tests' too: say it now
    longest = ", ".join(f"{name}{''.join(f' {a}' for a in args)} {s:.0f} s" for s, name, args in sorted(took)[::-1][:3])
    print(f"warm: kernels and task paths ready in {time.monotonic() - t0:.0f} s ({jobs} processes; longest: {longest})")
    return 0


if __name__ == "__main__":
    sys.exit(main(int(sys.argv[1]) if len(sys.argv) > 1 else os.cpu_count() or 1))
