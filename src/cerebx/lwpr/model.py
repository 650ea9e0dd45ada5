"""``LWPR``: incremental locally weighted projection regression with one sub-model per output.
The numeric work is in ``kernels.py``; this class owns the flat arrays and grows them by doubling."""

from __future__ import annotations

from typing import Any

import numpy as np

from cerebx.lwpr import kernels as K
from cerebx.lwpr.schema import LWPRParams


def _per_dim(value: float | tuple[float, ...], n: int, name: str) -> np.ndarray:
    arr = np.full(n, value, float) if np.isscalar(value) else np.asarray(value, float)
    if arr.shape != (n,):
        raise ValueError(f"{name}: needs 1 or {n} values, got {arr.size}")
    return arr


class _SubModel:
    """The receptive fields of one output dimension."""

    def __init__(self, n_in: int, capacity: int) -> None:
        self.mat = np.zeros((capacity, K.N_MAT, n_in, n_in))
        self.vec = np.zeros((capacity, K.N_VEC, n_in))
        self.sca = np.zeros((capacity, K.N_SCA))
        self.n_rf = 0
        self.n_created = 0
        self.n_pruned = 0

    def ensure_free_slot(self) -> None:
        if self.n_rf < self.mat.shape[0]:
            return
        cap = 2 * self.mat.shape[0]
        for name in ("mat", "vec", "sca"):
            old = getattr(self, name)
            new = np.zeros((cap, *old.shape[1:]))
            new[: old.shape[0]] = old
            setattr(self, name, new)


class LWPR:
    """``LWPR(n_in, n_out, **params)``; ``update(x, y)`` trains on one pair and returns the prediction
    made before this pair changed the model; ``predict(x)``; ``activations(x)`` per output."""

    def __init__(self, n_in: int, n_out: int = 1, params: LWPRParams | None = None, **overrides: Any) -> None:
        if n_in < 1 or n_out < 1:
            raise ValueError("LWPR: n_in and n_out must be >= 1")
        p = params if params is not None else LWPRParams()
        if overrides:
            p = LWPRParams.model_validate({**p.model_dump(), **overrides})
        self.params, self.n_in, self.n_out = p, n_in, n_out
        self.norm_in = _per_dim(p.norm_in, n_in, "norm_in")
        self.norm_out = _per_dim(p.norm_out, n_out, "norm_out")
        self.init_D = p.init_D * np.eye(n_in)
        self.init_M = np.sqrt(p.init_D) * np.eye(n_in)
        self.init_alpha = np.full((n_in, n_in), p.init_alpha)
        self.hp = np.zeros(K.N_HP)
        self.hp[K.HP_W_GEN] = p.w_gen
        self.hp[K.HP_W_PRUNE] = p.w_prune
        self.hp[K.HP_INIT_LAMBDA] = p.init_lambda
        self.hp[K.HP_FINAL_LAMBDA] = p.final_lambda
        self.hp[K.HP_TAU_LAMBDA] = p.tau_lambda
        self.hp[K.HP_PENALTY] = p.penalty
        self.hp[K.HP_DIAG_ONLY] = float(p.diag_only)
        self.hp[K.HP_UPDATE_D] = float(p.update_D)
        self.hp[K.HP_ADD_THRESHOLD] = p.add_threshold
        self.hp[K.HP_INIT_S2] = p.init_S2
        self.hp[K.HP_BISQUARE] = float(p.kernel == "bisquare")
        self.hp[K.HP_CUTOFF] = p.cutoff
        self.subs = [_SubModel(n_in, p.initial_capacity) for _ in range(n_out)]
        self.n_updates = 0

    def _x(self, x: Any) -> np.ndarray:
        xa = np.asarray(x, float).reshape(-1)
        if xa.shape[0] != self.n_in:
            raise ValueError(f"LWPR: input needs {self.n_in} values, got {xa.shape[0]}")
        return xa / self.norm_in

    def update(self, x: Any, y: Any) -> np.ndarray:
        xn = self._x(x)
        yn = np.asarray(y, float).reshape(-1) / self.norm_out
        if yn.shape[0] != self.n_out:
            raise ValueError(f"LWPR: target needs {self.n_out} values, got {yn.shape[0]}")
        out = np.empty(self.n_out)
        for d, sub in enumerate(self.subs):
            sub.ensure_free_slot()
            before = sub.n_rf
            out[d], sub.n_rf, _ = K.update(sub.mat, sub.vec, sub.sca, sub.n_rf, xn, yn[d],
                                           self.init_M, self.init_D, self.init_alpha, self.hp)
            sub.n_created += sub.n_rf > before
            sub.n_pruned += sub.n_rf < before
        self.n_updates += 1
        return out * self.norm_out

    def predict(self, x: Any) -> np.ndarray:
        return self.predict_with_activations(x)[0]

    def predict_with_activations(self, x: Any) -> tuple[np.ndarray, list[np.ndarray]]:
        """Prediction and, per output, the activation of every RF that took part (0 for the others)."""
        xn = self._x(x)
        out = np.empty(self.n_out)
        acts = []
        bisquare = bool(self.hp[K.HP_BISQUARE])
        for d, sub in enumerate(self.subs):
            act = np.empty(sub.n_rf)
            out[d] = K.predict(sub.mat, sub.vec, sub.sca, sub.n_rf, xn, self.params.cutoff, bisquare, act)
            acts.append(act)
        return out * self.norm_out, acts

    def activations(self, x: Any) -> list[np.ndarray]:
        """Kernel weight of every RF at x, per output (trustworthy or not)."""
        xn = self._x(x)
        acts = []
        for sub in self.subs:
            act = np.empty(sub.n_rf)
            K.activations(sub.mat, sub.vec, sub.n_rf, xn, bool(self.hp[K.HP_BISQUARE]), act)
            acts.append(act)
        return acts

    @property
    def n_receptive_fields(self) -> list[int]:
        """RFs per output dimension."""
        return [sub.n_rf for sub in self.subs]

    @property
    def n_created(self) -> list[int]:
        """RFs created so far per output dimension (pruned ones included)."""
        return [sub.n_created for sub in self.subs]

    def state(self) -> dict[str, np.ndarray]:
        """The learned arrays (for saving); :meth:`load` restores them."""
        out: dict[str, np.ndarray] = {}
        for d, sub in enumerate(self.subs):
            n = sub.n_rf
            out.update({f"lwpr{d}_mat": sub.mat[:n], f"lwpr{d}_vec": sub.vec[:n], f"lwpr{d}_sca": sub.sca[:n],
                        f"lwpr{d}_counts": np.array([sub.n_created, sub.n_pruned])})
        return out

    def load(self, state: dict[str, np.ndarray]) -> None:
        for d, sub in enumerate(self.subs):
            mat = state[f"lwpr{d}_mat"]
            if mat.shape[1:] != sub.mat.shape[1:]:
                raise ValueError(f"LWPR state: {mat.shape[2]} inputs saved, this model has {self.n_in}")
            n = mat.shape[0]
            cap = max(self.params.initial_capacity, 2 * n)
            sub.mat, sub.vec, sub.sca = (np.zeros((cap, *a.shape[1:])) for a in (sub.mat, sub.vec, sub.sca))
            sub.mat[:n], sub.vec[:n], sub.sca[:n] = mat, state[f"lwpr{d}_vec"], state[f"lwpr{d}_sca"]
            sub.n_rf = n
            sub.n_created, sub.n_pruned = (int(v) for v in state[f"lwpr{d}_counts"])

    def distance_metric(self, out: int, rf: int) -> np.ndarray:
        """D of RF ``rf`` of output ``out`` (in normalised input units)."""
        sub = self.subs[out]
        if not 0 <= rf < sub.n_rf:
            raise IndexError(f"LWPR: output {out} has {sub.n_rf} RFs, no RF {rf}")
        return sub.mat[rf, K.D_].copy()

    def centres(self, out: int = 0) -> np.ndarray:
        sub = self.subs[out]
        return sub.vec[: sub.n_rf, K.C_].copy() * self.norm_in
