"""Where a run's time goes (``recording.phase_times``): every second in exactly one phase, the loop's parts
timed from outside without changing what the run records."""

from __future__ import annotations

import json
import time

import pytest

from cerebx import phase_clock
from cerebx.loop.runner import run_experiment
from cerebx.phase_clock import PhaseClock
from cerebx.recording.reader import read_messages


def test_phases_nest_exclusively_and_add_up_to_the_wall_time():
    t0 = time.perf_counter()
    clock = PhaseClock("outer")
    time.sleep(0.02)
    with clock.span("coarse"):
        time.sleep(0.02)
        with clock.charge("inner"):
            time.sleep(0.03)
    report = clock.report()
    total = time.perf_counter() - t0
    wall = report["wall_s"]
    assert set(wall) == {"outer", "coarse", "inner"}
    assert wall["inner"] >= 0.03 and 0.02 <= wall["coarse"] < 0.03 + 0.02  # the inner wait is not coarse's
    assert sum(wall.values()) == pytest.approx(total, abs=2e-3)
    assert set(report["cpu_s"]) == {"coarse"}  # only coarse phases read the CPU clock


def test_background_work_is_reported_apart():
    clock = PhaseClock()
    clock.add_background("network", 0.5, 0.4)
    clock.add_background("network", 0.5, 0.4)
    assert clock.report()["background"] == {"network": {"wall_s": 1.0, "cpu_s": 0.8, "count": 2}}


def test_no_active_clock_costs_a_shared_no_op():
    phase_clock.activate(None)
    assert phase_clock.span("x") is phase_clock.charge("y")


@pytest.mark.integration
def test_a_timed_run_records_the_same_data_and_says_where_its_time_went(tmp_path, load):
    runs = {}
    for timed in (False, True):
        run_dir = tmp_path / str(timed)
        cfg = load(["+experiment=demo", "trials=3", "recording.checkpoint_every=2", "recording.progress=off",
                    f"recording.phase_times={str(timed).lower()}"])
        summary = run_experiment(cfg, run_dir)
        assert summary["status"] == "completed" and summary["cpu_seconds"] > 0
        runs[timed] = (summary, list(read_messages(run_dir)))
    (plain, plain_log), (timed, timed_log) = runs[False], runs[True]
    assert "phase_times" not in plain and plain_log == timed_log
    assert timed["mae_per_trial"] == plain["mae_per_trial"]
    report = json.loads((tmp_path / "True" / "summary.json").read_text())["phase_times"]
    wall = report["wall_s"]
    assert {"build", "plant", "brain", "robot", "recording", "loop", "checkpoint", "summary", "finish"} <= set(wall)
    assert sum(wall.values()) == pytest.approx(timed["wall_seconds"], rel=0.05)
    assert phase_clock.active() is None  # the run leaves no clock behind
