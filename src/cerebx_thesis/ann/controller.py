"""The rate-based (analog) cerebellum: the ANN baseline of thesis §3.2.6 / Annex S6
(docs/models.md#ann-plasticity; the original code: docs/provenance.md#original-ann).

Each step, per joint j with agonist/antagonist cells s in {ag, an}:

    active_j  = the 4n granule cells of joint j's state table (see :meth:`ANN.active_cells`)
    PC_js     = sum of w[js, g] over the active cells of all joints (``pc_input``; own joint only optional)
    e_j       = k_pos (q_d - q) + k_vel (qd_d - qd);  IO_j,ag = clip(e_j, 0, 1), IO_j,an = clip(-e_j, 0, 1)
    DCN_js    = clip(w_mf MF - w_pc PC_js + w_io IO_js, 0, 1)
    tau_j     = gain_j (DCN_j,ag - DCN_j,an)
    w[js, g] += (LTP (1 - IO_js) - LTD IO_js) |e_k|  for every listed active cell g of joint k, clipped to [0, w_max]

As the original ``analog_cerebellum.py`` (docs/provenance.md#original-ann), the newest arrived
measurement is paired with the newest desired sample (``desired: newest``): under a sensor delay d the
error and the state coding compare q_d(t) with q(t - d), exactly as the PD does; the original's
time-aligning full-state node only
fed its MAE plots, not the ANN. ``desired: sensor_stamp`` pairs the measurement with the desired
sample of its own stamp instead (what the SNN's CF error does). The |e| factor of a weight change is
the error of the joint whose granule cell is listed (the original's loop order), not the PC's joint
(``plasticity_error``). Every step is a handful of numpy calls on arrays of at most 12 x 96 entries;
there is no per-cell Python loop.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import numpy as np

from cerebx.api import (
    BuildContext,
    ControlInput,
    Controller,
    StateMismatchError,
    TorqueMsg,
    load_state_npz,
    mf_ranges,
    save_state_npz,
)
from cerebx_thesis.ann.schema import ANNController

STEP_S = 0.002
HISTORY_STEPS = 4096
STATE_VERSION = 1


class ANN(Controller):
    def __init__(self, cfg: ANNController, ctx: BuildContext | None = None):
        self.cfg = cfg
        nj = cfg.n_joints
        self.n_ctrl = nj
        plant = getattr(ctx, "plant", None)
        self.n_joints = plant.n_joints if plant is not None else nj
        if self.n_joints < nj:
            raise ValueError(f"controller: {nj} joints configured but the plant has {self.n_joints}")
        self.lo, self.hi = mf_ranges(cfg.ranges, nj, getattr(ctx, "task", None))
        n = cfg.bins
        self.n_bins = n
        self.states_per_joint = n**4
        self.strides = n ** np.arange(3, -1, -1)
        self._bin_values = np.arange(n)
        self._joint_offset = np.arange(nj) * self.states_per_joint
        self.k_pos, self.k_vel = np.asarray(cfg.k_pos, float), np.asarray(cfg.k_vel, float)
        self.gain = np.asarray(cfg.gain_Nm, float)
        self.w_init = cfg.initial_weight
        self.w_max = cfg.w_max_factor * self.w_init
        self.pc_joint = np.repeat(np.arange(nj), 2)  # PC/IO/DCN order: ag0, an0, ag1, an1, ...
        self._rows = np.arange(2 * nj)[:, None]
        self.config_hash = hashlib.sha256(
            json.dumps(cfg.model_dump(mode="json"), sort_keys=True).encode()
        ).hexdigest()[:16]
        self.w = np.full((2 * nj, nj * self.states_per_joint), self.w_init)
        self.reset(np.random.default_rng(0))

    def reset(self, rng: np.random.Generator) -> None:
        """Clear the loop state; the learned weights persist (they may come from ``load_state``)."""
        self._q_hist = np.zeros((HISTORY_STEPS, self.n_ctrl))
        self._qd_hist = np.zeros((HISTORY_STEPS, self.n_ctrl))
        self._hist_tick = np.full(HISTORY_STEPS, -1, dtype=np.int64)
        self._zero = np.zeros(self.n_joints)
        self._abs_error_sum = np.zeros(self.n_ctrl)
        self._steps = 0

    def position_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The MF position ranges, which the original used as watchdog bounds."""
        lo, hi = np.zeros(self.n_joints), np.zeros(self.n_joints)
        lo[: self.n_ctrl], hi[: self.n_ctrl] = self.lo[:, 1], self.hi[:, 1]
        return lo, hi

    def active_cells(self, q_d: np.ndarray, q: np.ndarray, qd_d: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """(n_joints, 4 n) global indices of the active granule cells.

        Row j lists, for each signal in turn, the n cells that differ from joint j's current
        state only in that signal; the current state itself is listed once per signal.
        """
        x = np.stack([q_d, q, qd_d, qd], axis=1)
        b = np.floor((x - self.lo) / (self.hi - self.lo) * self.n_bins)
        b = np.clip(b, 0, self.n_bins - 1).astype(np.int64)
        base = b @ self.strides
        cells = (
            base[:, None, None]
            + (self._bin_values[None, None, :] - b[:, :, None]) * self.strides[None, :, None]
        )
        cells = cells.reshape(self.n_ctrl, -1) + self._joint_offset[:, None]
        if self.cfg.joint0_overwrite:
            k = min(5, self.n_ctrl - 1)
            cells[0, 1 : k + 1] = base[1 : k + 1] + self._joint_offset[1 : k + 1]
        return cells

    def _pc_columns(self, cells: np.ndarray) -> np.ndarray:
        if self.cfg.pc_input == "all_joints":
            return np.broadcast_to(cells.reshape(1, -1), (2 * self.n_ctrl, cells.size))
        return cells[self.pc_joint]

    def _remember_desired(self, inp: ControlInput) -> None:
        i = inp.tick % HISTORY_STEPS
        self._q_hist[i], self._qd_hist[i], self._hist_tick[i] = (
            inp.q_des[: self.n_ctrl],
            inp.qd_des[: self.n_ctrl],
            inp.tick,
        )

    def _desired_at(self, stamp_s: float, inp: ControlInput) -> tuple[np.ndarray, np.ndarray]:
        tick = int(round(stamp_s / STEP_S))
        i = tick % HISTORY_STEPS
        if self._hist_tick[i] == tick:
            return self._q_hist[i], self._qd_hist[i]
        return inp.q_des[: self.n_ctrl], inp.qd_des[: self.n_ctrl]

    def control(self, inp: ControlInput) -> TorqueMsg:
        self._remember_desired(inp)
        s = inp.sensor
        if s is None:
            return TorqueMsg(inp.t_s, self._zero)
        nj = self.n_ctrl
        if self.cfg.desired == "newest":
            q_d, qd_d = inp.q_des[:nj], inp.qd_des[:nj]
        else:
            q_d, qd_d = self._desired_at(s.stamp_s, inp)
        q, qd = s.q[:nj], s.qd[:nj]
        e = self.k_pos * (q_d - q) + self.k_vel * (qd_d - qd)
        io = np.empty(2 * nj)
        io[0::2] = np.clip(e, 0.0, 1.0)
        io[1::2] = np.clip(-e, 0.0, 1.0)
        cols = self._pc_columns(self.active_cells(q_d, q, qd_d, qd))
        pc = self.w[self._rows, cols].sum(axis=1)
        c = self.cfg
        dcn = np.clip(c.w_mf_dcn * c.mf_rate - c.w_pc_dcn * pc + c.w_io_dcn * io, 0.0, 1.0)
        tau = np.zeros(self.n_joints)
        tau[:nj] = self.gain * (dcn[0::2] - dcn[1::2])
        if c.plasticity:
            rows = np.broadcast_to(self._rows, cols.shape)
            rate = c.ltp * (1.0 - io) - c.ltd * io
            if c.plasticity_error == "granule_joint" and c.pc_input == "all_joints":
                # columns are joint 0's 4n listed cells, then joint 1's, ...: each scaled by its joint's |e|
                dw = rate[:, None] * np.repeat(np.abs(e), 4 * self.n_bins)[None, :]
            else:  # a row's own joint (with 'own_joint' input the granule cell's joint is the PC's)
                dw = np.broadcast_to((rate * np.abs(e)[self.pc_joint])[:, None], cols.shape)
            np.add.at(self.w, (rows, cols), dw)
            self.w[rows, cols] = np.clip(self.w[rows, cols], 0.0, self.w_max)
        self._abs_error_sum += np.abs(q_d - q)
        self._steps += 1
        return TorqueMsg(inp.t_s, tau)

    def end_trial(self, trial: int) -> dict[str, float]:
        out = {
            "w_mean": float(self.w.mean()),
            "w_min": float(self.w.min()),
            "w_max": float(self.w.max()),
            "w_at_floor_frac": float(np.mean(self.w <= 0.0)),
            "w_at_ceiling_frac": float(np.mean(self.w >= self.w_max)),
        }
        if self._steps:
            out["controller_mae_rad"] = float(self._abs_error_sum.mean() / self._steps)
        self._abs_error_sum[:] = 0.0
        self._steps = 0
        return out

    def describe(self) -> dict[str, Any]:
        return {
            "granule_cells": int(self.w.shape[1]),
            "active_per_joint": 4 * self.n_bins,
            "purkinje_cells": int(self.w.shape[0]),
            "w_init": self.w_init,
            "w_max": self.w_max,
            "pc_input": self.cfg.pc_input,
            "joint0_overwrite": self.cfg.joint0_overwrite,
            "gain_Nm": list(self.cfg.gain_Nm),
        }

    def save_state(self, path: Path) -> bool:
        path = Path(path)
        meta = {
            "version": STATE_VERSION,
            "kind": "ann",
            "config": self.config_hash,
            "shape": list(self.w.shape),
        }
        save_state_npz(path, meta, w=self.w)
        return True

    def load_state(self, path: Path) -> None:
        data, meta = load_state_npz(path, "ANN")
        w = data["w"] if "w" in data.files else np.zeros(0)
        if meta.get("kind") != "ann" or tuple(w.shape) != self.w.shape:
            raise StateMismatchError(
                f"{path}: ANN state of shape {tuple(w.shape)} does not fit this controller "
                f"({self.w.shape}; bins and joints must match)"
            )
        self.w[...] = w
