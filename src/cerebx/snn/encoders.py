"""Analog-to-spike encoders (thesis §2.2.6, facts §3).

MF box coding: per joint and signal (q_d, q, qd_d, qd), ``F`` fibres with centres evenly spaced
over [r_min, r_max] and half-width step * width_factor; the input is clipped to the range and
the fibre whose box contains it fires once per 2 ms step. MF local index = 4F j + F s + bin.

CF coding: e = kpos (q_d - q) + kvel (qd_d - qd); e > 0 drives the 50 agonist fibres of the
joint (input e), otherwise the antagonist ones (input |e|). Fibre k of a side has centre
c_k = c_min + k (c_max - c_min)/(n - 1) and width = centre step; rate = r_min + (r_max - r_min)
(tanh((x - c_k)/width) + 1)/2. Each step a fibre fires with probability rate * 2 ms; an event is
a burst of floor(x / c_k) spikes (clipped to 1..max_burst), one per step.
"""

from __future__ import annotations

import numpy as np

from cerebx.schema.controller import BoxEncoder, CFEncoder

STEP_S = 0.002


class MossyEncoder:
    """Box (interval) coding of the four signals of every joint."""

    def __init__(self, cfg: BoxEncoder, lo: np.ndarray, hi: np.ndarray):
        """``lo``/``hi``: shape (n_joints, 4) ranges of q_d, q, qd_d, qd."""
        self.F = cfg.fibers_per_signal
        self.lo = np.asarray(lo, dtype=np.float64)
        self.hi = np.asarray(hi, dtype=np.float64)
        self.step = (self.hi - self.lo) / (self.F - 1)
        self.half_width = self.step * cfg.width_factor
        self.n_joints = self.lo.shape[0]
        self.base = (np.arange(self.n_joints)[:, None] * 4 + np.arange(4)[None, :]) * self.F

    @property
    def n_fibers(self) -> int:
        return self.n_joints * 4 * self.F

    def active(self, q_des, q, qd_des, qd) -> np.ndarray:
        """Local indices of the fibres firing this step (one per signal; two only on an exact
        box boundary, as in the original)."""
        x = np.stack([q_des, q, qd_des, qd], axis=1)[: self.n_joints]
        x = np.clip(x, self.lo, self.hi)
        pos = (x - self.lo) / self.step
        b = np.clip(np.rint(pos).astype(np.int64), 0, self.F - 1)
        out = [(self.base + b).ravel()]
        # a neighbour is also inside its box only at an exact midpoint (width is 0.5 step + 1e-12)
        for nb in (b - 1, b + 1):
            ok = (nb >= 0) & (nb < self.F)
            c = self.lo + np.clip(nb, 0, self.F - 1) * self.step
            both = ok & (np.abs(x - c) < self.half_width)
            if both.any():
                out.append((self.base + nb)[both])
        return np.sort(np.concatenate(out)) if len(out) > 1 else out[0]


class ClimbingEncoder:
    """Stochastic error coding on agonist/antagonist climbing fibres."""

    def __init__(self, cfg: CFEncoder, n_joints: int, per_joint: int, kpos, kvel, rng: np.random.Generator):
        if per_joint % 2:
            raise ValueError(f"climbing fibres per joint ({per_joint}) must be even (agonist/antagonist)")
        self.cfg = cfg
        self.n_joints, self.per_joint, self.half = n_joints, per_joint, per_joint // 2
        self.kpos = np.asarray(kpos, dtype=np.float64)[:n_joints]
        self.kvel = np.asarray(kvel, dtype=np.float64)[:n_joints]
        n = self.half
        self.centres = cfg.center_min + np.arange(n) * (cfg.center_max - cfg.center_min) / max(n - 1, 1)
        self.width = (cfg.center_max - cfg.center_min) / max(n - 1, 1)
        self.rng = rng
        self.burst_left = np.zeros(n_joints * per_joint, dtype=np.int64)

    def error(self, q_des, q, qd_des, qd) -> np.ndarray:
        n = self.n_joints
        return self.kpos * (q_des[:n] - q[:n]) + self.kvel * (qd_des[:n] - qd[:n])

    def rates(self, e: np.ndarray) -> np.ndarray:
        """Firing rate (Hz) of every fibre, shape (n_joints, per_joint); the silent side is 0."""
        c = self.cfg
        x = np.abs(e)[:, None]
        r = c.rate_min_hz + (c.rate_max_hz - c.rate_min_hz) * (np.tanh((x - self.centres) / self.width) + 1) / 2
        out = np.zeros((self.n_joints, self.per_joint))
        pos = e > 0
        out[pos, : self.half] = r[pos]
        out[~pos, self.half :] = r[~pos]
        return out

    def bursts(self, e: np.ndarray) -> np.ndarray:
        """Spikes per event for every fibre: floor(|e| / c_k) clipped to 1..max_burst."""
        n = np.floor(np.abs(e)[:, None] / self.centres).astype(np.int64)
        n = np.clip(n, 1, self.cfg.max_burst)
        return np.concatenate([n, n], axis=1)

    def active(self, e: np.ndarray) -> np.ndarray:
        """Local indices of the fibres spiking this step (new events plus ongoing bursts)."""
        p = (self.rates(e) * STEP_S).ravel()
        fire = (self.rng.random(p.shape[0]) < p) & (self.burst_left == 0)
        self.burst_left[fire] = self.bursts(e).ravel()[fire]
        spiking = np.flatnonzero(self.burst_left > 0)
        self.burst_left[spiking] -= 1
        return spiking

    def reset(self) -> None:
        self.burst_left[:] = 0
