"""Cartesian Baxter tasks (SPEC §2): end-effector paths turned into joint paths by inverse kinematics.

The end-effector is the Baxter model's ``end_effector`` site (origin of the URDF ``left_hand`` frame,
base frame). The path is centred on the end-effector position of the home pose; the orientation is
held at the home orientation. IK runs once per task definition and is cached on disk under
``ctx.cache_dir`` keyed by a hash of the task config and the arm's kinematic MJCF.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from cerebx.plants.baxter import JOINT_RANGE, kinematic_mjcf
from cerebx.tasks.base import Task, TrialReference
from cerebx.tasks.ik import SiteIK

CONTROL_DT_S = 0.002
IK_VERSION = "dls-1"


def _circle(t: np.ndarray, period: float, r: float, phase: float = np.pi) -> np.ndarray:
    a = 2 * np.pi * t / period + phase
    return np.stack([r * np.cos(a), r * np.sin(a), np.zeros_like(t)], 1)


def _eight(t: np.ndarray, period: float, r: float, direction: float = 1.0) -> np.ndarray:
    a = direction * 2 * np.pi * t / period
    return np.stack([0.5 * r * np.sin(2 * a), r * np.cos(a), np.zeros_like(t)], 1)


def min_jerk(s: np.ndarray) -> np.ndarray:
    """Minimum-jerk position profile 0 -> 1 on s in [0, 1] (bell-shaped velocity)."""
    s = np.clip(s, 0.0, 1.0)
    return s**3 * (10 - 15 * s + 6 * s**2)


def _steps(cfg: Any) -> np.ndarray:
    return np.arange(int(round(cfg.period_s / CONTROL_DT_S))) * CONTROL_DT_S


def circle_offsets(cfg: Any) -> list[np.ndarray]:
    return [_circle(_steps(cfg), cfg.period_s, cfg.radius_m)]


def eight_offsets(cfg: Any) -> list[np.ndarray]:
    return [_eight(_steps(cfg), cfg.period_s, cfg.radius_m)]


def inclined_circle_offsets(cfg: Any) -> list[np.ndarray]:
    c = _circle(_steps(cfg), cfg.period_s, cfg.radius_m)
    tilt = np.deg2rad(cfg.tilt_deg)
    c[:, 2] = c[:, 0] * np.sin(tilt)
    c[:, 0] *= np.cos(tilt)
    return [c]


def circle_eight_offsets(cfg: Any) -> list[np.ndarray]:
    """The circle starts at its top point (centre + (0, R)) where the eight starts; the eight runs
    in the reverse direction so position, velocity and acceleration join continuously."""
    t = _steps(cfg)
    th = t[: len(t) // 2]
    r, half = cfg.radius_m, cfg.period_s / 2
    return [np.concatenate([_circle(th, half, r, np.pi / 2), _eight(th, half, r, -1.0)])]


def reaching_offsets(cfg: Any) -> list[np.ndarray]:
    """One out-and-back path per target, evenly spaced on a circle of ``radius_m``."""
    steps = len(_steps(cfg))
    n_out = int(round(cfg.out_s / CONTROL_DT_S))
    n_back = steps - n_out
    s = np.concatenate([min_jerk(np.arange(n_out) / n_out), 1.0 - min_jerk(np.arange(n_back) / n_back)])
    r = cfg.radius_m
    out = []
    for k in range(cfg.targets):
        a = np.pi + 2 * np.pi * k / cfg.targets
        out.append(s[:, None] * np.array([r * np.cos(a), r * np.sin(a), 0.0]))
    return out


Offsets = Callable[[Any], list[np.ndarray]]


def periodic_derivative(q: np.ndarray, dt: float) -> np.ndarray:
    """Central difference with wrap-around (the paths are periodic)."""
    return (np.roll(q, -1, 0) - np.roll(q, 1, 0)) / (2 * dt)


def solve_paths(cfg: Any, offsets_of: Offsets) -> dict[str, np.ndarray]:
    """Run IK for every variant of ``cfg``: arrays q (V, steps, 6), xyz (V, steps, 3), errors."""
    model = mujoco.MjModel.from_xml_string(kinematic_mjcf())
    lo = np.array([r[0] for r in JOINT_RANGE])
    hi = np.array([r[1] for r in JOINT_RANGE])
    ik = SiteIK(model, "end_effector", 6, lo, hi)
    home = np.asarray(cfg.home_q_rad, dtype=float)
    centre, rot = ik.fk(home)
    qs, xyzs = [], []
    for offsets in offsets_of(cfg):
        xyz = centre + offsets
        q = np.empty((len(xyz), 6))
        prev = home
        for i, p in enumerate(xyz):
            prev, _ = ik.solve(prev, p, rot)
            q[i] = prev
        qs.append(q)
        xyzs.append(xyz)
    return {"q": np.stack(qs), "xyz": np.stack(xyzs), "home": home, "centre": centre, "rot": rot}


def cache_key(cfg: Any) -> str:
    text = json.dumps(cfg.model_dump(mode="json"), sort_keys=True) + kinematic_mjcf() + IK_VERSION
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def load_or_solve(cfg: Any, cache_dir: Path | None, offsets_of: Offsets) -> dict[str, np.ndarray]:
    """Joint paths from the cache, or solved and written there (atomically)."""
    if cache_dir is None:
        return solve_paths(cfg, offsets_of)
    path = Path(cache_dir) / f"ik_{cfg.kind}_{cache_key(cfg)}.npz"
    if path.exists():
        try:
            with np.load(path) as f:
                return {k: f[k] for k in f.files}
        except (OSError, ValueError):
            pass
    data = solve_paths(cfg, offsets_of)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(f".{np.random.default_rng().integers(1 << 30)}.tmp.npz")
    np.savez(tmp, **data)
    tmp.replace(path)
    return data


class CartesianTask(Task):
    """A Baxter task whose trials are IK joint paths of Cartesian end-effector paths."""

    control_dt_s = CONTROL_DT_S

    def __init__(self, cfg: Any, paths: dict[str, np.ndarray]):
        self.cfg = cfg
        self.kind = cfg.kind
        self.period_s = float(cfg.period_s)
        self._q = paths["q"]
        self._qd = np.stack([periodic_derivative(q, CONTROL_DT_S) for q in self._q])
        self._xyz = paths["xyz"]
        self._home = np.asarray(paths["home"], dtype=float)
        self.centre = np.asarray(paths["centre"])
        self.orientation = np.asarray(paths["rot"])

    @property
    def variants(self) -> int:
        return self._q.shape[0]

    def trial(self, index: int, rng: np.random.Generator) -> TrialReference:
        v = int(rng.integers(self.variants)) if self.variants > 1 else 0
        label = f"{self.kind}:target{v}" if self.variants > 1 else self.kind
        return TrialReference(
            q=self._q[v].copy(), qd=self._qd[v].copy(), xyz=self._xyz[v].copy(), label=label
        )

    def start_position(self) -> np.ndarray:
        return self._home.copy()

    def first_sample(self) -> np.ndarray:
        """Joint positions of the first path sample (variant 0)."""
        return self._q[0, 0].copy()

    def envelope(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        q = self._q.reshape(-1, 6)
        qd = self._qd.reshape(-1, 6)
        return q.min(0), q.max(0), qd.min(0), qd.max(0)


def _builder(offsets_of: Offsets) -> Callable[[Any, Any], CartesianTask]:
    def build(cfg: Any, ctx: Any = None) -> CartesianTask:
        cache = getattr(ctx, "cache_dir", None) if ctx is not None else None
        return CartesianTask(cfg, load_or_solve(cfg, cache, offsets_of))

    build.__doc__ = f"Registry builder: the Cartesian task whose path is ``{offsets_of.__name__}``."
    return build


build_circle = _builder(circle_offsets)
build_eight = _builder(eight_offsets)
build_inclined_circle = _builder(inclined_circle_offsets)
build_circle_eight = _builder(circle_eight_offsets)
build_reaching = _builder(reaching_offsets)
