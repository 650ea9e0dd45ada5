"""``LWPR``: incremental locally weighted projection regression with one sub-model per output.
The numeric work is in ``kernels.py``; this class owns the model buffer and doubles its RF slots when an
output runs out of them. ``update`` and ``predict`` are one kernel call each, for every output at once,
given the buffer's address and the caller's arrays as they are (others are converted once a call fails)."""

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


def _vector(v: Any) -> np.ndarray:
    """A writable C-contiguous float64 copy of v as one row (what the kernels take)."""
    return np.array(v, float).reshape(-1)


def _rows(a: Any, width: int) -> np.ndarray:
    """Samples as writable C-contiguous rows; a 1-D array is one value per sample when width is 1."""
    a = np.require(a, float, ["C", "W"])
    return a.reshape(len(a), -1) if a.ndim > 1 or width != 1 else a[:, None]


def _head(p: LWPRParams, n_in: int, n_out: int) -> np.ndarray:
    """Sizes and hyper-parameters: the first ``N_HP`` values of a model buffer (capacity set by ``_buffer``)."""
    hp = np.zeros(K.N_HP)
    bisquare = p.kernel == "bisquare"
    hp[K.H_N_IN], hp[K.H_N_OUT] = n_in, n_out
    hp[K.HP_W_GEN] = p.w_gen
    hp[K.HP_W_PRUNE] = p.w_prune
    hp[K.HP_INIT_LAMBDA] = p.init_lambda
    hp[K.HP_FINAL_LAMBDA] = p.final_lambda
    hp[K.HP_TAU_LAMBDA] = p.tau_lambda
    hp[K.HP_PENALTY] = p.penalty
    hp[K.HP_DIAG_ONLY] = float(p.diag_only)
    hp[K.HP_UPDATE_D] = float(p.update_D)
    hp[K.HP_ADD_THRESHOLD] = p.add_threshold
    hp[K.HP_INIT_S2] = p.init_S2
    hp[K.HP_BISQUARE] = float(bisquare)
    hp[K.HP_CUTOFF] = p.cutoff
    hp[K.HP_INIT_D] = p.init_D
    hp[K.HP_INIT_ALPHA] = p.init_alpha
    # below these activations no RF is updated, created from or pruned, nor joins a prediction
    hp[K.HP_Q_UPDATE] = K.far_distance(min(0.001, 0.1 * p.w_gen, p.w_prune), bisquare)
    hp[K.HP_Q_PREDICT] = K.far_distance(p.cutoff, bisquare)
    return hp


def _buffer(head: np.ndarray, norm_in: np.ndarray, norm_out: np.ndarray, capacity: int) -> tuple[np.ndarray, K.Store]:
    """A zeroed model buffer holding ``capacity`` RF slots per output, and numpy views of its RF arrays."""
    n_in, n_out = len(norm_in), len(norm_out)
    o_in, o_out, o_count, *_, size = K.regions(n_in, n_out, capacity)
    buf = np.zeros(size)
    buf[: K.N_HP] = head
    buf[K.H_CAPACITY] = capacity
    buf[o_in:o_out], buf[o_out:o_count] = norm_in, norm_out
    return buf, _views(buf, n_in, n_out)


def _views(buf: np.ndarray, n_in: int, n_out: int) -> K.Store:
    """numpy views of the RF arrays of a model buffer."""
    capacity = int(buf[K.H_CAPACITY])
    _, _, o_count, _, _, o_mat, o_vec, o_sca, size = K.regions(n_in, n_out, capacity)
    return K.Store(buf[o_mat:o_vec].reshape(n_out, capacity, K.N_MAT, n_in, n_in),
                   buf[o_vec:o_sca].reshape(n_out, capacity, K.N_VEC, n_in),
                   buf[o_sca:size].reshape(n_out, capacity, K.N_SCA),
                   buf[o_count:o_count + n_out * K.N_COUNT].reshape(n_out, K.N_COUNT))


class LWPR:
    """Locally weighted projection regression (Vijayakumar & Schaal): ``update(x, y)`` trains on one pair and
    returns the prediction of the RFs it updated; ``update_many(X, Y)`` does the same for a whole stream in one
    call; ``predict(x)``, ``predict_many(X)``; ``activations(x)`` per output.

    Parameters
    ----------
    n_in : int
        Input dimensions.
    n_out : int
        Output dimensions (one model per output).
    params : LWPRParams, optional
        The learning parameters (defaults when None).
    **overrides
        Fields of ``LWPRParams`` that replace those of ``params``.
    """

    def __init__(self, n_in: int, n_out: int = 1, params: LWPRParams | None = None, **overrides: Any) -> None:
        if n_in < 1 or n_out < 1:
            raise ValueError("LWPR: n_in and n_out must be >= 1")
        p = params if params is not None else LWPRParams()
        if overrides:
            p = LWPRParams.model_validate({**p.model_dump(), **overrides})
        self.params, self.n_in, self.n_out = p, n_in, n_out
        self.norm_in = _per_dim(p.norm_in, n_in, "norm_in")
        self.norm_out = _per_dim(p.norm_out, n_out, "norm_out")
        self._update = K.entry_point("update", n_in, n_out)
        self._predict = K.entry_point("predict", n_in, n_out)
        self._head = _head(p, n_in, n_out)
        self._use(*_buffer(self._head, self.norm_in, self.norm_out, p.initial_capacity))
        self._no_act = np.empty((n_out, 0))

    def _use(self, buf: np.ndarray, store: K.Store) -> None:
        """Make ``buf`` the model's buffer: the kernels get its address, ``update`` and ``predict`` return
        copies of its pred."""
        self._buf, self._store, self._addr = buf, store, buf.ctypes.data
        self._pred = buf[K.regions(self.n_in, self.n_out, 0)[3]:][: self.n_out]

    def _kernel(self, name: str) -> Any:
        return K.entry_point(name, self.n_in, self.n_out)

    def __getstate__(self) -> dict[str, Any]:
        """Pickled (checkpoints) without what points into the buffer or at compiled code: the address, the
        views (a pickle would hold them as copies) and the kernels."""
        state = self.__dict__.copy()
        for name in ("_store", "_addr", "_pred", "_update", "_predict"):
            state.pop(name, None)
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        """A state of :meth:`__getstate__`, or the pickled ``__dict__`` of earlier code, whose buffer had no
        pred region: its RF arrays (``_store``) then go into a buffer of today's layout."""
        old = state.pop("_store", None)  # only earlier code pickled it
        self.__dict__.update(state)
        self._update = K.entry_point("update", self.n_in, self.n_out)
        self._predict = K.entry_point("predict", self.n_in, self.n_out)
        if old is None:
            self._use(self._buf, _views(self._buf, self.n_in, self.n_out))
            return
        self._use(*_buffer(self._head, self.norm_in, self.norm_out, old.mat.shape[1]))
        for a, b in zip(old, self._store):
            b[:] = a

    def _grow(self) -> None:
        """Move the model to a buffer with twice the RF slots per output."""
        old = self._store
        self._use(*_buffer(self._head, self.norm_in, self.norm_out, 2 * old.mat.shape[1]))
        for a, b in zip(old, self._store):
            b[:, : a.shape[1]] = a

    def _check(self, status: int, x: np.ndarray, y: np.ndarray | None = None) -> None:
        if status == K.BAD_X:
            raise ValueError(f"LWPR: input needs {self.n_in} values, got {x.shape[0]}")
        if status == K.BAD_Y and y is not None:
            raise ValueError(f"LWPR: target needs {self.n_out} values, got {y.shape[0]}")

    def update(self, x: Any, y: Any) -> np.ndarray:
        """Train on one pair; returns the prediction at x of the RFs this pair updated (trustworthy ones)."""
        try:
            status = self._update(self._addr, x, y)
        except TypeError:  # not both float64 C-contiguous writable 1-D arrays
            x, y = _vector(x), _vector(y)
            status = self._update(self._addr, x, y)
        if status:
            self._retry(status, x, y)
        return self._pred.copy()

    def _retry(self, status: int, x: np.ndarray, y: np.ndarray) -> None:
        """After ``update`` returned ``status``: grow the buffer until the pair fits, or raise for bad input."""
        while status == K.FULL:
            self._grow()
            status = self._update(self._addr, x, y)
        if status:
            self._check(status, _vector(x), _vector(y))

    def update_many(self, X: Any, Y: Any) -> np.ndarray:
        """Train on the rows of X and Y in order (as ``update`` row by row, in one kernel call); returns
        the (rows, n_out) predictions ``update`` would have returned."""
        X, Y = _rows(X, self.n_in), _rows(Y, self.n_out)
        if len(Y) != len(X):
            raise ValueError(f"LWPR: {len(X)} inputs but {len(Y)} targets")
        if X.shape[1] != self.n_in:
            self._check(K.BAD_X, X[0])
        if Y.shape[1] != self.n_out:
            self._check(K.BAD_Y, X[0], Y[0])
        out = np.empty((len(X), self.n_out))
        t, update_many = 0, self._kernel("update_many")
        while t < len(X):
            t = update_many(self._addr, X, Y, out, t)
            if t < len(X):
                self._grow()
        return out

    def predict(self, x: Any) -> np.ndarray:
        """Weighted prediction of the trustworthy RFs above the activation cutoff, per output."""
        try:
            status = self._predict(self._addr, x)
        except TypeError:  # not a float64 C-contiguous writable 1-D array
            status = self._predict(self._addr, _vector(x))
        if status:
            self._check(K.BAD_X, _vector(x))
        return self._pred.copy()

    def predict_many(self, X: Any) -> np.ndarray:
        """``predict`` at every row of X: (rows, n_out)."""
        X = _rows(X, self.n_in)
        if X.shape[1] != self.n_in:
            self._check(K.BAD_X, X[0])
        out = np.empty((len(X), self.n_out))
        self._kernel("predict_many")(self._addr, X, out, self._no_act)
        return out

    def predict_with_activations(self, x: Any) -> tuple[np.ndarray, list[np.ndarray]]:
        """Prediction and, per output, the activation of every RF that took part (0 for the others)."""
        x = _vector(x)
        if x.shape[0] != self.n_in:
            self._check(K.BAD_X, x)
        out = np.empty((1, self.n_out))
        act = np.zeros((self.n_out, max(1, int(self._store.count[:, K.N_RF].max()))))
        self._kernel("predict_many")(self._addr, x[None], out, act)
        return out[0], [act[d, :n] for d, n in enumerate(self.n_receptive_fields)]

    def activations(self, x: Any) -> list[np.ndarray]:
        """Kernel weight of every RF at x, per output (trustworthy or not)."""
        x = _vector(x)
        if x.shape[0] != self.n_in:
            self._check(K.BAD_X, x)
        act = np.zeros((self.n_out, max(1, int(self._store.count[:, K.N_RF].max()))))
        self._kernel("activations")(self._addr, x, act)
        return [act[d, :n] for d, n in enumerate(self.n_receptive_fields)]

    @property
    def n_receptive_fields(self) -> list[int]:
        """RFs per output dimension."""
        return [int(n) for n in self._store.count[:, K.N_RF]]

    @property
    def n_created(self) -> list[int]:
        """RFs created so far per output dimension (pruned ones included)."""
        return [int(n) for n in self._store.count[:, K.N_CREATED]]

    @property
    def n_updates(self) -> int:
        """Training pairs seen since construction."""
        return int(self._store.count[0, K.N_SEEN])

    def state(self) -> dict[str, np.ndarray]:
        """The learned arrays (for saving); :meth:`load` restores them."""
        st, out = self._store, {}
        for d, n in enumerate(self.n_receptive_fields):
            out.update({f"lwpr{d}_mat": st.mat[d, :n].copy(), f"lwpr{d}_vec": st.vec[d, :n].copy(),
                        f"lwpr{d}_sca": st.sca[d, :n].copy(),
                        f"lwpr{d}_counts": st.count[d, [K.N_CREATED, K.N_PRUNED]].astype(np.int64)})
        return out

    def load(self, state: dict[str, np.ndarray]) -> None:
        mats = [np.asarray(state[f"lwpr{d}_mat"]) for d in range(self.n_out)]
        for mat in mats:
            if mat.shape[1:] != self._store.mat.shape[2:]:
                raise ValueError(f"LWPR state: {mat.shape[2]} inputs saved, this model has {self.n_in}")
        capacity = max(self.params.initial_capacity, 2 * max(len(m) for m in mats))
        buf, st = _buffer(self._head, self.norm_in, self.norm_out, capacity)
        for d, mat in enumerate(mats):
            n = len(mat)
            st.mat[d, :n], st.vec[d, :n], st.sca[d, :n] = mat, state[f"lwpr{d}_vec"], state[f"lwpr{d}_sca"]
            st.count[d, K.N_RF] = n
            st.count[d, [K.N_CREATED, K.N_PRUNED]] = state[f"lwpr{d}_counts"]
        self._use(buf, st)

    def distance_metric(self, out: int, rf: int) -> np.ndarray:
        """D of RF ``rf`` of output ``out`` (in normalised input units)."""
        n = self.n_receptive_fields[out]
        if not 0 <= rf < n:
            raise IndexError(f"LWPR: output {out} has {n} RFs, no RF {rf}")
        return self._store.mat[out, rf, K.D_].copy()

    def centres(self, out: int = 0) -> np.ndarray:
        return self._store.vec[out, : self.n_receptive_fields[out], K.C_].copy() * self.norm_in
