"""Helpers of the tests that run ``cerebx run`` as a process and kill it (test_resume.py, test_window.py)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cerebx.loop import resume


def cerebx_run(*args: str, cwd: Path) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src")}
    return subprocess.Popen([sys.executable, "-m", "cerebx", "run", *args], cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)


def wait_for_checkpoint(run_dir: Path, trials: int, proc: subprocess.Popen, timeout_s: float = 120) -> None:
    """Return once ``proc``'s run has written a checkpoint at ``trials`` trials or more."""
    head = run_dir / (resume.CHECKPOINT + ".json")
    t0 = time.monotonic()
    while time.monotonic() - t0 < timeout_s:
        if proc.poll() is not None:
            pytest.fail(f"run ended before its checkpoint: {proc.stdout.read()}")
        try:
            if json.loads(head.read_text())["trials_done"] >= trials:
                return
        except (OSError, ValueError):
            pass
        time.sleep(0.05)
    pytest.fail(f"no checkpoint at trial {trials} within {timeout_s} s")
