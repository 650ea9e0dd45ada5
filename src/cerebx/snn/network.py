"""A built spiking network with its state, advanced one 2 ms control step per call."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numba
import numpy as np

from cerebx.schema.network import NetworkConfig
from cerebx.snn import kernels
from cerebx.snn.topology import build_topology, structure_fingerprint

PF_RING = 1 << 16  # buffered PF arrivals per plastic projection (must cover the kernel window)


@dataclass(frozen=True)
class StepSpikes:
    """Spikes of one control step: global neuron index and time in substeps from the step start
    (1..n_sub: the spike happened at the end of that substep)."""

    idx: np.ndarray
    sub: np.ndarray


class Network:
    """Flat-array spiking network (see :mod:`cerebx.snn.kernels` for the numerics)."""

    STATE_KEYS = ("V", "g", "ref", "ring_idx", "ring_n", "pf_t", "pf_j", "pf_head", "pf_lost", "dense_w")

    def __init__(self, cfg: NetworkConfig, parallel: bool = True, pf_ring: int = PF_RING):
        t_start = time.perf_counter()
        self.cfg = cfg
        self.parallel = parallel
        self.topo = topo = build_topology(cfg)
        self.n_sub = topo.n_sub
        self.fingerprint = structure_fingerprint(cfg)
        n = topo.n_neurons
        self.V = np.zeros(n, dtype=np.float32)
        self.g = np.zeros((3, n), dtype=np.float32)
        self.ref = np.zeros(n, dtype=np.float32)
        self.flag = np.zeros(n, dtype=np.uint8)
        R = topo.max_delay + 2
        self.ring_idx = np.zeros((R, n), dtype=np.int32)
        self.ring_n = np.zeros(R, dtype=np.int64)

        self.pop_lo, self.pop_hi, self.pop_kind = topo.lo, topo.hi, topo.kind
        self.pop_par = topo.par
        sp = topo.sparse
        ptr_parts, off = [], 0
        sp_i = np.zeros((len(sp), 6), dtype=np.int64)
        syn_base = 0
        for k, s in enumerate(sp):
            sp_i[k] = (s.pre_lo, s.n_pre, off, s.receptor, s.delay, int(s.teaching))
            ptr_parts.append(s.ptr + syn_base)
            off += len(s.ptr)
            syn_base += len(s.post)
        self.sp_i = sp_i
        self.sp_ptr = np.concatenate(ptr_parts) if sp else np.zeros(1, np.int64)
        self.sp_post = np.concatenate([s.post for s in sp]) if sp else np.zeros(0, np.int32)
        self.sp_w = np.concatenate([s.w for s in sp]) if sp else np.zeros(0, np.float32)
        self.de_i = np.array(
            [(d.pre_lo, d.n_pre, d.post_lo, d.n_post, d.w_off, d.receptor, d.delay, d.plastic)
             for d in topo.dense], dtype=np.int64).reshape(-1, 8)
        self.dense_w = topo.dense_w
        pl = topo.plastic
        k_off = np.cumsum([0] + [len(r.kernel) for r in pl])
        self.pl_i = np.array([(r.dense, r.teacher, k_off[i], len(r.kernel)) for i, r in enumerate(pl)],
                             dtype=np.int64).reshape(-1, 4)
        self.pl_f = np.array([(r.ltp, r.ltd, r.w_lo, r.w_hi) for r in pl], dtype=np.float64).reshape(-1, 4)
        self.kern = np.concatenate([r.kernel for r in pl]) if pl else np.zeros(1, np.float32)
        longest = max([len(r.kernel) for r in pl] + [1])
        self.pf_t = np.zeros((len(pl), pf_ring), dtype=np.int64)
        self.pf_j = np.zeros((len(pl), pf_ring), dtype=np.int32)
        self.pf_head = np.zeros(len(pl), dtype=np.int64)
        self.pf_lost = np.zeros(len(pl), dtype=np.int64)
        self.kernel_window_sub = longest
        self.col_buf = np.zeros(n, dtype=np.int64)
        self.out_idx = np.zeros(n * self.n_sub, dtype=np.int32)
        self.out_t = np.zeros(n * self.n_sub, dtype=np.int32)
        self.learn = True
        self.t_sub = 0
        self.reset_state()
        self.build_s = time.perf_counter() - t_start

    # ------------------------------------------------------------------ state
    def reset_state(self) -> None:
        """Neurons at rest, no conductances, nothing in flight; weights are kept."""
        for pi in range(len(self.topo.names)):
            self.V[self.pop_lo[pi] : self.pop_hi[pi]] = self.pop_par[pi, 2]
        self.g[:] = 0
        self.ref[:] = 0
        self.ring_n[:] = 0
        self.pf_head[:] = 0
        self.pf_lost[:] = 0
        self.t_sub = 0

    def state_arrays(self) -> dict[str, np.ndarray]:
        d = {k: getattr(self, k) for k in self.STATE_KEYS}
        d["t_sub"] = np.array(self.t_sub, dtype=np.int64)
        return d

    def load_arrays(self, arrays: dict[str, np.ndarray]) -> None:
        for k in self.STATE_KEYS:
            dst = getattr(self, k)
            src = arrays[k]
            if src.shape != dst.shape or src.dtype != dst.dtype:
                raise ValueError(f"state array {k}: saved {src.shape} {src.dtype}, "
                                 f"network needs {dst.shape} {dst.dtype}")
            dst[...] = src
        self.t_sub = int(arrays["t_sub"])

    # ------------------------------------------------------------------ access
    def index(self, pop: str) -> slice:
        return self.topo.slice(pop)

    def weights(self, projection: str) -> np.ndarray:
        """Weights of an all-to-all projection as a [n_pre, n_post] view (float32, nS)."""
        for d in self.topo.dense:
            if d.name == projection:
                return self.topo.dense_block(d)
        raise KeyError(f"{projection!r} is not an all-to-all projection")

    @property
    def plastic_projections(self) -> list[str]:
        return [r.proj for r in self.topo.plastic]

    @property
    def n_neurons(self) -> int:
        return self.cfg.n_neurons

    @property
    def n_synapses(self) -> int:
        return self.cfg.n_synapses

    @property
    def n_plastic(self) -> int:
        return self.cfg.n_plastic

    # ------------------------------------------------------------------ run
    def step(self, inputs: np.ndarray) -> StepSpikes:
        """One 2 ms step; ``inputs`` are global indices of input fibres spiking at its start
        (each fibre at most once)."""
        inputs = np.ascontiguousarray(inputs, dtype=np.int32)
        prev = None
        if not self.parallel:
            prev = numba.get_num_threads()
            numba.set_num_threads(1)
        try:
            n = kernels.run_step(
                self.t_sub, self.n_sub, inputs, self.learn, self.V, self.g, self.ref, self.flag,
                self.pop_lo, self.pop_hi, self.pop_kind, self.pop_par,
                self.ring_idx, self.ring_n, self.sp_i, self.sp_ptr, self.sp_post, self.sp_w,
                self.de_i, self.dense_w, self.pl_i, self.pl_f, self.kern, self.pf_t, self.pf_j,
                self.pf_head, self.pf_lost, self.col_buf, self.out_idx, self.out_t,
            )
        finally:
            if prev is not None:
                numba.set_num_threads(prev)
        self.t_sub += self.n_sub
        return StepSpikes(self.out_idx[:n], self.out_t[:n])
