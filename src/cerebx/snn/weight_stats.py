"""Statistics of a projection's weights for ``/weights`` (mean, std, min, max), equal bit for bit to numpy's.

``np.std(w, dtype=float64)`` of the 36 M PF-PC weights builds a 288 MB float64 temporary (``w - mean``) and
squares and sums it: about 0.7 s of CPU a call, most of it page faults. :func:`std_f64` gives the same
double in one pass without a temporary: numpy sums that contiguous float64 array pairwise (blocks of 8
partial sums up to 128 values, halves split at multiples of 8 above), and the pass below performs the
same additions in the same order on ``(float64(w[i]) - mean)**2`` computed on the fly
(``tests/cerebx/snn/test_weight_stats.py`` checks the equality over sizes around every branch).

:func:`weight_stats` reads the weights twice where numpy's mean, std, min and max read them four times:
:func:`_sum_min_max` gives the mean's sum, the min and the max in one pass, :func:`std_f64` the rest. Both
passes can be split between two threads (the runs' sums are kept and added in order afterwards; the pairwise
sum's first split is numpy's too).
``w.mean(dtype=float64)`` of float32 data is a buffered cast reduction: numpy casts ``np.getbufsize()``
(8192) elements at a time into a float64 buffer, sums each buffer pairwise as above and adds the buffer
sums in order to a result that starts at the identity 0.0 (not at the first element). A C-contiguous
array, 2-D included, is iterated as one flat run, so the buffers are consecutive runs of the flat array,
and :func:`_sum_min_max` sums the same runs the same way. Checked against numpy 2.4: runs of another
length, or shifted by one element, change the last bits, so the tests use data whose sums round. Other
layouts and dtypes keep numpy's reductions.

The kernels index 0-based slices (``c = w[lo:hi]``, ``c[i]``): with an index numba cannot prove
non-negative, every access carries the negative-index wraparound, which costs the pairwise sums 7-17 % and
turns the vector loads of the min/max scan into gathers.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numba import njit

_BLOCK = 128  # numpy's PW_BLOCKSIZE


@njit(cache=True, nogil=True, boundscheck=False)
def _sum(c):
    """numpy's pairwise sum of ``float64(c[i])`` (the additions of :func:`_sq_dev_sum`)."""
    n = c.size
    if n < 8:
        res = -0.0
        for i in range(n):
            res += np.float64(c[i])
        return res
    if n <= _BLOCK:
        r0 = np.float64(c[0])
        r1 = np.float64(c[1])
        r2 = np.float64(c[2])
        r3 = np.float64(c[3])
        r4 = np.float64(c[4])
        r5 = np.float64(c[5])
        r6 = np.float64(c[6])
        r7 = np.float64(c[7])
        m = n - n % 8
        for i in range(8, m, 8):
            r0 += np.float64(c[i])
            r1 += np.float64(c[i + 1])
            r2 += np.float64(c[i + 2])
            r3 += np.float64(c[i + 3])
            r4 += np.float64(c[i + 4])
            r5 += np.float64(c[i + 5])
            r6 += np.float64(c[i + 6])
            r7 += np.float64(c[i + 7])
        res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        for i in range(m, n):
            res += np.float64(c[i])
        return res
    n2 = n // 2
    n2 -= n2 % 8
    return _sum(c[:n2]) + _sum(c[n2:])


@njit(cache=True, nogil=True, boundscheck=False)
def _sq_dev_sum(c, mean):
    """numpy's pairwise sum of ``(float64(c[i]) - mean)**2``."""
    n = c.size
    if n < 8:
        res = -0.0
        for i in range(n):
            d = np.float64(c[i]) - mean
            res += d * d
        return res
    if n <= _BLOCK:
        d = np.float64(c[0]) - mean
        r0 = d * d
        d = np.float64(c[1]) - mean
        r1 = d * d
        d = np.float64(c[2]) - mean
        r2 = d * d
        d = np.float64(c[3]) - mean
        r3 = d * d
        d = np.float64(c[4]) - mean
        r4 = d * d
        d = np.float64(c[5]) - mean
        r5 = d * d
        d = np.float64(c[6]) - mean
        r6 = d * d
        d = np.float64(c[7]) - mean
        r7 = d * d
        m = n - n % 8
        for i in range(8, m, 8):
            d = np.float64(c[i]) - mean
            r0 += d * d
            d = np.float64(c[i + 1]) - mean
            r1 += d * d
            d = np.float64(c[i + 2]) - mean
            r2 += d * d
            d = np.float64(c[i + 3]) - mean
            r3 += d * d
            d = np.float64(c[i + 4]) - mean
            r4 += d * d
            d = np.float64(c[i + 5]) - mean
            r5 += d * d
            d = np.float64(c[i + 6]) - mean
            r6 += d * d
            d = np.float64(c[i + 7]) - mean
            r7 += d * d
        res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        for i in range(m, n):
            d = np.float64(c[i]) - mean
            res += d * d
        return res
    n2 = n // 2
    n2 -= n2 % 8
    return _sq_dev_sum(c[:n2], mean) + _sq_dev_sum(c[n2:], mean)


@njit(cache=True, nogil=True, boundscheck=False)
def _key(x):
    """The bits ``x`` of a float32 as an integer that orders as the float does (NaN aside); its own inverse."""
    return x ^ ((x >> 31) & 0x7FFFFFFF)


@njit(cache=True, nogil=True, boundscheck=False)
def _total_min_max(w, sums, lo_k, hi_k):
    """(the mean's sum: the runs' sums added in order to 0.0, as numpy adds its buffers; min; max). A NaN in
    ``w`` makes the sum NaN, and only then is ``w`` searched for one, which is then the min and the max, as
    numpy's min and max propagate it."""
    total = 0.0
    for r in range(sums.size):
        total += sums[r]
    if np.isnan(total):
        for i in range(w.size):
            if np.isnan(w[i]):
                return total, w[i], w[i]
    out = np.empty(2, np.int32)
    out[0] = _key(lo_k)
    out[1] = _key(hi_k)
    mm = out.view(np.float32)
    return total, mm[0], mm[1]


@njit(cache=True, nogil=True, boundscheck=False)
def _update_runs(w, bufsize, runs, sums, lo_keys, hi_keys):
    """For each run ``r`` in ``runs`` (of ``bufsize`` values of the flat float32 ``w``): its pairwise sum into
    ``sums[r]`` and its min and max keys (:func:`_key`) into ``lo_keys[r]``, ``hi_keys[r]``.

    Each run is summed, then scanned for min and max while it is still in the cache. The scan compares integer
    keys of the bits: a float min that must mind NaN stays scalar, an integer one is vectorised, three to four
    times faster."""
    bits = w.view(np.int32)
    for j in range(runs.size):
        r = runs[j]
        lo = r * bufsize
        hi = min(lo + bufsize, w.size)
        sums[r] = _sum(w[lo:hi])
        b = bits[lo:hi]
        lo_k = hi_k = _key(b[0])
        for i in range(b.size):
            k = _key(b[i])
            lo_k = min(lo_k, k)
            hi_k = max(hi_k, k)
        lo_keys[r] = lo_k
        hi_keys[r] = hi_k


class RunCache:
    """The first pass of :func:`weight_stats` kept between calls on one array: each run's sum and min and max
    keys, so that a later call reads again only the runs written since (``changed``). The learning weights of the
    full network change in ~2,000 of 60,000 rows per 10 trials, which touch about a third of the runs."""

    def __init__(self, size: int, bufsize: int):
        n_runs = -(-size // bufsize)
        self.size, self.bufsize = size, bufsize
        self.sums = np.zeros(n_runs)
        self.lo_keys = np.zeros(n_runs, np.int32)
        self.hi_keys = np.zeros(n_runs, np.int32)
        self.filled = False

    def runs_of(self, starts: np.ndarray, length: int) -> np.ndarray:
        """The runs that the ranges ``flat[s:s + length]`` (s in ``starts``) touch, in order."""
        if not len(starts) or not length:
            return np.zeros(0, np.int64)
        starts = np.asarray(starts, np.int64)
        first, last = starts // self.bufsize, (starts + length - 1) // self.bufsize
        edge = np.zeros(len(self.sums) + 1, np.int64)
        np.add.at(edge, first, 1)
        np.add.at(edge, last + 1, -1)
        return np.flatnonzero(np.cumsum(edge[:-1]))


def _cached_sum_min_max(w: np.ndarray, cache: RunCache, changed: np.ndarray | None,
                        beside: Beside | None) -> tuple[float, Any, Any]:
    """(sum as ``w.mean(dtype=float64)`` adds it, min, max) of the flat float32 ``w`` from ``cache``, whose runs
    ``changed`` (all of them when None or while the cache is not filled) are read again first; with ``beside``
    half of those on the other thread."""
    runs = np.arange(len(cache.sums), dtype=np.int64) if changed is None or not cache.filled else changed
    if beside is None or runs.size * cache.bufsize < SPLIT_MIN:
        _update_runs(w, cache.bufsize, runs, cache.sums, cache.lo_keys, cache.hi_keys)
    else:
        half = runs.size // 2
        other = beside(_update_runs, w, cache.bufsize, runs[half:], cache.sums, cache.lo_keys, cache.hi_keys)
        _update_runs(w, cache.bufsize, runs[:half], cache.sums, cache.lo_keys, cache.hi_keys)
        other()
    cache.filled = True
    return _total_min_max(w, cache.sums, cache.lo_keys.min(), cache.hi_keys.max())


Beside = Callable[..., Callable[[], Any]]
"""Runs ``fn(*args)`` on another thread and returns a function that waits for its result."""

SPLIT_MIN = 1 << 20
"""Arrays at least this large are read by two threads when a second one is offered."""


def _sum_min_max(w: np.ndarray, bufsize: int, beside: Beside | None = None) -> tuple[float, Any, Any]:
    """(sum as ``w.mean(dtype=float64)`` adds it, min, max) of the flat float32 ``w`` (size >= 1), one pass;
    with ``beside`` the second half of the runs is read on the other thread."""
    return _cached_sum_min_max(w, RunCache(w.size, bufsize), None, beside)


def std_f64(w: np.ndarray, mean: float, beside: Beside | None = None) -> float:
    """``np.std(w, dtype=np.float64)`` (``mean``: ``w.mean(dtype=np.float64)``), without the temporary; with
    ``beside`` the two halves of numpy's first pairwise split are summed on two threads and added as numpy
    adds them."""
    flat = np.ascontiguousarray(w).reshape(-1)
    mean = np.float64(mean)
    if beside is None or flat.size < SPLIT_MIN or flat.size <= _BLOCK:  # numpy splits only above a block
        total = _sq_dev_sum(flat, mean)
    else:
        n2 = flat.size // 2
        n2 -= n2 % 8
        right = beside(_sq_dev_sum, flat[n2:], mean)
        total = _sq_dev_sum(flat[:n2], mean) + right()
    return float(np.sqrt(total / flat.size))


def weight_stats(w: np.ndarray, beside: Beside | None = None, cache: RunCache | None = None,
                 changed: np.ndarray | None = None) -> tuple[float, float, float, float]:
    """(mean, std, min, max) of ``w`` as ``w.mean(dtype=float64)``, ``w.std(dtype=float64)``, ``w.min()``,
    ``w.max()`` give them.

    A C-contiguous float32 ``w`` is read twice (:func:`_sum_min_max`, :func:`std_f64`), each pass split between
    this thread and another when ``beside`` offers one (the spiking controller's network thread, idle between
    trials): the same additions in the same order, about half the wall time. One difference ``==`` does not
    see: where 0.0 and -0.0 both hold the min (or max), numpy reports either, by its vector lane order, this
    -0.0 for the min and 0.0 for the max. The weights hold no -0.0: the plasticity kernels clip at the lower
    bound by writing the bound.

    With ``cache`` (a :class:`RunCache` of ``w``'s size and numpy's buffer size) the first pass reads only the
    runs in ``changed`` (:meth:`RunCache.runs_of` of the ranges written since the last call with that cache)
    and takes the other runs' sums and extremes from the cache: the same numbers.
    """
    if w.dtype != np.float32 or not w.flags.c_contiguous or w.size == 0:
        mean = w.mean(dtype=np.float64)
        return float(mean), std_f64(w, mean), float(w.min()), float(w.max())
    flat = w.reshape(-1)
    if cache is not None and cache.size == flat.size and cache.bufsize == np.getbufsize():
        total, mn, mx = _cached_sum_min_max(flat, cache, changed, beside)
    else:
        total, mn, mx = _sum_min_max(flat, np.getbufsize(), beside)
    mean = total / flat.size
    return float(mean), std_f64(flat, mean, beside), float(mn), float(mx)
