"""Spike-to-torque decoder (thesis Eq. 2.16-2.17 / 3.4-3.5, facts §4): per joint,
tau_j = alpha_j (agonist - antagonist DCN spikes in the 2 ms bin), no offset, no memory."""

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

    def torque(self, local_idx: np.ndarray) -> np.ndarray:
        """Torque (N m) from the local DCN indices that spiked in this bin (repeats count)."""
        net = np.bincount(local_idx // self.per_joint, weights=self.sign[local_idx], minlength=self.n_joints)
        return self.alpha * net[: self.n_joints]
