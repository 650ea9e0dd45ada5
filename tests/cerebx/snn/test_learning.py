"""The cerebellar controller learns: later trials track better than early ones (thesis Fig. 2.6 g)."""

from __future__ import annotations

import numpy as np
import pytest

from cerebx.build import build_components
from cerebx.loop.loop import ClosedLoop

pytestmark = pytest.mark.integration


def test_snn_learning_reduces_error_on_small_network(load):
    cfg = load(["+task=circle", "+experiment=small_snn", "trials=30", "seed=0"])
    ctx = build_components(cfg)
    loop = ClosedLoop(ctx, None)
    loop.start()
    mae = np.array([loop.run_trial(i).mae for i in range(30)])
    early, late = mae[:5].mean(), mae[-5:].mean()
    assert late < 0.8 * early, mae.round(3)
    w = ctx.controller.net.weights("pf_pc")
    assert 0.0 <= w.min() < w.max() <= 5.0


def test_plasticity_off_does_not_learn(load):
    cfg = load(["+task=circle", "+experiment=small_snn", "trials=8", "controller.plasticity=false"])
    ctx = build_components(cfg)
    loop = ClosedLoop(ctx, None)
    loop.start()
    mae = np.array([loop.run_trial(i).mae for i in range(8)])
    w = ctx.controller.net.weights("pf_pc")
    assert w.min() == w.max() == 2.0
    assert mae[-3:].mean() > 0.9 * mae[:3].mean()


def test_pipelined_network_gives_identical_results(load):
    """Running the network a chunk ahead on a worker thread changes wall time, not results."""
    runs = {}
    for pipeline in (True, False):
        cfg = load(["+task=circle", "+experiment=small_snn", "trials=1", f"controller.pipeline={pipeline}"])
        ctx = build_components(cfg)
        loop = ClosedLoop(ctx, None)
        loop.start()
        m = loop.run_trial(0)
        runs[pipeline] = (m.mae_per_joint, ctx.controller.net.weights("pf_pc").copy())
    assert runs[True][0] == runs[False][0]
    np.testing.assert_array_equal(runs[True][1], runs[False][1])


def test_init_from_other_network_is_one_clear_error(load, tmp_path, capsys):
    """A learned state from a different network is refused at validation with one line."""
    from cerebx.loop.runner import run_experiment

    first = run_experiment(load(["+task=circle", "+experiment=small_snn", "trials=1"]), tmp_path / "small")
    assert first["status"] == "completed" and (tmp_path / "small" / "controller_state.npz").exists()
    cfg = load(["+task=circle", "+experiment=small_snn", "trials=1",
                "controller.network.projections.mf_dcn.weight_nS=0.2",
                f"init_from={tmp_path / 'small'}"])
    same = run_experiment(cfg, tmp_path / "same")  # same structure, other weights: allowed
    assert same["status"] == "completed"
    from cerebx.errors import ConfigError

    with pytest.raises(ConfigError) as err:  # refused at validation: no run folder is made
        load(["+task=circle", "trials=1", f"init_from={tmp_path / 'small'}"])
    assert len(err.value.problems) == 1 and "fingerprint" in err.value.problems[0]
    assert err.value.problems[0].startswith("init_from: ") and not (tmp_path / "other").exists()


@pytest.mark.slow
def test_full_network_learns_the_circle_on_baxter(load):
    """The thesis network (62,040 neurons, 36 M plastic PF-PC synapses) closed-loop with the MuJoCo Baxter:
    after 100 trials from scratch the last 10 track clearly better than the first 10 (Table 2.3's trend)."""
    cfg = load(["+task=circle", "trials=100", "seed=0"])
    loop = ClosedLoop(build_components(cfg), None)
    loop.start()
    mae = np.array([loop.run_trial(i).mae for i in range(100)])
    assert mae[-10:].mean() < 0.6 * mae[:10].mean(), mae.round(3)
