"""Weight statistics for /weights: the one-pass standard deviation equals numpy's bit for bit."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.snn.weight_stats import std_f64, weight_stats

# around every branch of numpy's pairwise sum: < 8, the 8-way blocks up to 128, odd splits above
SIZES = [1, 2, 7, 8, 9, 15, 16, 17, 127, 128, 129, 130, 255, 256, 257, 1000, 8191, 8192, 8193, 65_537,
         1_000_003]


@pytest.mark.parametrize("n", SIZES)
def test_std_equals_numpy_bit_for_bit(n):
    rng = np.random.default_rng(n)
    for w in (rng.random(n, dtype=np.float32) * 5, np.where(rng.random(n) < 0.9, 2.0, rng.random(n) * 5)):
        w = w.astype(np.float32)
        assert std_f64(w, w.mean(dtype=np.float64)) == w.std(dtype=np.float64)


def test_a_pf_pc_block_and_its_summary_are_numpy_s():
    rng = np.random.default_rng(0)
    w = np.full((10_000, 600), 2.0, np.float32)
    w.reshape(-1)[rng.integers(0, w.size, 100_000)] = rng.random(100_000, dtype=np.float32) * 5
    want = (w.mean(dtype=np.float64), w.std(dtype=np.float64), w.min(), w.max())
    assert weight_stats(w) == tuple(float(x) for x in want)
