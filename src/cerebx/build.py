"""Turns a validated experiment config into live components through the registries."""

from __future__ import annotations

import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cerebx import registry


def component_rng(seed: int, name: str) -> np.random.Generator:
    """An independent generator per component, derived from the one experiment seed."""
    return np.random.default_rng(np.random.SeedSequence([seed, zlib.crc32(name.encode())]))


def cache_dir() -> Path:
    """Where derived artefacts (IK joint paths) are cached; override with CEREBX_CACHE."""
    import os

    root = Path(os.environ.get("CEREBX_CACHE", Path.home() / ".cache" / "cerebx"))
    root.mkdir(parents=True, exist_ok=True)
    return root


@dataclass
class BuildContext:
    """What builders may use: the whole config, already-built components, the seed."""

    cfg: Any
    plant: Any = None
    task: Any = None
    run_dir: Path | None = None
    extras: dict[str, Any] = field(default_factory=dict)

    def rng(self, name: str) -> np.random.Generator:
        return component_rng(self.cfg.seed, name)

    @property
    def cache_dir(self) -> Path:
        return cache_dir()


def build_components(cfg: Any, run_dir: Path | None = None) -> BuildContext:
    """Build plant, then task (which may need the plant model for IK), then controller, delays."""
    ctx = BuildContext(cfg=cfg, run_dir=run_dir)
    ctx.plant = registry.plants.build(cfg.plant, ctx)
    ctx.task = registry.tasks.build(cfg.task, ctx)
    ctx.extras["controller"] = registry.controllers.build(cfg.controller, ctx)
    ctx.extras["delay"] = registry.delays.build(cfg.delay, ctx)
    return ctx
