"""Cartesian Baxter tasks (docs/models.md#cartesian-tasks): end-effector paths turned into joint paths by
inverse kinematics.

The end-effector is the Baxter model's ``end_effector`` site (origin of the URDF ``left_hand`` frame,
base frame). The path is centred on the end-effector position of the home pose; the orientation is
held at the home orientation. As in the original (docs/provenance.md#original-trajectories: MoveIt on the 7-joint
arm, then w2 held at 0 by the supervisor), IK solves the 7-joint chain including the wrist roll w2 and the task keeps
s0..w1: the end-effector lies on the w2 axis, so dropping w2 keeps the position exactly and turns
the hand about that axis only. The redundancy is resolved towards the home pose (w2 = 0), a
*constructed* choice (MoveIt's is not recorded) that reproduces the original paths' joint envelopes
to within 0.03 rad. IK runs once per task definition and is cached on disk under
``ctx.cache_dir`` keyed by a hash of the task config and the arm's MJCF file.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from cerebx.builders import BuildContext
from cerebx.plants.baxter import JOINT_RANGE, MJCF, W2_RANGE, kinematic_model
from cerebx.tasks.base import Task, TrialReference
from cerebx.tasks.ik import SiteIK

CONTROL_DT_S = 0.002
IK_VERSION = "dls7-posture-1"


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


def ramp_linear(s: np.ndarray, ramp: float) -> np.ndarray:
    """Position profile 0 -> 1 on s in [0, 1] whose velocity rises smoothly (half cosine) over the
    first ``ramp`` of the way, then stays constant to the end ("smooth ramp then linear",
    docs/provenance.md#original-trajectories)."""
    s = np.clip(s, 0.0, 1.0)
    if ramp <= 0:
        return s
    v = 1.0 / (1.0 - ramp / 2)  # the constant speed that still arrives at 1
    rising = v * (s / 2 - ramp / (2 * np.pi) * np.sin(np.pi * s / ramp))
    return np.where(s < ramp, rising, v * (ramp / 2 + (s - ramp)))


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


def reaching_profile(cfg: Any) -> np.ndarray:
    """Fraction of the way to the target at each step of a trial: out in ``out_s``, back in the
    rest, each leg following ``cfg.profile``."""
    steps = len(_steps(cfg))
    n_out = int(round(cfg.out_s / CONTROL_DT_S))
    n_back = steps - n_out
    if cfg.profile == "min_jerk":
        leg = min_jerk
    else:
        def leg(x: np.ndarray) -> np.ndarray:
            return ramp_linear(x, cfg.ramp_fraction)
    return np.concatenate([leg(np.arange(n_out) / n_out), 1.0 - leg(np.arange(n_back) / n_back)])


def reaching_targets(cfg: Any) -> np.ndarray:
    """(targets, 3) offsets from the centre, evenly spaced on a circle of ``radius_m`` from angle pi
    (where the circle starts)."""
    a = np.pi + 2 * np.pi * np.arange(cfg.targets) / cfg.targets
    r = cfg.radius_m
    return np.stack([r * np.cos(a), r * np.sin(a), np.zeros_like(a)], 1)


def reaching_offsets(cfg: Any) -> list[np.ndarray]:
    """One straight out-and-back Cartesian path per target."""
    s = reaching_profile(cfg)
    return [s[:, None] * target for target in reaching_targets(cfg)]


Offsets = Callable[[Any], list[np.ndarray]]


def periodic_derivative(q: np.ndarray, dt: float) -> np.ndarray:
    """Central difference with wrap-around (the paths are periodic)."""
    return (np.roll(q, -1, 0) - np.roll(q, 1, 0)) / (2 * dt)


def _arm_ik() -> SiteIK:
    """IK of the end-effector on the 7-joint chain (s0..w1 and w2)."""
    model = kinematic_model(w2=True)
    lo = np.array([r[0] for r in JOINT_RANGE] + [W2_RANGE[0]])
    hi = np.array([r[1] for r in JOINT_RANGE] + [W2_RANGE[1]])
    return SiteIK(model, "end_effector", 7, lo, hi)


def _paths(q7: np.ndarray, xyz: np.ndarray, home: np.ndarray, centre: np.ndarray, rot: np.ndarray) -> dict:
    return {"q": q7[..., :6].copy(), "q7": q7, "xyz": xyz, "home": home, "centre": centre, "rot": rot}


def solve_paths(cfg: Any, offsets_of: Offsets) -> dict[str, np.ndarray]:
    """Run IK on the 7-joint chain for every variant of ``cfg``: arrays q (V, steps, 6: s0..w1, w2
    dropped), q7 (V, steps, 7: the solution with w2), xyz (V, steps, 3), home, centre, rot."""
    ik = _arm_ik()
    home = np.asarray(cfg.home_q_rad, dtype=float)
    home7 = np.append(home, 0.0)
    centre, rot = ik.fk(home7)
    qs, xyzs = [], []
    for offsets in offsets_of(cfg):
        xyz = centre + offsets
        q = np.empty((len(xyz), 7))
        prev = home7
        for i, p in enumerate(xyz):
            prev, _ = ik.solve(prev, p, rot, posture=home7, max_iter=200)
            q[i] = prev
        qs.append(q)
        xyzs.append(xyz)
    return _paths(np.stack(qs), np.stack(xyzs), home, centre, rot)


def solve_reaching(cfg: Any) -> dict[str, np.ndarray]:
    """Reaching paths: straight Cartesian legs (``space: cartesian``, IK at every sample), or, as the
    original (docs/provenance.md#original-trajectories: joint-space targets, joint-space ramps), IK at the targets
    only and the joints
    interpolated from the home pose (``space: joint``; the hand then moves on a slightly curved line)."""
    if cfg.space == "cartesian":
        return solve_paths(cfg, reaching_offsets)
    ik = _arm_ik()
    home = np.asarray(cfg.home_q_rad, dtype=float)
    home7 = np.append(home, 0.0)
    centre, rot = ik.fk(home7)
    s = reaching_profile(cfg)[:, None]
    qs, xyzs = [], []
    for target in reaching_targets(cfg):
        q_end, _ = ik.solve(home7, centre + target, rot, posture=home7, max_iter=400)
        q = home7 + s * (q_end - home7)
        qs.append(q)
        xyzs.append(np.stack([ik.fk(qi)[0] for qi in q]))
    return _paths(np.stack(qs), np.stack(xyzs), home, centre, rot)


def cache_key(cfg: Any) -> str:
    text = json.dumps(cfg.model_dump(mode="json"), sort_keys=True) + MJCF.read_text() + IK_VERSION
    return hashlib.sha256(text.encode()).hexdigest()[:24]


Solver = Callable[[Any], dict[str, np.ndarray]]


def load_or_solve(cfg: Any, cache_dir: Path | None, solve: Solver) -> dict[str, np.ndarray]:
    """Joint paths from the cache, or solved by ``solve(cfg)`` and written there (atomically)."""
    if cache_dir is None:
        return solve(cfg)
    path = Path(cache_dir) / f"ik_{cfg.kind}_{cache_key(cfg)}.npz"
    if path.exists():
        try:
            with np.load(path) as f:
                return {k: f[k] for k in f.files}
        except (OSError, ValueError):
            pass
    data = solve(cfg)
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
        self._q7 = paths.get("q7")
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


def _builder(offsets_of: Offsets | None = None, solve: Solver | None = None) -> Callable[[Any, Any], CartesianTask]:
    if solve is None:
        def solve(cfg: Any) -> dict[str, np.ndarray]:
            return solve_paths(cfg, offsets_of)
        name = offsets_of.__name__
    else:
        name = solve.__name__

    def build(cfg: Any, ctx: BuildContext | None = None) -> CartesianTask:
        cache = getattr(ctx, "cache_dir", None) if ctx is not None else None
        return CartesianTask(cfg, load_or_solve(cfg, cache, solve))

    build.__doc__ = f"Registry builder: the Cartesian task whose path is ``{name}``."
    return build


build_circle = _builder(circle_offsets)
build_eight = _builder(eight_offsets)
build_inclined_circle = _builder(inclined_circle_offsets)
build_circle_eight = _builder(circle_eight_offsets)
build_reaching = _builder(solve=solve_reaching)
