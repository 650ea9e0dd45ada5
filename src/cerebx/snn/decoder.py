"""Spike-to-torque decoder (docs/models.md#dcn-decoder): per joint,
tau_j = alpha_j (agonist - antagonist DCN spikes in the 2 ms bin), no offset, no memory.
For a muscle stage the two sides are kept apart: M_ag,j and M_at,j = the side's
spikes in the bin / full scale, each in [0, 1] when the full scale is the most the side can fire,
or capped at 1 (saturate)."""

from __future__ import annotations

import numpy as np


class DCNDecoder:
    def __init__(self, alpha_Nm_per_spike, n_joints: int, per_joint: int):
        if per_joint % 2:
            raise ValueError(f"DCN per joint ({per_joint}) must be even (agonist/antagonist)")
        self.alpha = np.asarray(alpha_Nm_per_spike, dtype=np.float64)[:n_joints]
        self.n_joints, self.per_joint = n_joints, per_joint
        sign = np.concatenate([np.ones(per_joint // 2), -np.ones(per_joint // 2)])
        self.sign = np.tile(sign, n_joints)

    def sides(self, local_idx: np.ndarray, step_of: np.ndarray, n_steps: int, full_scale,
              saturate: bool = False) -> np.ndarray:
        """(n_steps, 2 n_joints): per step [M_ag of each joint, M_at of each joint] from the local DCN
        indices that spiked and the step each spike belongs to (repeats count); ``full_scale`` one value
        or one per joint; ``saturate`` caps M at 1."""
        nj, half = self.n_joints, self.per_joint // 2
        counts = np.bincount(step_of * 2 * nj + local_idx // half, minlength=n_steps * 2 * nj)
        scale = np.broadcast_to(np.asarray(full_scale, dtype=np.float64), (nj,))[:, None]
        m = counts[: n_steps * 2 * nj].reshape(n_steps, nj, 2) / scale
        if saturate:
            m = np.minimum(m, 1.0)
        return m.transpose(0, 2, 1).reshape(n_steps, 2 * nj)

    def torque(self, local_idx: np.ndarray) -> np.ndarray:
        """Torque (N m) from the local DCN indices that spiked in this bin (repeats count)."""
        net = np.bincount(local_idx // self.per_joint, weights=self.sign[local_idx], minlength=self.n_joints)
        return self.alpha * net[: self.n_joints]
