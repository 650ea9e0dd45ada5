"""SLURM: per-job numba settings, and a 4-job sweep through a real local SLURM (slow; needs root on a
Debian-like machine: scripts/slurm_local.sh installs and starts slurmctld, slurmd and munge)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cerebx import jobenv

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[3]
SCRIPT = ROOT / "scripts" / "slurm_local.sh"


def test_job_cpus_follow_slurm_allocation():
    available = len(os.sched_getaffinity(0))
    assert jobenv.job_cpus({"SLURM_CPUS_PER_TASK": "1"}) == 1
    assert jobenv.job_cpus({"SLURM_CPUS_PER_TASK": str(available + 8)}) == available  # never more than present
    assert jobenv.job_cpus({}) == available


def test_configure_sets_only_what_is_unset(tmp_path):
    env = {"CEREBX_CACHE": str(tmp_path), "SLURM_CPUS_PER_TASK": "1"}
    assert jobenv.configure(env) == {"NUMBA_CACHE_DIR": str(tmp_path / "numba"), "NUMBA_NUM_THREADS": "1"}
    env = {"NUMBA_CACHE_DIR": "/elsewhere", "SLURM_CPUS_PER_TASK": "1"}
    assert jobenv.configure(env) == {"NUMBA_NUM_THREADS": "1"} and env["NUMBA_CACHE_DIR"] == "/elsewhere"
    assert "SLURM_JOB_ID=7 " in jobenv.describe({**env, "SLURM_JOB_ID": "7"})


def test_a_job_chooses_again_what_the_submitting_process_chose():
    # the sweep's own process (2 CPUs here, say) sets the thread count; its SLURM job inherits that
    # environment, and must use its own allocation instead, unless the user had set the value
    submitter = {"CEREBX_CACHE": "/c"}
    jobenv.configure(submitter)
    job = {**submitter, "SLURM_CPUS_PER_TASK": "1", "NUMBA_NUM_THREADS": "2"}
    assert jobenv.configure(job) == {"NUMBA_NUM_THREADS": "1"} and job["NUMBA_NUM_THREADS"] == "1"
    user = {"CEREBX_CACHE": "/c", "SLURM_CPUS_PER_TASK": "1", "NUMBA_NUM_THREADS": "2"}
    assert "NUMBA_NUM_THREADS" not in jobenv.configure(user) and user["NUMBA_NUM_THREADS"] == "2"


def _slurm_up() -> str | None:
    """Bring the local SLURM up; the reason it cannot be, else None."""
    try:
        import hydra_plugins.hydra_submitit_launcher  # noqa: F401
    except ImportError:
        return "hydra-submitit-launcher is not installed (pip install 'cerebx[slurm]')"
    if shutil.which("sinfo") and subprocess.run([str(SCRIPT), "status"], capture_output=True).returncode == 0:
        return None
    if not shutil.which("apt-get") and not shutil.which("slurmctld"):
        return "no SLURM and no apt-get to install it (scripts/slurm_local.sh needs Debian/Ubuntu)"
    if os.geteuid() != 0 and not shutil.which("slurmctld"):
        return "SLURM is not installed and installing it needs root"
    up = subprocess.run([str(SCRIPT), "up"], capture_output=True, text=True, timeout=600)
    if up.returncode != 0:
        return f"scripts/slurm_local.sh up failed: {(up.stderr or up.stdout).strip().splitlines()[-1:]}"
    return None


@pytest.mark.slow
def test_four_job_sweep_runs_through_local_slurm(tmp_path):
    why = _slurm_up()
    if why:
        pytest.skip(why)
    sweep = tmp_path / "sweep"
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}  # the job sets them itself
    env.update(PYTHONPATH=str(ROOT / "src"), CEREBX_CACHE=str(ROOT / ".cache" / "cerebx"))
    t0 = time.monotonic()
    proc = subprocess.run(
        [sys.executable, "-m", "cerebx", "run", "-m", "+experiment=demo", "trials=2", "seed=1,2,3,4",
         "hydra/launcher=slurm", "hydra.launcher.timeout_min=10", f"hydra.sweep.dir={sweep}",
         "recording.progress=off"],
        cwd=tmp_path, env=env, capture_output=True, text=True, timeout=900)
    wall = time.monotonic() - t0
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    summaries = [json.loads((sweep / str(i) / "summary.json").read_text()) for i in range(4)]
    assert [s["status"] for s in summaries] == ["completed"] * 4
    assert [s["seed"] for s in summaries] == [1, 2, 3, 4]
    assert all(s["trials_completed"] == 2 and s["final_mae"] > 0 for s in summaries)
    job_ids = set()
    for i in range(4):
        line = next(ln for ln in (sweep / str(i) / "cerebx.log").read_text().splitlines() if "job: " in ln)
        fields = dict(f.split("=", 1) for f in line.split("job: ", 1)[1].split())
        job_ids.add(fields["SLURM_JOB_ID"])
        assert fields["NUMBA_NUM_THREADS"] == "1"  # from the preset's cpus_per_task, set by cerebx in the job
        assert fields["NUMBA_CACHE_DIR"] == str(ROOT / ".cache" / "cerebx" / "numba")
    assert len(job_ids) == 4  # four SLURM jobs
    table = (sweep / "sweep_summary.md").read_text().splitlines()
    assert table[0] == "| job | seed | status | trials | final_mae_rad | rt_factor |" and len(table) == 6
    assert "| job | seed |" in proc.stdout
    print(f"4-job SLURM sweep: {wall:.1f} s wall")
