"""The corrective spiking cerebellum of Luque et al. 2011 as a brain-side stage.

Each 2 ms tick: the desired q and qd of the three joints are RBF-encoded into the 120 input cells'
drive (Eq. 2); the newest joint measurement that has arrived through the link is compared with the
desired state of its own time stamp (Eq. 7) and the IO cells fire with a probability that grows with
the error (0-10 Hz); the network (``cerebellum/kernels.py``) advances 2 ms with PF-PC plasticity; the DCN spikes
of the last ``buffer_ms`` give the corrective torque, rate(+ group) - rate(- group) per joint. The
teaching delay is the link's: a measurement that arrives at t was caused by torques sent about one
round trip earlier, which is where the LTD kernel peaks.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from cerebx.api import BuildContext, Frame, Stage, StateMismatchError, load_state_npz, save_state_npz
from cerebx_luque2011.cerebellum import kernels as k
from cerebx_luque2011.cerebellum.schema import ConductanceLIF, Luque2011Cerebellum

STEP_MS = 2.0
N_JOINTS = 3
N_IO = N_PC = 48
N_DCN = 24
HISTORY = 256  # remembered spikes per input cell (enough for 100 Hz over a 2.5 s kernel span)
DESIRED_TICKS = 4096  # desired states remembered for pairing with delayed measurements (8 s)


def lif_params(cell: ConductanceLIF, dt_ms: float) -> k.LIFConstants:
    return k.LIFConstants(float(cell.capacitance_pF), float(cell.rest_conductance_nS), float(cell.rest_mV),
                          float(cell.threshold_mV), round(cell.refractory_ms / dt_ms),
                          math.exp(-dt_ms / cell.tau_exc_ms), math.exp(-dt_ms / cell.tau_inh_ms), float(cell.e_exc_mV),
                          float(cell.e_inh_mV))


class Luque2011Stage(Stage):
    """Writes the corrective ``joint.torque`` (added to the feed-forward when it is a composite's part)."""

    def __init__(self, cfg: Luque2011Cerebellum, ctx: BuildContext):
        self.cfg = cfg
        n_per = cfg.inputs.cells_per_signal
        self.n_per, self.n_in = n_per, 2 * N_JOINTS * n_per
        lo, hi = cfg.inputs.ranges.bounds(N_JOINTS, ctx.task)
        lo, hi = np.concatenate([lo[:, 0], lo[:, 2]]), np.concatenate([hi[:, 0], hi[:, 2]])  # desired q, qd
        self.centres = np.concatenate([np.linspace(a, b, n_per) for a, b in zip(lo, hi)])
        self.sigma = cfg.inputs.sigma_spacing * (hi - lo) / (n_per - 1)
        self.enc = np.stack([self.centres, np.repeat(0.5 / self.sigma**2, n_per)])
        dt_ms = cfg.substep_ms
        self.kern = k.kernel_table(self.kernel_peak_ms, dt_ms)
        self.p_pc, self.p_dcn = lif_params(cfg.pc, dt_ms), lif_params(cfg.dcn, dt_ms)
        pl, t = cfg.plasticity, cfg.teaching
        self.pars = k.Constants(
            n_sub=round(STEP_MS / dt_ms), dt_ms=float(dt_ms), input_decay=math.exp(-dt_ms / cfg.inputs.tau_ms),
            drive_at_centre=float(cfg.inputs.drive_at_centre), n_per=n_per, w_max_nS=float(pl.weight_max_nS),
            ltp_nS=float(pl.ltp_nS), ltd_nS=float(pl.ltd_nS), learn=bool(pl.enabled), w_dcn_nS=float(cfg.pf_dcn_nS),
            w_inh_nS=float(cfg.pc_dcn_nS), eps_full_scale=float(t.eps_full_scale),
            io_p_max=t.rate_max_hz * STEP_MS / 1000.0)
        self.kp, self.kv = np.asarray(t.kp, float), np.asarray(t.kv, float)
        self.buffer = max(1, int(round(cfg.output.buffer_ms / STEP_MS)))
        self.gain = np.asarray(cfg.output.gain_Nm_per_hz, float)
        self.rng = np.random.default_rng(0)
        self.w = np.full((N_PC, self.n_in), cfg.pf_pc_initial_nS)
        self._allocate()

    def _allocate(self) -> None:
        """Fresh neuron, history and buffer state (the weights are kept), grouped for the kernel in
        ``circuit``."""
        cfg = self.cfg
        self.v_in = np.zeros(self.n_in)
        self.v_pc, self.ge_pc, self.gi_pc = np.full(N_PC, cfg.pc.rest_mV), np.zeros(N_PC), np.zeros(N_PC)
        self.r_pc = np.zeros(N_PC, np.int64)
        self.v_dcn, self.ge_dcn, self.gi_dcn = np.full(N_DCN, cfg.dcn.rest_mV), np.zeros(N_DCN), np.zeros(N_DCN)
        self.r_dcn = np.zeros(N_DCN, np.int64)
        self.hist = np.full((self.n_in, HISTORY), -1, np.int64)
        self.head = np.zeros(self.n_in, np.int64)
        self.clock = np.zeros(3, np.int64)  # sub-step index, tick index, IO spikes since the last trial end
        self.counts = np.zeros((self.buffer, N_DCN), np.int64)  # DCN spikes of the last `buffer` ticks
        self.io_spike = np.zeros(N_IO, np.bool_)
        self.drive = np.zeros(self.n_in)
        self.desired = np.zeros((DESIRED_TICKS, 2 * N_JOINTS))
        self.uniform = np.zeros((0, N_IO))
        self._sensed: Any = None
        self._no_eps = np.full(N_JOINTS, np.nan)
        self.tau = np.zeros(N_JOINTS)
        self.circuit = k.circuit_state(k.Circuit(
            pars=self.pars, clock=self.clock,
            inputs=k.InputCells(self.v_in, self.drive, self.enc, self.hist, self.head),
            pc=k.LIFCells(self.v_pc, self.ge_pc, self.gi_pc, self.r_pc, self.p_pc),
            dcn=k.LIFCells(self.v_dcn, self.ge_dcn, self.gi_dcn, self.r_dcn, self.p_dcn),
            w=self.w, kern=self.kern, io_spike=self.io_spike, counts=self.counts, gain=self.gain))

    def reset(self, rng: np.random.Generator) -> None:
        self._allocate()
        self.rng = rng

    def teaching_error(self, frame: Frame) -> np.ndarray:
        """eps per joint (Eq. 7) for a measurement that arrived this tick; NaN when none did."""
        sensed = frame.sensed
        if sensed is None or sensed is self._sensed:
            return self._no_eps
        self._sensed = sensed
        tick = int(round(sensed.stamp_s * 1000.0 / STEP_MS))
        if tick > frame.tick or frame.tick - tick >= DESIRED_TICKS:
            return self._no_eps
        d = self.desired[tick % DESIRED_TICKS]
        return self.kp * (d[:N_JOINTS] - sensed["joint.q"]) + self.kv * (d[N_JOINTS:] - sensed["joint.qd"])

    def step(self, frame: Frame) -> None:
        s = frame.signals
        x = self.desired[frame.tick % DESIRED_TICKS]
        x[:N_JOINTS], x[N_JOINTS:] = s["ref.q"], s["ref.qd"]
        eps = self.teaching_error(frame)
        row = int(self.clock[1]) % 1024
        if row == 0 or self.uniform.shape[0] == 0:  # IO random numbers, drawn 1024 ticks at a time
            self.uniform = self.rng.random((1024, N_IO))
        self.tau = np.empty(N_JOINTS)
        k.tick(x, eps, self.uniform[row], self.circuit, self.tau)
        self.emit(frame, "joint.torque", self.tau)

    def end_trial(self, trial: int) -> dict[str, float]:
        out = {"w_mean_nS": float(self.w.mean()), "w_min_nS": float(self.w.min()), "w_max_nS": float(self.w.max()),
               "io_spikes": float(self.clock[2])}
        self.clock[2] = 0
        return out

    def save_state(self, path: Path) -> bool:
        save_state_npz(Path(path), {"kind": "luque2011_cerebellum", "n_in": self.n_in}, w=self.w,
                       centres=self.centres)
        return True

    def load_state(self, path: Path) -> None:
        data, meta = load_state_npz(path, "luque2011 cerebellum")
        if meta.get("kind") != "luque2011_cerebellum" or data["w"].shape != self.w.shape:
            raise StateMismatchError(f"{path}: not a luque2011_cerebellum state of {N_PC} x {self.n_in} weights")
        self.w[...] = data["w"]  # in place: ``circuit`` holds this array

    def describe(self) -> dict[str, Any]:
        return {"input_cells": self.n_in, "io": N_IO, "pc": N_PC, "dcn": N_DCN,
                "kernel_peak_ms": self.kernel_peak_ms}

    @property
    def kernel_peak_ms(self) -> float:
        """Where the LTD kernel peaks: the teaching delay plus the arm's own lag."""
        return self.cfg.plasticity.kernel_peak_ms + self.cfg.plasticity.arm_lag_ms
