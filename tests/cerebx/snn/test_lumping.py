"""Lumped populations (snn/lumping.py): the thesis network's granule layer stepped as classes of cells with equal
state and equal input. Every spike, state and weight equals the network that lists its granule cells one by one,
bit for bit, through mossy fibres switching boxes, steps without any input, two fibres of a signal at once,
learning, a pickle and a saved state in the middle; and the classes are few."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from cerebx.config import load
from cerebx.controllers.snn.schema import BoxEncoder
from cerebx.snn import lumping
from cerebx.snn.encoders import MossyEncoder
from cerebx.snn.network import Network

COMPACT = 1000  # compact_min: the small network's 3,750 granule cells listed (and so lumped)


@pytest.fixture(scope="module")
def small():
    exp, _ = load(["+experiment=small_snn", "+task=circle"])
    return exp.controller.network


def _drive(net: Network, cfg, n: int, seed: int = 0) -> list[np.ndarray]:
    """Box-coded mossy fibres of six joints following sines (each joint its own phase and speed), climbing fibres
    at random; steps 40-59 without any mossy input, and at steps 80-89 two fibres of every signal at once."""
    rng = np.random.default_rng(seed)
    mf, cf = net.index(cfg.io.mossy), net.index(cfg.io.climbing)
    F = (mf.stop - mf.start) // 24
    enc = MossyEncoder(BoxEncoder(fibers_per_signal=F), -np.ones((6, 4)), np.ones((6, 4)))
    ph, sp = np.arange(6), 1.0 + 0.3 * np.arange(6)
    out = []
    for k in range(n):
        t = k * 0.002
        x = [np.sin(np.pi * sp * (t - lag) + ph) for lag in (0.0, 0.05)]
        v = [np.cos(np.pi * sp * (t - lag) + ph) for lag in (0.0, 0.05)]
        act = enc.active(x[0], x[1], v[0], v[1]) + mf.start
        if 40 <= k < 60:
            act = act[:0]
        if 80 <= k < 90:
            act = np.unique(np.concatenate([act, np.minimum(act + 1, (act // F + 1) * F - 1)]))
        cfs = cf.start + np.flatnonzero(rng.random(cf.stop - cf.start) < 0.01)
        out.append(np.concatenate([act, cfs]).astype(np.int32))
    return out


def _bits(a: np.ndarray) -> np.ndarray:
    return a.view(np.uint32) if a.dtype == np.float32 else a


def _same_state(a: Network, b: Network) -> None:
    sa, sb = a.state_arrays(), b.state_arrays()
    for k in ("V", "g", "ref", "dense_w"):
        assert np.array_equal(_bits(sa[k]), _bits(sb[k])), k


def _run(net: Network, inputs: list[np.ndarray]) -> np.ndarray:
    return np.concatenate([net.step_many(inputs[c : c + 10])[0] for c in range(0, len(inputs), 10)])


def test_the_granule_layer_is_lumped_only_where_the_classes_are_exact(small):
    assert Network(small, parallel=False, compact_min=COMPACT).lumped == ["gc"]
    assert Network(small, parallel=False, compact_min=COMPACT, lumped=False).lumped == []
    assert Network(small, parallel=False).lumped == []  # not listed (3,750 < compact_min): nothing to lump
    # spikes that arrive between two of the granule cells' 1 ms steps (delay 0.5 ms) are scaled by their decay:
    # a class's input would no longer be its count times the weight
    late = small.projections["mf_gc"].model_copy(update={"delay_ms": 0.5})
    off_step = small.model_copy(update={"projections": {**small.projections, "mf_gc": late}})
    assert Network(off_step, parallel=False, compact_min=COMPACT).lumped == []


def test_lumped_granule_cells_spike_and_learn_bit_for_bit_as_listed_ones(small):
    lumped = Network(small, parallel=False, compact_min=COMPACT)
    listed = Network(small, parallel=False, compact_min=COMPACT, lumped=False)
    inputs = _drive(listed, small, 600)
    spikes = [_run(net, inputs[:300]) for net in (lumped, listed)]
    assert np.array_equal(spikes[0], spikes[1])
    gc = listed.index("gc")
    assert ((spikes[0] >= gc.start) & (spikes[0] < gc.stop)).sum() > 50  # the granule layer does spike
    _same_state(lumped, listed)
    # the classes are few: a handful of states among thousands of cells off rest
    n_cls = int(lumped.lp.n_cls[lumped.topo.index["gc"]] - lumped.lp.n_free[lumped.topo.index["gc"]])
    assert int(listed.n_act[listed.topo.index["gc"]]) > 10 * n_cls
    spikes = [_run(net, inputs[300:]) for net in (lumped, listed)]
    assert np.array_equal(spikes[0], spikes[1])
    _same_state(lumped, listed)


def test_a_lumped_network_pickled_or_saved_midway_goes_on_as_if_it_never_stopped(small):
    whole = Network(small, parallel=False, compact_min=COMPACT)
    inputs = _drive(whole, small, 400, seed=1)
    _run(whole, inputs[:200])
    copied = pickle.loads(pickle.dumps(whole))
    saved = Network(small, parallel=False, compact_min=COMPACT)
    saved.load_arrays(whole.state_arrays())
    assert copied.lumped == saved.lumped == ["gc"]
    spikes = [_run(net, inputs[200:]) for net in (whole, copied, saved)]
    assert np.array_equal(spikes[0], spikes[1]) and np.array_equal(spikes[0], spikes[2])
    _same_state(whole, copied)
    _same_state(whole, saved)


def test_reset_puts_every_lumped_cell_back_at_rest(small):
    net = Network(small, parallel=False, compact_min=COMPACT)
    net.learn = False
    inputs = _drive(net, small, 100)
    first = _run(net, inputs)
    net.reset_state()
    pi = net.topo.index["gc"]
    assert net.n_act[pi] == 0 and (net.lp.cls[net.index("gc")] == -1).all()
    assert np.array_equal(_run(net, inputs), first)


def test_fibres_that_fire_at_random_send_the_population_back_to_its_list_with_the_same_results(small):
    """Input that changes at nearly every spike gives nearly every cell a class of its own: the population goes
    back to its list for good (lumping.LUMP_MAX), and its spikes stay those of the listed network."""
    lumped = Network(small, parallel=False, compact_min=COMPACT)
    listed = Network(small, parallel=False, compact_min=COMPACT, lumped=False)
    mf = listed.index(small.io.mossy)
    rng = np.random.default_rng(3)
    inputs = [(mf.start + np.flatnonzero(rng.random(mf.stop - mf.start) < 0.3)).astype(np.int32) for _ in range(200)]
    spikes = [_run(net, inputs) for net in (lumped, listed)]
    assert lumped.lumped == []
    assert np.array_equal(spikes[0], spikes[1])
    _same_state(lumped, listed)


def test_a_fibre_given_many_times_in_one_step_hands_the_population_back_to_its_list_exactly(small):
    """Nine copies of one fibre in a step change its cells' counts by more than the class table holds
    (lumping.KMAX): the population goes back to its list at that window, which delivers every copy."""
    lumped = Network(small, parallel=False, compact_min=COMPACT)
    listed = Network(small, parallel=False, compact_min=COMPACT, lumped=False)
    inputs = _drive(listed, small, 120, seed=4)
    mf = listed.index(small.io.mossy)
    inputs[60] = np.concatenate([np.full(9, mf.start, np.int32), inputs[60]])
    spikes = [_run(net, inputs) for net in (lumped, listed)]
    assert lumped.lumped == []
    assert np.array_equal(spikes[0], spikes[1])
    _same_state(lumped, listed)


def _lumps_of(states: list[tuple[float, float, float, int]], sizes: list[int]) -> lumping.Lumps:
    """One population's classes (slots 0..), class c with state ``states[c]`` (u, g, refractory, count) and
    ``sizes[c]`` members, numbered in class order; the hash table sized as :func:`lumping.build` sizes it."""
    n = sum(sizes)
    lp = lumping.empty(n, 1)._replace(htab=np.zeros(1 << int(np.ceil(np.log2(2 * (n + 1)))), np.int32),
                                      used=np.zeros(n, np.int64))
    i = 0
    for c, ((u, g, r, k), m) in enumerate(zip(states, sizes, strict=True)):
        lp.cu[c], lp.cg[c], lp.cref[c], lp.ccnt[c], lp.csize[c], lp.chead[c] = u, g, r, k, m, i
        for j in range(m):
            lp.cls[i], lp.pv[i], lp.nx[i] = c, i - 1 if j else -1, i + 1 if j < m - 1 else -1
            i += 1
    lp.n_cls[0] = len(states)
    return lp


@pytest.mark.parametrize("n_pairs", [3, 150])
def test_classes_that_reached_the_same_state_merge_into_one_with_every_member(n_pairs):
    """Pairs of classes with equal bits and count (and one that differs from its twin only in the count) merge,
    each member then in the class of its old state; the probe table is empty again. 300 classes probe a table
    much larger than the first-level one the merge starts from; 6, a table of 16 slots."""
    rng = np.random.default_rng(1)
    twins = [(float(u), float(g), float(r), int(k)) for u, g, r, k in
             zip(rng.normal(size=n_pairs).astype(np.float32), rng.random(n_pairs).astype(np.float32),
                 rng.integers(0, 3, n_pairs), rng.integers(0, 5, n_pairs), strict=True)]
    states = [s for s in twins for _ in range(2)] + [twins[0][:3] + (twins[0][3] + 1,)]
    sizes = list(rng.integers(1, 4, len(states)))
    lp = _lumps_of(states, sizes)
    before = [states[c] for c in lp.cls]
    lumping.merge(lp, 0, 0)
    live = np.flatnonzero(lp.csize[: lp.n_cls[0]] > 0)
    assert len(live) == n_pairs + 1
    for c in live:
        members, i = [], lp.chead[c]
        while i >= 0:
            members.append(i)
            i = lp.nx[i]
        assert len(members) == lp.csize[c] and all(lp.cls[i] == c for i in members)
    after = [(float(lp.cu[c]), float(lp.cg[c]), float(lp.cref[c]), int(lp.ccnt[c])) for c in lp.cls]
    assert after == before
    assert not lp.htab.any()
