"""The chunk server: the pipelined network's chunks simulated by a compiled loop that never takes the interpreter
lock (``ChunkServer``), with the results of the network thread and of the synchronous controller."""

from __future__ import annotations

import gc
import time

import numpy as np
import pytest

from cerebx.build import build_components
from cerebx.controllers.snn import controller as snn_controller
from cerebx.loop.loop import ClosedLoop

pytestmark = pytest.mark.integration


def _run(load, serve: bool, trials: int = 2, pipeline: bool = True, sheds: dict[int, int] | None = None):
    """Torques per tick, MAE per trial, learned weights and the CF generator's next draws of the small network;
    ``sheds``: the shedding level set at those ticks."""
    ctx = build_components(load(["+task=circle", "+experiment=small_snn", f"trials={trials}",
                                 f"controller.pipeline={pipeline}"]))
    ctrl = ctx.controller
    ctrl.serve_chunks = serve
    loop = ClosedLoop(ctx, None)
    loop.start()
    torques, control = [], ctrl.control

    def recorded(inp):
        if sheds and inp.tick in sheds:
            ctrl.shed(sheds[inp.tick])
        msg = control(inp)
        torques.append(msg.tau.copy())
        return msg

    ctrl.control = recorded
    maes = [loop.run_trial(i).mae_per_joint for i in range(trials)]
    ctrl._join()
    used = ctrl._srv is not None
    if ctrl._aff is not None:
        ctrl._aff.encode_now()
    return maes, np.array(torques), ctrl.net.weights("pf_pc").copy(), ctrl.cf.rng.random(3), used


def test_the_chunk_server_gives_the_network_threads_and_the_synchronous_results(load):
    served = _run(load, True)
    assert served[-1], "the chunk server was not used"
    for other in (_run(load, False), _run(load, True, pipeline=False)):
        assert other[0] == served[0]
        for a, b in zip(served[1:4], other[1:4]):
            np.testing.assert_array_equal(a, b)


def test_chunks_switch_between_the_server_and_the_network_thread_with_the_same_results(load):
    """Shedding spike propagation (level 2) hands chunks to the network thread, which does not run the network;
    back at level 0 they go to the server again: torques and weights as with the network thread throughout."""
    sheds = {300: 2, 600: 0, 1200: 1, 1500: 0}
    served, threaded = _run(load, True, sheds=sheds), _run(load, False, sheds=sheds)
    assert served[-1] and not threaded[-1]
    assert served[0] == threaded[0]
    for a, b in zip(served[1:4], threaded[1:4]):
        np.testing.assert_array_equal(a, b)


def test_an_exception_in_the_server_is_raised_on_the_loop_thread_and_the_next_chunk_gets_a_new_server(
        load, monkeypatch):
    ctx = build_components(load(["+task=circle", "+experiment=small_snn", "trials=1"]))
    ctrl = ctx.controller
    loop = ClosedLoop(ctx, None)
    loop.start()

    def broken(box, *args):
        raise ValueError("kernel: out of spike buffer")

    monkeypatch.setattr(snn_controller, "_serve_chunks", broken)
    with pytest.raises(ValueError, match="out of spike buffer"):
        loop.run_trial(0)
    assert ctrl._srv is None and ctrl._in_flight == 0 and not ctrl._served
    monkeypatch.undo()
    ctrl.reset(np.random.default_rng(0))
    loop.run_trial(1)  # a new server
    assert ctrl._srv is not None and ctrl._srv.collected > 0


def _one_trial(load):
    """The small network's closed loop after one trial, its chunk server idle."""
    ctx = build_components(load(["+task=circle", "+experiment=small_snn", "trials=1"]))
    loop = ClosedLoop(ctx, None)
    loop.start()
    loop.run_trial(0)
    loop.settle()
    return ctx, loop


def test_the_server_thread_stops_when_its_controller_is_collected(load):
    ctx, loop = _one_trial(load)
    thread = ctx.controller._srv._thread
    assert thread.is_alive()
    del loop, ctx
    gc.collect()
    t0 = time.monotonic()
    while thread.is_alive() and time.monotonic() - t0 < 5:
        time.sleep(0.01)
    assert not thread.is_alive()


def test_an_idle_server_leaves_its_core_free(load):
    """Waiting for chunks the server sleeps between polls: idle, its thread takes a few percent of a core."""
    ctx, _loop = _one_trial(load)
    ident = ctx.controller._srv._thread.native_id
    time.sleep(0.1)  # past its polling and short naps

    def cpu_s() -> float:
        with open(f"/proc/self/task/{ident}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / 100.0  # utime + stime, clock ticks

    c0, t0 = cpu_s(), time.monotonic()
    time.sleep(1.0)
    assert (cpu_s() - c0) / (time.monotonic() - t0) < 0.1


def test_a_recorded_run_logs_the_same_spikes_from_the_server_as_from_the_network_thread(load, tmp_path, monkeypatch):
    from cerebx.loop.runner import run_experiment
    from cerebx.recording.reader import read_messages

    served = []
    result = snn_controller.ChunkServer.result

    def counted(self):
        served.append(1)
        return result(self)

    monkeypatch.setattr(snn_controller.ChunkServer, "result", counted)
    logs = {}
    for serve in (True, False):
        monkeypatch.setattr(snn_controller.SNNControllerImpl, "serve_chunks", serve)
        run_dir = tmp_path / f"serve_{serve}"
        summary = run_experiment(load(["+task=circle", "+experiment=small_snn", "trials=2",
                                       "controller.record_spikes=[dcn,pc]"]), run_dir)
        assert summary["status"] == "completed"
        logs[serve] = [(t, m) for t, _ns, m in read_messages(run_dir, ["/spikes/dcn", "/spikes/pc"])]
    assert len(logs[True]) > 100 and sum(len(m["indices"]) for _t, m in logs[True]) > 0
    assert logs[True] == logs[False]
    assert len(served) > 10  # the server's chunks (the network thread's run none)
