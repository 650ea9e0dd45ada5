"""Shared fixtures: configs are composed once through the real Hydra tree, then shortened."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
os.environ.setdefault("NUMBA_CACHE_DIR", str(ROOT / ".cache" / "numba"))
os.environ.setdefault("CEREBX_CACHE", str(ROOT / ".cache" / "cerebx"))
from cerebx.numba_cache import retire_stale  # noqa: E402  (kernels compiled from other sources are dropped first)

retire_stale(Path(os.environ["NUMBA_CACHE_DIR"]))

DEMO = ["+experiment=demo"]


@pytest.fixture
def load():
    """Compose and validate a config from overrides (as `cerebx validate` does)."""
    from cerebx.config import load as _load

    def _do(overrides):
        return _load(list(overrides))[0]

    return _do


@pytest.fixture
def in_tmp(tmp_path, monkeypatch):
    """Run with the working directory in a fresh temporary folder (runs/ lands there)."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


def pytest_collection_modifyitems(config, items):
    """A test marked neither integration nor slow is a unit test (``-m unit`` runs only those)."""
    for item in items:
        if not any(item.get_closest_marker(m) for m in ("integration", "slow")):
            item.add_marker(pytest.mark.unit)
