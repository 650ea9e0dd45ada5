"""Upper-limb tasks: flexion-extension and a vertical circle, both with
bell-shaped velocity profiles from the minimum-jerk polynomial s(u) = 10u^3 - 15u^4 + 6u^5. The paths are
constructed; see :mod:`cerebx.schema.arm_tasks`."""

from __future__ import annotations

import numpy as np

from cerebx.builders import BuildContext
from cerebx.errors import ConfigError
from cerebx.schema.arm_tasks import FlexionExtensionTask, VerticalCircleTask
from cerebx.tasks.base import Task, TrialReference

# The upper limb's planar geometry (upper_limb.xml, OpenSim x forward / y up, at q = 0): elbow centre in the
# humerus frame, hand point in the forearm frame. Joint range of the plant.
ELBOW_M = np.array([0.0061, -0.2904])
HAND_M = np.array([-0.0011, -0.23559])
RANGE_RAD = (np.array([-0.8, 0.0]), np.array([1.3, 2.26892803]))
# world position of the shoulder centre, moved into the plane the hand point moves in (world y = -0.252 m)
SHOULDER_WORLD_M = np.array([-0.017545, -0.252, 0.793])


def min_jerk(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Minimum-jerk position s(u) and ds/du on u in [0, 1]."""
    return u**3 * (10 - 15 * u + 6 * u**2), 30 * u**2 * (1 - u) ** 2


def _rot(a: np.ndarray, v: np.ndarray) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * v[0] - s * v[1], s * v[0] + c * v[1]], -1)


def hand_position(q: np.ndarray) -> np.ndarray:
    """Hand point (forward, up) from the shoulder for joint angles q (..., 2)."""
    q = np.asarray(q, float)
    return _rot(q[..., 0], ELBOW_M) + _rot(q[..., 0] + q[..., 1], HAND_M)


def jacobian(q: np.ndarray) -> np.ndarray:
    d_s = _rot(q[0] + np.pi / 2, ELBOW_M) + _rot(q[0] + q[1] + np.pi / 2, HAND_M)
    d_e = _rot(q[0] + q[1] + np.pi / 2, HAND_M)
    return np.stack([d_s, d_e], 1)


def inverse_kinematics(xy: np.ndarray, q0: np.ndarray) -> np.ndarray:
    """Joint angles for each hand point in ``xy`` (steps, 2), Newton iterations from ``q0`` then from the
    previous point's solution (keeps the elbow-flexed branch)."""
    out = np.empty((len(xy), 2))
    q = np.asarray(q0, float).copy()
    for i, target in enumerate(xy):
        for _ in range(50):
            err = target - hand_position(q)
            if np.linalg.norm(err) < 1e-12:
                break
            q = q + np.linalg.solve(jacobian(q), err)
        out[i] = q
    if np.abs(hand_position(out) - xy).max() > 1e-9:
        raise ConfigError("task: the circle leaves the arm's reach (inverse kinematics does not converge)")
    return out


class _UpperLimbTask(Task):
    control_dt_s = 0.002

    def _finish(self, q: np.ndarray, qd: np.ndarray, label: str, xyz: np.ndarray | None = None) -> None:
        lo, hi = RANGE_RAD
        if np.any(q < lo) or np.any(q > hi):
            raise ConfigError(f"task: the {label} path leaves the upper limb's joint range "
                              f"(shoulder {lo[0]}..{hi[0]}, elbow {lo[1]}..{hi[1]:.3f} rad)")
        self._ref = TrialReference(q=q, qd=qd, xyz=xyz, label=label)

    def trial(self, index: int, rng: np.random.Generator) -> TrialReference:
        return self._ref

    def start_position(self) -> np.ndarray:
        return self._ref.q[0].copy()


class FlexionExtension(_UpperLimbTask):
    def __init__(self, cfg: FlexionExtensionTask, ctx: BuildContext | None = None):
        self.period_s = cfg.period_s
        n = self.steps_per_trial
        t = np.arange(n) * self.control_dt_s
        half = cfg.period_s / 2
        u = np.where(t < half, t / half, (t - half) / half)
        s, ds = min_jerk(u)
        a, b = np.asarray(cfg.start_rad), np.asarray(cfg.end_rad)
        out = t < half
        frac = np.where(out, s, 1 - s)[:, None]
        rate = np.where(out, ds, -ds)[:, None] / half
        self._finish(a + frac * (b - a), rate * (b - a), "flexion_extension")


class VerticalCircle(_UpperLimbTask):
    def __init__(self, cfg: VerticalCircleTask, ctx: BuildContext | None = None):
        self.period_s = cfg.period_s
        n = self.steps_per_trial
        t = np.arange(n) * self.control_dt_s
        s, ds = min_jerk(t / cfg.period_s)
        phi = cfg.start_angle_rad + 2 * np.pi * s
        phid = 2 * np.pi * ds / cfg.period_s
        c, r = np.asarray(cfg.centre_m), cfg.radius_m
        xy = c + r * np.stack([np.cos(phi), np.sin(phi)], 1)
        xyd = r * phid[:, None] * np.stack([-np.sin(phi), np.cos(phi)], 1)
        q = inverse_kinematics(xy, np.array([0.4, 1.2]))
        qd = np.array([np.linalg.solve(jacobian(qi), v) for qi, v in zip(q, xyd)])
        # the hand's path in the world frame (x forward, z up; the arm's plane is y = const)
        xyz = SHOULDER_WORLD_M + np.stack([xy[:, 0], np.zeros(n), xy[:, 1]], 1)
        self._finish(q, qd, "vertical_circle", xyz)
