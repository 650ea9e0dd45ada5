"""One modular cerebellar circuit (MCC) of Capolei et al. (2020), Section II-D.

Per joint n (an *ulm*) and microcircuit m (M = 2: m = 0 fed by the position error, m = 1 by the
velocity error), one update with mossy-fibre input MF, teaching signal x (the efference copy:
tau^tot for the inverse model, qdot for the forward one) and errors e_{n,m}:

- granular layer: LWPR trained on (MF, x); its prediction is the PF signal x^pf_n (Eq. 9);
- IO: io = sat(e / io_range) in [-1, 1];
- PF-PC (Eq. 12):   dw = LTP / (|io| + 1)^a - LTD |io|;                 x^pc = w x^pf
- PC-DCN (Eq. 13):  dw = LTP |pc|^a (1 - 1 / (1 + |dcn|)^a) - LTD (1 - |pc|);  x^pc-dcn = w pc
  with pc = sat(x^pc / signal_range) and dcn the previous output, both in [-1, 1];
- MF-DCN (Eq. 14):  dw = LTP / (|pc| + 1)^a - LTD |pc|;                 x^mf-dcn = w x
- IO-DCN (Eq. 15):  dw = MTP |io| - MTD / (|io| + 1)^a;                 x^io-dcn = w io
- DCN (Eq. 16-17):  dcn = k(-k(sum_m x^pc-dcn) + k(sum_m x^mf-dcn) + k(sum_m x^io-dcn)),
  k(y) = 2 / (1 + e^(-2y)) - 1.

The rule forms are those of the authors' released cerebellum (HBP_SGA2_C2942, cerebellum_C2942.py),
which cites Luque et al. 2014 (PC-DCN) and Garrido et al. 2013; the paper gives only their
parameters (Table I). Weights start at 0; with ``learn`` false nothing plastic changes.
"""

from __future__ import annotations

import numpy as np

from cerebx.api import LWPR
from cerebx_capolei2020.modules.schema import CerebellarModule, SynapseKernel


def k(y: np.ndarray | float) -> np.ndarray:
    """Eq. 17: k(y) = 2 / (1 + e^(-2y)) - 1 (= tanh y)."""
    return 2.0 / (1.0 + np.exp(-2.0 * np.asarray(y, float))) - 1.0


def _kernel(s: SynapseKernel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return np.asarray(s.ltp, float), np.asarray(s.ltd, float), np.asarray(s.alpha, float)


class ModularCerebellarCircuit:
    """N ulms x M = 2 microcircuits sharing one LWPR granular layer with 2N inputs and N outputs."""

    M = 2

    def __init__(self, cfg: CerebellarModule):
        n = cfg.n_joints
        self.cfg, self.n = cfg, n
        self.granular = LWPR(2 * n, n, cfg.granular)
        self.pf_pc, self.pc_dcn = _kernel(cfg.pf_pc), _kernel(cfg.pc_dcn)
        self.mf_dcn, self.io_dcn = _kernel(cfg.mf_dcn), _kernel(cfg.io_dcn)
        self.io_range = np.asarray(cfg.io_range, float)
        self.signal_range = np.asarray(cfg.signal_range, float)[:, None]
        self.w_pf_pc = np.zeros((n, self.M))
        self.w_pc_dcn = np.zeros((n, self.M))
        self.w_mf_dcn = np.zeros((n, self.M))
        self.w_io_dcn = np.zeros((n, self.M))
        self.dcn = np.zeros(n)
        self.x_pf = np.zeros(n)

    def step(self, mf: np.ndarray, x: np.ndarray, errors: np.ndarray, learn: bool,
             mf_train: np.ndarray | None = None) -> np.ndarray:
        """One update. ``errors`` is (N, 2): [position, velocity] error per joint; the LWPR learns x at
        ``mf_train`` (default ``mf``) and predicts at ``mf``. Returns the DCN output (N values in -1..1)."""
        if learn:
            self.granular.update(mf if mf_train is None else mf_train, x)
        self.x_pf = self.granular.predict(mf)
        io = np.clip(errors / self.io_range, -1.0, 1.0)
        aio = np.abs(io)
        if learn:
            ltp, ltd, a = self.pf_pc
            self.w_pf_pc += ltp / (aio + 1.0) ** a - ltd * aio
        pc = np.clip(self.w_pf_pc * self.x_pf[:, None] / self.signal_range, -1.0, 1.0)
        apc = np.abs(pc)
        if learn:
            ltp, ltd, a = self.pc_dcn
            adcn = np.abs(np.clip(self.dcn[:, None] / self.signal_range, -1.0, 1.0))
            self.w_pc_dcn += ltp * apc ** a * (1.0 - 1.0 / (1.0 + adcn) ** a) - ltd * (1.0 - apc)
            ltp, ltd, a = self.mf_dcn
            self.w_mf_dcn += ltp / (apc + 1.0) ** a - ltd * apc
            ltp, ltd, a = self.io_dcn
            self.w_io_dcn += ltp * aio - ltd / (aio + 1.0) ** a
        x_pc_dcn = (self.w_pc_dcn * pc).sum(1)
        x_mf_dcn = (self.w_mf_dcn * np.asarray(x, float)[:, None]).sum(1)
        x_io_dcn = (self.w_io_dcn * io).sum(1)
        self.dcn = k(-k(x_pc_dcn) + k(x_mf_dcn) + k(x_io_dcn))
        return self.dcn

    def state(self) -> dict[str, np.ndarray]:
        return {"w_pf_pc": self.w_pf_pc, "w_pc_dcn": self.w_pc_dcn, "w_mf_dcn": self.w_mf_dcn,
                "w_io_dcn": self.w_io_dcn, "dcn": self.dcn, **self.granular.state()}

    def load(self, state: dict[str, np.ndarray]) -> None:
        for name in ("w_pf_pc", "w_pc_dcn", "w_mf_dcn", "w_io_dcn", "dcn"):
            got, want = np.asarray(state[name]), getattr(self, name).shape
            if got.shape != want:
                raise ValueError(f"cerebellar state: {name} has shape {got.shape}, expected {want}")
            setattr(self, name, got.copy())
        self.granular.load(state)

    def summary(self) -> dict[str, float]:
        out = {f"rf_j{j + 1}": float(c) for j, c in enumerate(self.granular.n_created)}
        out["rf_created"] = float(sum(self.granular.n_created))
        for name in ("w_pf_pc", "w_pc_dcn", "w_mf_dcn", "w_io_dcn"):
            out[f"{name}_mean"] = float(getattr(self, name).mean())
        return out
