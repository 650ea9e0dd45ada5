"""The remaining runs of a profile at the pace its finished runs went, by kind of run, shared out over jobs."""

from __future__ import annotations

import json

import pytest

from cerebx.config import load
from cerebx.estimate import estimate
from cerebx.report.pace import kind_of, left_fraction, measured_pace, remaining_wall_s

pytestmark = pytest.mark.unit


def _summary(controller: str, plant: str, delay: str, sim: float, wall: float, status: str = "completed") -> dict:
    return {"controller": controller, "network": None, "plant": plant, "delay": delay, "sim_seconds": sim,
            "wall_seconds": wall, "status": status}


def test_a_run_takes_the_median_pace_of_its_kind_and_runs_share_the_machine():
    exp, _ = load(["+experiment=demo", "trials=10"])  # PD on the planar arm, 20 s simulated
    quiet = estimate(exp).wall_s
    pace = measured_pace([(_summary("pd", "planar2", "none", 20.0, 2.0), quiet),
                          (_summary("pd", "planar2", "none", 20.0, 4.0), quiet),
                          (_summary("pd", "planar2", "none", 20.0, 1.0), quiet),
                          (_summary("pd", "planar2", "constant", 20.0, 10.0), quiet),
                          (_summary("pd", "planar2", "none", 20.0, 99.0, status="failed"), quiet)])
    assert pace.runs == 4 and pace.per_kind[kind_of("pd", None, "planar2", "none")] == 10.0  # median of 10, 5, 20
    assert pace.wall_s(exp) == pytest.approx(2.0)
    assert remaining_wall_s(pace, [exp, exp, exp, exp], jobs=2) == pytest.approx(4.0)


def test_a_kind_without_finished_runs_is_the_quiet_estimate_slowed_as_the_others_were():
    exp, _ = load(["+experiment=demo", "trials=10"])
    quiet = estimate(exp).wall_s
    pace = measured_pace([(_summary("snn", "baxter", "none", 100.0, 3 * quiet), quiet)])
    assert pace.slowdown == pytest.approx(3.0)
    assert pace.wall_s(exp) == pytest.approx(3 * quiet)


def test_a_run_resumed_from_a_checkpoint_counts_only_its_trials_left(tmp_path):
    exp, _ = load(["+experiment=demo", "trials=10"])
    pace = measured_pace([(_summary("pd", "planar2", "none", 20.0, 5.0), 0.0)])
    assert left_fraction(tmp_path, 10) == 1.0  # no checkpoint
    (tmp_path / "checkpoint.pkl.json").write_text(json.dumps({"trials_done": 7}))
    f = left_fraction(tmp_path, 10)
    assert f == pytest.approx(0.3)
    assert remaining_wall_s(pace, [exp, exp], jobs=1, left=[f, 1.0]) == pytest.approx(1.5 + 5.0)
    (tmp_path / "checkpoint.pkl.json").write_text("not json")
    assert left_fraction(tmp_path, 10) == 1.0


def test_the_dry_run_says_which_studies_take_the_time():
    """Seeds of a study count together; the shares are of the CPU when runs share the cores, of the wall time
    one at a time; the times add up to the whole estimate."""
    from cerebx.estimate import Estimate, total
    from cerebx.report.build import where_the_time_goes

    snn = Estimate(1000.0, 0.0, 0.0, wall_s=60.0, cpu_s=120.0)  # two threads
    pd = Estimate(1000.0, 0.0, 0.0, wall_s=40.0, cpu_s=40.0)  # one thread
    studies = ["learn", "learn~seed1", "learn~seed2", "baseline"]
    ests = [snn, snn, snn, pd]
    assert total(ests, 2).wall_s == pytest.approx(200.0)  # (3 x 120 + 40) s of CPU on 2 cores
    line = where_the_time_goes(studies, ests, 2)
    assert line == "where the time goes: learn ~3 min (90 %), baseline ~20 s (10 %)"
    assert where_the_time_goes(studies, ests, 1) == "where the time goes: learn ~3 min (82 %), baseline ~40 s (18 %)"
    assert where_the_time_goes(studies, ests, 2, top=1).endswith("; 1 other studies the rest")
