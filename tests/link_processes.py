"""Helpers of the link tests that run both sides as processes (test_link_run.py, test_link_attacks.py)."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from cerebx.link.transport import free_port

CLI = [sys.executable, "-m", "cerebx.cli"]
PD = ["+task=circle", "controller=pd", "clock=wall", "recording.progress=off", "link.link_lost_after_ms=1000",
      "link.hold_pose_after_ms=400", "link.pair_timeout_s=30"]
RUN_TIMEOUT = 120


def ports(kind: int = socket.SOCK_DGRAM) -> list[str]:
    return [f"link.{side}=127.0.0.1:{free_port('127.0.0.1', kind)}" for side in ("robot", "brain", "relay")]


def start(args: list[str], env: dict[str, str] | None = None, **kw) -> subprocess.Popen:
    return subprocess.Popen(CLI + args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env={**os.environ, **(env or {})}, start_new_session=True, **kw)


def finish(proc: subprocess.Popen, timeout: float = RUN_TIMEOUT) -> tuple[int, str, str]:
    try:
        out, err = proc.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
        pytest.fail(f"{proc.args[3:5]} did not stop within {timeout} s:\n{err[-2000:]}")
    return proc.returncode, out, err


def wait_for(cond, timeout: float, what: str):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        got = cond()
        if got:
            return got
        time.sleep(0.05)
    pytest.fail(f"timed out waiting for {what}")


def ticking(run_dir: Path, side: str = "robot") -> int | None:
    """The pid of a side once it has written its summary (it then pairs within a second or so)."""
    p = run_dir / ("robot" if side == "robot" else "") / "summary.json"
    try:
        s = json.loads(p.read_text())
    except (OSError, ValueError):
        return None
    return s.get("pid")
