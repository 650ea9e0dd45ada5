"""Statistics of a projection's weights for ``/weights`` (mean, std, min, max), equal bit for bit to numpy's.

``np.std(w, dtype=float64)`` of the 36 M PF-PC weights builds a 288 MB float64 temporary (``w - mean``) and
squares and sums it: about 0.7 s of CPU a call, most of it page faults. :func:`std_f64` gives the same
double in one pass without a temporary: numpy sums that contiguous float64 array pairwise (blocks of 8
partial sums up to 128 values, halves split at multiples of 8 above), and the pass below performs the
same additions in the same order on ``(float64(w[i]) - mean)**2`` computed on the fly
(``tests/cerebx/snn/test_weight_stats.py`` checks the equality over sizes around every branch).
"""

from __future__ import annotations

import numpy as np
from numba import njit

_BLOCK = 128  # numpy's PW_BLOCKSIZE


@njit(cache=True, boundscheck=False)
def _sq_dev_sum(w, lo, n, mean):
    """numpy's pairwise sum of ``(float64(w[i]) - mean)**2`` over ``w[lo:lo + n]``."""
    if n < 8:
        res = -0.0
        for i in range(lo, lo + n):
            d = np.float64(w[i]) - mean
            res += d * d
        return res
    if n <= _BLOCK:
        d = np.float64(w[lo]) - mean
        r0 = d * d
        d = np.float64(w[lo + 1]) - mean
        r1 = d * d
        d = np.float64(w[lo + 2]) - mean
        r2 = d * d
        d = np.float64(w[lo + 3]) - mean
        r3 = d * d
        d = np.float64(w[lo + 4]) - mean
        r4 = d * d
        d = np.float64(w[lo + 5]) - mean
        r5 = d * d
        d = np.float64(w[lo + 6]) - mean
        r6 = d * d
        d = np.float64(w[lo + 7]) - mean
        r7 = d * d
        end = lo + n - n % 8
        i = lo + 8
        while i < end:
            d = np.float64(w[i]) - mean
            r0 += d * d
            d = np.float64(w[i + 1]) - mean
            r1 += d * d
            d = np.float64(w[i + 2]) - mean
            r2 += d * d
            d = np.float64(w[i + 3]) - mean
            r3 += d * d
            d = np.float64(w[i + 4]) - mean
            r4 += d * d
            d = np.float64(w[i + 5]) - mean
            r5 += d * d
            d = np.float64(w[i + 6]) - mean
            r6 += d * d
            d = np.float64(w[i + 7]) - mean
            r7 += d * d
            i += 8
        res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        while i < lo + n:
            d = np.float64(w[i]) - mean
            res += d * d
            i += 1
        return res
    n2 = n // 2
    n2 -= n2 % 8
    return _sq_dev_sum(w, lo, n2, mean) + _sq_dev_sum(w, lo + n2, n - n2, mean)


def std_f64(w: np.ndarray, mean: float) -> float:
    """``np.std(w, dtype=np.float64)`` (``mean``: ``w.mean(dtype=np.float64)``), without the temporary."""
    flat = np.ascontiguousarray(w).reshape(-1)
    return float(np.sqrt(_sq_dev_sum(flat, 0, flat.size, np.float64(mean)) / flat.size))


def weight_stats(w: np.ndarray) -> tuple[float, float, float, float]:
    """(mean, std, min, max) of ``w`` as ``w.mean(dtype=float64)``, ``w.std(dtype=float64)``, ``w.min()``,
    ``w.max()`` give them."""
    mean = w.mean(dtype=np.float64)
    return float(mean), std_f64(w, mean), float(w.min()), float(w.max())
