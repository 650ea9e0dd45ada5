"""Damped least-squares inverse kinematics of a MuJoCo site, holding a fixed orientation.

On a redundant chain (more joints than the 6 task coordinates) an optional rest posture is pursued
in the Jacobian's null space, so each solution is the one nearest that posture: the joint path of
a closed Cartesian path then closes too (plain least-squares steps drift from lap to lap).
"""

from __future__ import annotations

import mujoco
import numpy as np


def rotation_error(r_cur: np.ndarray, r_des: np.ndarray) -> np.ndarray:
    """Small-angle rotation vector taking ``r_cur`` to ``r_des`` (world frame, rad): half the sum over the
    columns of r_cur x r_des, written out on floats (``np.cross`` on 3-vectors took 70 % of a path's IK; the
    same operations in the same order, so the same bits)."""
    (a00, a01, a02), (a10, a11, a12), (a20, a21, a22) = r_cur.tolist()
    (b00, b01, b02), (b10, b11, b12), (b20, b21, b22) = r_des.tolist()
    x = ((a10 * b20 - a20 * b10) + (a11 * b21 - a21 * b11)) + (a12 * b22 - a22 * b12)
    y = ((a20 * b00 - a00 * b20) + (a21 * b01 - a01 * b21)) + (a22 * b02 - a02 * b22)
    z = ((a00 * b10 - a10 * b00) + (a01 * b11 - a11 * b01)) + (a02 * b12 - a12 * b02)
    return np.array([0.5 * x, 0.5 * y, 0.5 * z])


def rotation_angle(r_a: np.ndarray, r_b: np.ndarray) -> float:
    """Angle (rad) of the relative rotation between two rotation matrices."""
    c = (np.trace(r_a.T @ r_b) - 1.0) / 2.0
    return float(np.arccos(np.clip(c, -1.0, 1.0)))


class SiteIK:
    """Solves q so that a site reaches positions with one fixed orientation.

    Uses its own MjData on ``model``; the first ``n`` joints (hinges, qpos = qvel index) are solved.
    """

    def __init__(self, model: mujoco.MjModel, site: str, n: int, lower: np.ndarray, upper: np.ndarray):
        self.model = model
        self.data = mujoco.MjData(model)
        self.site = model.site(site).id
        self.n = n
        self.lower, self.upper = lower, upper
        self._jac = np.zeros((6, model.nv))

    def fk(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d = self.data
        d.qpos[: self.n] = q
        mujoco.mj_kinematics(self.model, d)
        return d.site_xpos[self.site].copy(), d.site_xmat[self.site].reshape(3, 3).copy()

    def solve(
        self,
        q0: np.ndarray,
        pos: np.ndarray,
        rot: np.ndarray,
        *,
        tol: float = 1e-9,
        damping: float = 1e-4,
        max_iter: int = 100,
        posture: np.ndarray | None = None,
    ) -> tuple[np.ndarray, float]:
        """Newton iterations with damped least squares from ``q0``; returns (q, final error norm).

        With ``posture`` (redundant chains) each step also moves towards it in the null space of the
        Jacobian, and iterating stops once that step is negligible too."""
        m, d, n = self.model, self.data, self.n
        q = np.array(q0, dtype=float)
        err = np.zeros(6)
        norm = np.inf
        damp, eye_n = damping**2 * np.eye(6), np.eye(n)
        for _ in range(max_iter):
            d.qpos[:n] = q
            mujoco.mj_kinematics(m, d)
            mujoco.mj_comPos(m, d)
            err[:3] = pos - d.site_xpos[self.site]
            err[3:] = rotation_error(d.site_xmat[self.site].reshape(3, 3), rot)
            norm = float(np.linalg.norm(err))
            mujoco.mj_jacSite(m, d, self._jac[:3], self._jac[3:], self.site)
            j = self._jac[:, :n]
            pinv = j.T @ np.linalg.inv(j @ j.T + damp)
            dq = pinv @ err
            if posture is not None:
                dq += (eye_n - pinv @ j) @ (posture - q)
            if norm < tol and (posture is None or np.linalg.norm(dq) < tol):
                break
            q = np.clip(q + dq, self.lower, self.upper)
        return q, norm
