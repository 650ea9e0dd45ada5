"""PF-PC kernel STDP (docs/models.md#kernel-stdp): LTP per PF spike, LTD at CF spikes weighted by the kernel."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.persistence import checkpoint
from cerebx.snn.network import Network
from cerebx.snn.presets import PC
from cerebx.snn.schema import NetworkConfig
from cerebx.snn.topology import ltd_kernel_table

W0, LTP, LTD = 2.0, 0.002, -0.0008


def plastic_net(n_pf=4, n_pc=3, ltp=LTP, ltd=LTD, w_range=(0.0, 5.0), peak=150.0, onset=120.0) -> Network:
    cfg = {
        "name": "stdp", "dt_ms": 0.5,
        "populations": {"pf": {"size": n_pf, "neuron": {"kind": "input"}},
                        "cf": {"size": n_pc, "neuron": {"kind": "input"}},
                        "pc": {"size": n_pc, "neuron": PC}},
        "projections": {
            "pf_pc": {"pre": "pf", "post": "pc", "rule": {"kind": "all_to_all"}, "receptor": "ampa",
                      "synapses": n_pf * n_pc, "weight_nS": W0, "weight_range_nS": list(w_range),
                      "plasticity": {"kind": "kernel_stdp", "ltp_nS": ltp, "ltd_nS": ltd,
                                     "kernel_peak_ms": peak, "kernel_onset_ms": onset, "teacher": "cf_pc"}},
            "cf_pc": {"pre": "cf", "post": "pc", "rule": {"kind": "one_to_one"}, "receptor": "ampa",
                      "synapses": n_pc, "weight_nS": 0.0, "teaching": True},
        },
        "io": {"mossy": "pf", "climbing": "cf", "output": "pc", "purkinje": ["pc"], "granule": "pf"},
    }
    return Network(NetworkConfig.model_validate(cfg), parallel=False)


def run(net: Network, schedule: dict[int, list[tuple[str, int]]], n_steps: int) -> None:
    for k in range(n_steps):
        idx = [net.index(pop).start + i for pop, i in schedule.get(k, [])]
        net.step(np.array(idx, dtype=np.int32))


def test_kernel_table_shape():
    k = ltd_kernel_table(150.0, 120.0, 0.01, 0.5)
    assert k[240] == 0.0 and k[241] > 0  # zero up to the onset (120 ms)
    assert k[300] == pytest.approx(1.0)  # peak
    assert k.argmax() == 300
    assert 0.34 < len(k) * 0.5 / 1000 < 0.36  # window about 0.35 s (docs/provenance.md#original-learning-rule)


def test_pf_then_cf_at_kernel_peak_changes_weight_by_beta_plus_alpha():
    net = plastic_net()
    # PF 1 at t=0; CF to PC 2 at t=150 ms: both arrive one delay later, 150 ms apart (k = 1)
    run(net, {0: [("pf", 1)], 75: [("cf", 2)]}, 80)
    w = net.weights("pf_pc")
    assert w[1, 2] == pytest.approx(W0 + LTP + LTD, abs=1e-6)
    assert w[1, 0] == pytest.approx(W0 + LTP, abs=1e-6)  # no CF on PC 0: LTP only
    assert w[0, 2] == pytest.approx(W0, abs=1e-6)  # silent PF untouched


@pytest.mark.parametrize("cf_step", [2, 60, 250])
def test_cf_outside_the_kernel_window_gives_no_ltd(cf_step):
    """CF 4 ms (before onset), 120 ms (at onset, k = 0) or 500 ms (past the cutoff) after the PF."""
    net = plastic_net()
    run(net, {0: [("pf", 1)], cf_step: [("cf", 2)]}, cf_step + 5)
    assert net.weights("pf_pc")[1, 2] == pytest.approx(W0 + LTP, abs=1e-6)


def test_each_pf_spike_adds_alpha_to_every_pc():
    net = plastic_net()
    run(net, {k: [("pf", 3)] for k in range(0, 20, 2)}, 22)
    np.testing.assert_allclose(net.weights("pf_pc")[3], W0 + 10 * LTP, atol=1e-5)


def test_ltd_sums_over_buffered_pf_spikes():
    net = plastic_net()
    peak = ltd_kernel_table(150.0, 120.0, 0.01, 0.5)
    # two PF spikes 150 ms and 130 ms before the CF arrival
    run(net, {0: [("pf", 0)], 10: [("pf", 0)], 75: [("cf", 1)]}, 80)
    want = W0 + 2 * LTP + LTD * (peak[300] + peak[260])
    assert net.weights("pf_pc")[0, 1] == pytest.approx(want, abs=1e-6)


def test_weights_stay_in_range():
    net = plastic_net(ltp=0.5, ltd=-3.0, w_range=(0.5, 3.0))
    rng = np.random.default_rng(1)
    sched = {k: [("pf", int(j)) for j in rng.choice(4, 2, replace=False)]
             + ([("cf", int(rng.integers(3)))] if k % 7 == 0 else []) for k in range(300)}
    run(net, sched, 300)
    w = net.weights("pf_pc")
    assert w.min() >= 0.5 and w.max() <= 3.0
    assert (w == 0.5).any() or (w == 3.0).any()


def test_plasticity_off_freezes_weights():
    net = plastic_net()
    net.learn = False
    run(net, {0: [("pf", 1)], 75: [("cf", 2)]}, 80)
    np.testing.assert_array_equal(net.weights("pf_pc"), W0)


def test_checkpoints_rewrite_the_rows_learning_changed(tmp_path):
    net = plastic_net(n_pf=30, n_pc=4)
    rng = np.random.default_rng(0)

    def learn(n_steps, n_pf):  # PF and CF spikes; LTD also reaches PFs of the previous interval
        run(net, {k: [("pf", int(i)) for i in rng.choice(n_pf, 2, replace=False)]
                  + ([("cf", int(rng.integers(4)))] if k % 7 == 0 else []) for k in range(0, n_steps, 5)}, n_steps)

    store = checkpoint.ArrayStore()
    learn(200, 30)
    run(net, {}, 300)  # past the kernel window of those spikes
    run(net, {0: [("pf", 25)]}, 40)  # LTD after the checkpoint (CF at step 35 next)
    checkpoint.prepare(tmp_path, {"trials_done": 1}, {"net": net}, store, {}).write()  # whole
    before = net.weights("pf_pc").copy()
    learn(60, 10)
    changed = np.flatnonzero((net.weights("pf_pc") != before).any(axis=1))
    ckpt = checkpoint.prepare(tmp_path, {"trials_done": 2}, {"net": net}, store, {})
    assert ckpt.whole is None and 25 in changed and len(changed) < 30
    (_, starts, length, _), = ckpt.changes
    assert length == 4 and set(changed.tolist()) <= set((starts // 4).tolist())
    ckpt.write()
    _, state = checkpoint.load(tmp_path, {})
    np.testing.assert_array_equal(state["net"].dense_w, net.dense_w)
    np.testing.assert_array_equal(state["net"]._state.arrays.delivery.dense_w, net.dense_w)


@pytest.mark.parametrize("how", ["step", "chunk", "profiled"])
def test_every_row_learning_writes_is_reported_changed(how):
    """A checkpoint rewrites only the rows the kernels marked (``changed_ranges``): LTP alone (PF spikes, no CF
    in their window) and LTD must both mark every row they write, in each compiled variant of the step (one
    step, a chunk, a profiled step). An LTP-only row left unmarked came back from a checkpoint with its old
    weights, and a resumed run diverged from the uninterrupted one (issue #47)."""
    net = plastic_net(n_pf=30, n_pc=4)
    if how == "profiled":
        net.start_profile()
    rng = np.random.default_rng(3)
    rows = net.weights("pf_pc")
    w_off, n_post = (int(x) for x in net.de_i[net.pl_i[0, 0], [4, 3]])
    net.changed_ranges()  # the first call reports every weight; the interval starts here
    ltp_only = ltd = 0  # rows written in the first 200 steps; rows LTD lowered after
    for k in range(400):
        pf = rng.choice(30, 2, replace=False) if k % 5 == 0 else []
        cf = [int(rng.integers(4))] if k >= 200 and k % 35 == 0 else []  # the first 200 steps: LTP only
        x = np.array([net.index("pf").start + i for i in pf] + [net.index("cf").start + i for i in cf], np.int32)
        before = rows.copy()
        if how == "chunk":
            net.step_many([x])
        else:
            net.step(x)
        changed = set(np.flatnonzero((rows != before).any(axis=1)).tolist())
        marked = {int(s - w_off) // n_post for a, starts, length in net.changed_ranges() if a is net.dense_w
                  for s in starts}
        assert changed <= marked, f"step {k}: rows {sorted(changed - marked)} written but not reported"
        if k < 200:
            ltp_only += len(changed)
        else:
            ltd += int((rows < before).any(axis=1).sum())
    assert ltp_only > 20 and ltd > 20


def test_weights_written_ahead_then_their_changed_rows_give_the_checkpoint(tmp_path):
    net = plastic_net(n_pf=30, n_pc=4)
    rng = np.random.default_rng(1)

    def learn(n_steps):
        run(net, {k: [("pf", int(i)) for i in rng.choice(30, 2, replace=False)]
                  + ([("cf", int(rng.integers(4)))] if k % 7 == 0 else []) for k in range(0, n_steps, 5)}, n_steps)

    learn(200)
    store = checkpoint.ArrayStore()
    job = checkpoint.prime(tmp_path, 1, {"net": net}, store, {})  # the whole weights, from the live array
    learn(100)  # learning before the writer gets to them
    job.write()
    ahead = net.dense_w.copy()
    learn(100)  # and after
    ckpt = checkpoint.prepare(tmp_path, {"trials_done": 1}, {"net": net}, store, {})
    assert ckpt.whole is None and ckpt.file == job.name
    assert not np.array_equal(ahead, net.dense_w)
    ckpt.write()
    _, state = checkpoint.load(tmp_path, {})
    np.testing.assert_array_equal(state["net"].dense_w, net.dense_w)
