"""Per-job settings of a run's process: numba's cache folder and thread count.

A job started by a launcher (joblib, submitit on SLURM) does not inherit the Makefile's environment, so
``cerebx run`` sets them itself before numba is first imported. An environment variable that is already
set wins; otherwise:

- ``NUMBA_CACHE_DIR`` = ``$CEREBX_CACHE/numba``; without ``CEREBX_CACHE``, ``.cache/numba`` of the source
  checkout cerebx runs from (where ``make`` puts it), else ``~/.cache/cerebx/numba``: one writable cache
  shared by the jobs of a sweep on one machine (or one shared home on a cluster), never ``src/…/__pycache__``;
- ``NUMBA_NUM_THREADS`` = the CPUs given to this job: ``SLURM_CPUS_PER_TASK`` inside a SLURM job, else
  the CPUs this process may run on.

A value set by cerebx itself in another process (``CEREBX_JOBENV_CHOSEN`` names them: a sweep's submitting
process on a 2-CPU login node, whose environment SLURM hands to each job) does not count as set: the job
chooses again for its own allocation.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

from cerebx import vectors

CHOSEN_BY_CEREBX = "CEREBX_JOBENV_CHOSEN"
"""Names of the variables :func:`configure` set itself (not the user), comma-separated."""


def job_cpus(environ: dict[str, str] | None = None) -> int:
    """CPUs this job may use: SLURM's allocation when inside a SLURM job, else the process's CPU set."""
    env = os.environ if environ is None else environ
    try:
        available = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        available = os.cpu_count() or 1
    slurm = env.get("SLURM_CPUS_PER_TASK", "")
    if slurm.isdigit() and int(slurm) > 0:
        return max(1, min(int(slurm), available))
    return max(1, available)


def source_checkout() -> Path | None:
    """The source checkout cerebx runs from (the folder of its ``pyproject.toml``), or None when installed."""
    checkout = Path(__file__).resolve().parents[2]
    return checkout if (checkout / "pyproject.toml").is_file() else None


def numba_cache_dir(environ: dict[str, str] | None = None) -> Path:
    """numba's cache folder: ``numba`` under ``CEREBX_CACHE``, the checkout's ``.cache`` or ``~/.cache/cerebx``;
    ``numba-256`` for kernels compiled with ``CEREBX_VECTOR_BITS=256`` (whether a run's kernels are compiled
    already is read from the folder's index files, which do not say for which width)."""
    env = os.environ if environ is None else environ
    name = "numba" if vectors.asked(env) else "numba-256"
    if env.get("CEREBX_CACHE"):
        return Path(env["CEREBX_CACHE"]) / name
    checkout = source_checkout()
    if checkout is not None:
        return checkout / ".cache" / name
    return Path.home() / ".cache" / "cerebx" / name


def configure(environ: dict[str, str] | None = None) -> dict[str, str]:
    """Set (if unset) the numba variables of this job in ``environ`` (default: the process's); return
    what was set. Does nothing to numba itself once it is imported (its config is read at import)."""
    env = os.environ if environ is None else environ
    chosen = {"NUMBA_CACHE_DIR": str(numba_cache_dir(env)), "NUMBA_NUM_THREADS": str(job_cpus(env))}
    # values an earlier cerebx process chose for itself (a sweep's submitting process, whose environment a
    # SLURM job inherits) are chosen again here; only what the user set wins
    ours = set(filter(None, env.get(CHOSEN_BY_CEREBX, "").split(",")))
    set_now = {k: v for k, v in chosen.items() if not env.get(k) or (k in ours and env[k] != v)}
    env.update(set_now)
    env[CHOSEN_BY_CEREBX] = ",".join(sorted(ours | set_now.keys()))
    if environ is None and "numba" in sys.modules and set_now:
        return {}  # too late for this process; nothing changed in effect
    return set_now


def configure_job() -> None:
    """:func:`configure` at the start of a launcher's job, which may not have imported :mod:`cerebx.app` (Hydra
    hands launchers the undecorated task function, which cloudpickle then sends by value); if numba is loaded
    already, its thread count is set at run time instead (numba reads ``NUMBA_NUM_THREADS`` only at import)."""
    configure()
    numba = sys.modules.get("numba")
    if numba is not None:
        wanted = int(os.environ["NUMBA_NUM_THREADS"])
        pool = numba.config.NUMBA_NUM_THREADS  # sized at import
        # numba reads its environment again when it compiles a kernel, and once its threads are started it
        # refuses a NUMBA_NUM_THREADS other than the pool's: the variable says the pool's size
        os.environ["NUMBA_NUM_THREADS"] = str(pool)
        numba.set_num_threads(max(1, min(wanted, pool)))


def describe(environ: dict[str, str] | None = None) -> str:
    """One line for the job's log: where it runs and with which numba settings (in this process, once numba is
    loaded, the threads it runs with, whatever the size of its pool)."""
    env = dict(os.environ if environ is None else environ)
    numba = sys.modules.get("numba")
    if environ is None and numba is not None:
        env["NUMBA_NUM_THREADS"] = str(numba.get_num_threads())
    keys = ("SLURM_JOB_ID", "SLURM_ARRAY_TASK_ID", "SLURM_RESTART_COUNT", "SLURM_CPUS_PER_TASK",
            "NUMBA_NUM_THREADS", "NUMBA_CACHE_DIR")
    return " ".join(f"{k}={env[k]}" for k in keys if env.get(k))
