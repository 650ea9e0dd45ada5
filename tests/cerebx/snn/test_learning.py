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


@pytest.mark.parametrize("where", ["loop", "network", "alternating"])
def test_cf_uniforms_drawn_on_either_thread_give_identical_results(load, monkeypatch, where):
    """The pipelined controller draws a chunk's CF uniforms on the loop's thread or, as the chunk starts, on the
    network thread (whichever has time to spare): forced to one, the other or each in turn, the torques, the
    learned weights and the draws' stream are those of the synchronous controller."""
    import threading

    from cerebx.controllers.snn.controller import NetworkThread
    from cerebx.snn.encoders import AfferentRing

    drew: list[str] = []
    draws = AfferentRing.draws

    def counted(self, ticks):
        if len(ticks) == 2:
            drew.append(threading.current_thread().name)
        return draws(self, ticks)

    turns = iter(range(10**6))
    behind = {"loop": lambda self: False, "network": lambda self: True,
              "alternating": lambda self: next(turns) % 2 == 0}[where]
    runs = {}
    for pipeline in (True, False):
        cfg = load(["+task=circle", "+experiment=small_snn", "trials=2", f"controller.pipeline={pipeline}"])
        ctx = build_components(cfg)
        if pipeline:
            ctx.controller.serve_chunks = False  # the network thread's chunks (the chunk server draws on the loop's)
            monkeypatch.setattr(NetworkThread, "ready", behind)
            monkeypatch.setattr(AfferentRing, "draws", counted)
        loop = ClosedLoop(ctx, None)
        loop.start()
        torques = []
        control = ctx.controller.control

        def recorded(inp, control=control, torques=torques):
            msg = control(inp)
            torques.append(msg.tau.copy())
            return msg

        ctx.controller.control = recorded
        maes = [loop.run_trial(i).mae_per_joint for i in range(2)]
        ctx.controller._join()
        aff = getattr(ctx.controller, "_aff", None)
        if pipeline:  # the ticks kept since the last chunk drawn too, as the synchronous controller has
            assert aff is not None and aff.drawn == aff.batches > 0
            aff.encode_now()
        runs[pipeline] = (maes, np.array(torques), ctx.controller.net.weights("pf_pc").copy(),
                          ctx.controller.cf.rng.random(3))
        monkeypatch.undo()
    assert runs[True][0] == runs[False][0]
    for a, b in zip(runs[True][1:], runs[False][1:]):
        np.testing.assert_array_equal(a, b)
    on_network = drew.count("cerebx-snn")
    assert {"loop": on_network < len(drew) // 4, "network": on_network > 3 * len(drew) // 4,
            "alternating": 0 < on_network < len(drew)}[where], drew


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
