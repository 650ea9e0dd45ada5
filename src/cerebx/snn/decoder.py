"""Spike-to-torque decoder (docs/models.md#dcn-decoder): per joint,
tau_j = alpha_j (agonist - antagonist DCN spikes in the 2 ms bin), no offset, no memory.
For a muscle stage the two sides are kept apart: M_ag,j and M_at,j = the side's
spikes in the bin / full scale, each in [0, 1] when the full scale is the most the side can fire,
or capped at 1 (saturate)."""

from __future__ import annotations

import numpy as np
from numba import njit


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


@njit(cache=True, nogil=True, boundscheck=False)
def chunk_sides(idx, off, lo, hi, per_joint, full_scale, saturate):
    """A chunk's muscle commands without the interpreter lock: per step [M_ag of each joint, M_at of each joint]
    from ``idx[off[s]:off[s + 1]]`` (the DCN are ``lo:hi``), the same doubles as :meth:`DCNDecoder.sides` (a
    side's spike count divided by its joint's ``full_scale``, capped at 1 with ``saturate``), and the DCN spikes
    per step."""
    n, nj, half = off.size - 1, full_scale.size, per_joint // 2
    m = np.zeros((n, 2 * nj))
    counts = np.zeros(n, np.int64)
    for s in range(n):
        for k in range(off[s], off[s + 1]):
            i = idx[k]
            if lo <= i < hi:
                c = (i - lo) // half  # 2 joint + side
                m[s, (c % 2) * nj + c // 2] += 1.0
                counts[s] += 1
    for s in range(n):
        for c in range(2 * nj):
            x = m[s, c] / full_scale[c % nj]
            m[s, c] = min(x, 1.0) if saturate else x
    return m, counts


@njit(cache=True, nogil=True, boundscheck=False)
def chunk_torques(idx, off, lo, hi, per_joint, sign, alpha):
    """A chunk's torques without the interpreter lock: ``idx[off[s]:off[s + 1]]`` are the global indices that
    spiked in step s; the DCN are ``lo:hi``. Returns (torque per step and joint, DCN spikes per step), the sums
    made in the order of the spikes, as ``np.bincount`` with weights makes them (the same doubles as
    :meth:`DCNDecoder.torque` per step)."""
    n, nj = off.size - 1, alpha.size
    net = np.zeros((n, nj))
    counts = np.zeros(n, np.int64)
    for s in range(n):
        for k in range(off[s], off[s + 1]):
            i = idx[k]
            if lo <= i < hi:
                d = i - lo
                net[s, d // per_joint] += sign[d]
                counts[s] += 1
    for s in range(n):
        for j in range(nj):
            net[s, j] = alpha[j] * net[s, j]
    return net, counts


@njit(cache=True, nogil=True, boundscheck=False)
def chunk_select(idx, off, lo, hi):
    """The spikes of each population ``lo[p]:hi[p]`` in a chunk, as local indices one population after the
    other, and where each step's part ends (population p, step s: ``local[ends[p, s - 1]:ends[p, s]]``, the
    first step from ``ends[p - 1, -1]``, 0 for the first population). One call for all the populations
    recorded: each return from compiled code waits for the interpreter lock."""
    n, n_pop = off.size - 1, lo.size
    local = np.empty(n_pop * (off[n] - off[0]), np.int32)
    ends = np.empty((n_pop, n), np.int64)
    m = 0
    for p in range(n_pop):
        a, b = lo[p], hi[p]
        for s in range(n):
            for k in range(off[s], off[s + 1]):
                i = idx[k]
                if a <= i < b:
                    local[m] = i - a
                    m += 1
            ends[p, s] = m
    return local[:m], ends
