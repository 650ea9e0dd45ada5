"""Weight statistics for /weights: the one-pass standard deviation and the fused mean, min and max equal
numpy's bit for bit."""

from __future__ import annotations

import math
import threading

import numpy as np
import pytest

from cerebx.snn import weight_stats as ws
from cerebx.snn.weight_stats import std_f64, weight_stats

# around every branch of numpy's pairwise sum: < 8, the 8-way blocks up to 128, odd splits above, and
# around the 8192-value buffers of the mean's cast (one, two, three buffers and a bit)
SIZES = [1, 2, 7, 8, 9, 15, 16, 17, 127, 128, 129, 130, 255, 256, 257, 1000, 8191, 8192, 8193, 16383,
         16384, 16385, 8191 * 3, 65_537, 1_000_003, 2_000_001]
SHAPES = [(10_000, 600), (37, 8193), (8193, 37)]


def numpy_stats(w):
    return tuple(float(x) for x in (w.mean(dtype=np.float64), w.std(dtype=np.float64), w.min(), w.max()))


def patterns(n, seed):
    """Random weights, mostly one value (as after learning), and signed values over many magnitudes. Drawn
    in float64 and rounded to float32, so small values carry low bits and the float64 sums round: a sum
    in another order differs in the last bits (with ``random(dtype=float32)`` they are exact)."""
    rng = np.random.default_rng(seed)
    yield (rng.random(n) * 5).astype(np.float32)
    yield np.where(rng.random(n) < 0.9, 2.0, rng.random(n) * 5).astype(np.float32)
    yield (rng.standard_normal(n) * np.exp(rng.normal(0.0, 4.0, n))).astype(np.float32)


@pytest.mark.parametrize("n", SIZES)
def test_std_equals_numpy_bit_for_bit(n):
    rng = np.random.default_rng(n)
    for w in (rng.random(n, dtype=np.float32) * 5, np.where(rng.random(n) < 0.9, 2.0, rng.random(n) * 5)):
        w = w.astype(np.float32)
        assert std_f64(w, w.mean(dtype=np.float64)) == w.std(dtype=np.float64)


@pytest.mark.parametrize("shape", SIZES + SHAPES)
def test_weight_stats_equal_numpy_bit_for_bit(shape):
    for w in patterns(int(np.prod(shape)), seed=int(np.prod(shape))):
        w = w.reshape(shape)
        assert weight_stats(w) == numpy_stats(w)


def run_sums(w, run, start=0.0):
    """``start`` plus numpy's pairwise float64 sums of consecutive runs of ``w``, added in order."""
    for i in range(0, w.size, run):
        start += np.add.reduce(w[i : i + run].astype(np.float64))
    return start


def test_the_mean_is_numpy_s_run_sums_and_the_data_shows_any_other_grouping():
    w = list(patterns(2_000_001, seed=0))[2]
    want = w.mean(dtype=np.float64)
    assert weight_stats(w)[0] == run_sums(w, 8192) / w.size == want
    # one sum over all, other run lengths, and runs after a first element taken as the start
    for other in (run_sums(w, w.size), run_sums(w, 4096), run_sums(w, 8200), run_sums(w[1:], 8192, float(w[0]))):
        assert other / w.size != want


def test_another_buffer_size_is_followed():
    w = next(patterns(100_003, seed=1))
    old = np.setbufsize(4096)
    try:
        assert weight_stats(w) == numpy_stats(w)
    finally:
        np.setbufsize(old)


def test_other_layouts_and_dtypes_are_numpy_s():
    w = next(patterns(600 * 1000, seed=2)).reshape(1000, 600)
    for v in (w[:, :300], w[::2], w.T, w.reshape(-1)[1::3], w.astype(np.float64)):
        assert weight_stats(v) == numpy_stats(v)


def test_nan_is_the_min_and_max_as_in_numpy_and_inf_is_kept():
    for n, at in ((1, 0), (9, 8), (8193, 0), (8193, 4000), (100_000, 99_999)):
        w = np.full(n, 2.0, np.float32)
        w[at] = np.nan
        got = weight_stats(w)
        assert all(math.isnan(x) for x in got) and all(math.isnan(x) for x in numpy_stats(w))
    w = next(patterns(20_000, seed=3))
    w[[10, 15_000]] = np.inf, -np.inf  # mean and std NaN, min and max the infinities
    with np.errstate(invalid="ignore"):
        got, want = weight_stats(w), numpy_stats(w)
    assert math.isnan(got[0]) and math.isnan(want[0]) and math.isnan(got[1]) and math.isnan(want[1])
    assert got[2:] == want[2:] == (-math.inf, math.inf)


def test_a_pf_pc_block_and_its_summary_are_numpy_s():
    rng = np.random.default_rng(0)
    w = np.full((10_000, 600), 2.0, np.float32)
    w.reshape(-1)[rng.integers(0, w.size, 100_000)] = rng.random(100_000, dtype=np.float32) * 5
    assert weight_stats(w) == numpy_stats(w)


def on_a_thread(fn, *args):
    """A ``beside``: ``fn(*args)`` on a thread of its own."""
    box = {}
    t = threading.Thread(target=lambda: box.setdefault("result", fn(*args)))
    t.start()

    def wait():
        t.join()
        return box["result"]

    return wait


@pytest.mark.parametrize("shape", SIZES + SHAPES)
def test_two_threads_give_numpy_s_stats_bit_for_bit(shape, monkeypatch):
    monkeypatch.setattr(ws, "SPLIT_MIN", 1)  # split every size, the smallest included
    for w in patterns(int(np.prod(shape)), seed=int(np.prod(shape))):
        w = w.reshape(shape)
        assert weight_stats(w, on_a_thread) == numpy_stats(w)


def test_two_threads_find_a_nan_or_an_extreme_in_either_half(monkeypatch):
    monkeypatch.setattr(ws, "SPLIT_MIN", 1)
    for n, at in ((8193, 0), (8193 * 4, 8193 * 3), (100_000, 99_999)):
        w = np.full(n, 2.0, np.float32)
        w[at] = np.nan
        assert all(math.isnan(x) for x in weight_stats(w, on_a_thread))
        w[at] = -7.0
        assert weight_stats(w, on_a_thread) == numpy_stats(w)
        w[at] = 9.0
        assert weight_stats(w, on_a_thread) == numpy_stats(w)


@pytest.mark.parametrize("beside", [None, on_a_thread])
@pytest.mark.parametrize("shape", [(10_000, 600), (37, 8193), (3, 20_000), (1000, 7)])
def test_a_cached_first_pass_that_reads_only_the_written_rows_gives_numpy_s_stats(shape, beside, monkeypatch):
    """Rows rewritten between calls (a few, many, none, the last one, a NaN and back), with the cache told
    which: the same numbers as numpy each time."""
    monkeypatch.setattr(ws, "SPLIT_MIN", 1)
    rng = np.random.default_rng(shape[0])
    w = next(patterns(int(np.prod(shape)), seed=1)).reshape(shape)
    n_pre, n_post = shape
    cache = ws.RunCache(w.size, np.getbufsize())
    assert weight_stats(w, beside, cache, None) == numpy_stats(w)
    for rows in (rng.choice(n_pre, max(1, n_pre // 30), replace=False), np.arange(n_pre), np.zeros(0, int),
                 np.array([n_pre - 1]), rng.choice(n_pre, max(1, n_pre // 3), replace=False)):
        w[rows] = (rng.random((len(rows), n_post)) * 5).astype(np.float32)
        got = weight_stats(w, beside, cache, cache.runs_of(np.sort(rows) * n_post, n_post))
        assert got == numpy_stats(w)
    w[n_pre // 2, 0] = np.nan
    got = weight_stats(w, beside, cache, cache.runs_of(np.array([n_pre // 2 * n_post]), n_post))
    assert all(math.isnan(x) for x in got)
    w[n_pre // 2, 0] = -3.0
    got = weight_stats(w, beside, cache, cache.runs_of(np.array([n_pre // 2 * n_post]), n_post))
    assert got == numpy_stats(w)


def test_the_runs_of_ranges_are_every_buffer_they_touch():
    cache = ws.RunCache(100, 10)
    assert cache.runs_of(np.array([0]), 10).tolist() == [0]
    assert cache.runs_of(np.array([5, 9, 95]), 2).tolist() == [0, 1, 9]
    assert cache.runs_of(np.array([15]), 31).tolist() == [1, 2, 3, 4]
    assert cache.runs_of(np.zeros(0, np.int64), 10).tolist() == []


def test_the_network_s_statistics_follow_its_learning_and_checkpoints():
    """The spiking network's own statistics (cached first pass, rows from the kernels' marks, checkpoints taking
    those marks in between, a load of other weights) equal numpy's on its weights after every stretch."""
    from cerebx.snn.network import Network
    from cerebx.snn.presets import network as full_network

    net = Network(full_network(fibers=5, per_joint=20), parallel=False)
    mf, cf = net.index("mf"), net.index("cf")
    rng = np.random.default_rng(0)
    name = net.plastic_projections[0]
    seen = set()
    F = (mf.stop - mf.start) // 24
    bins = rng.integers(F, size=(6, 4))
    for stretch in range(6):
        for k in range(60):  # each joint's 4 signals box-coded, moving every 20 ms; CF at ~10 Hz
            if k % 10 == 0:
                bins = np.clip(bins + rng.integers(-1, 2, size=bins.shape), 0, F - 1)
            ids = (np.arange(6)[:, None] * 4 * F + np.arange(4)[None, :] * F + bins).ravel() + mf.start
            cfs = np.flatnonzero(rng.random(cf.stop - cf.start) < 0.02) + cf.start
            net.step(np.concatenate([ids, cfs]).astype(np.int32))
        if stretch % 2:
            net.changed_ranges()  # a checkpoint takes the marks
        if stretch == 4:
            arrays = net.state_arrays()
            arrays = {k: v.copy() for k, v in arrays.items()}
            arrays["dense_w"][:] = rng.random(arrays["dense_w"].size).astype(np.float32) * 3
            net.load_arrays(arrays)
        stats = net.weight_stats(name)
        assert stats == numpy_stats(net.weights(name)), stretch
        seen.add(stats)
    assert len(seen) == 6  # the network learned in every stretch
