"""A plugin of examples/ installed as pip would (a dist-info with its cerebx.plugins entry point on the
path), for tests that run cerebx in a subprocess with it."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def plugin_env(site: Path, package: str, version: str = "0.1.0") -> dict[str, str]:
    """The environment of a process that sees ``examples/<package>`` as an installed plugin named
    ``package`` (its ``register()`` as the entry point); ``site`` is an empty folder to hold its metadata."""
    dist = package.replace("_", "-")
    info = site / f"{package}-{version}.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: {version}\n")
    (info / "entry_points.txt").write_text(f"[cerebx.plugins]\n{package} = {package}:register\n")
    # this tree's cerebx after the plugin: in a git worktree the installed (editable) cerebx is another tree's
    path = [str(site), str(ROOT / "examples" / package), str(ROOT / "src")]
    return {**os.environ, "PYTHONPATH": os.pathsep.join(path)}


def run_python(env: dict[str, str], cwd: Path, *args: str) -> subprocess.CompletedProcess:
    """``python ARGS`` in ``cwd`` with ``env`` (e.g. ``"-m", "cerebx", "run", ...``), output captured."""
    return subprocess.run([sys.executable, *args], env=env, cwd=cwd, capture_output=True, text=True, timeout=600)
