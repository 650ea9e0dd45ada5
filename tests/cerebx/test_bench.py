"""``cerebx bench``'s learning runs: a run timed as users run it, with its phases, next to its closed loop."""

from __future__ import annotations

import pytest

from cerebx import registry
from cerebx.bench_learning import bench_learning, closed_loop, learning_run
from cerebx.errors import CerebxError


def test_an_unknown_learning_run_is_one_line():
    with pytest.raises(CerebxError, match="unknown learning run 'nope'"):
        bench_learning(["nope"], trials=1, rounds=1, seconds=1.0, warmup=0.5)


def test_a_learning_run_name_is_registered_once():
    registry.load_plugins()
    name = next(iter(registry.bench_runs))
    with pytest.raises(ValueError, match="already registered"):
        registry.add_bench_run(name, ["+experiment=demo"])


@pytest.mark.integration
def test_a_timed_learning_run_reports_factors_and_phases(tmp_path):
    run = learning_run(["+experiment=demo"], trials=3, run_dir=tmp_path / "run", timed=True)
    assert run["sim_s"] > 0 and run["rt_factor"] > 0 and run["cpu_rt_factor"] > 0
    assert run["process_wall_s"] > run["run_wall_s"] and run["startup_s"] > 0
    assert {"plant", "recording", "loop"} <= set(run["phase_times"]["wall_s"])
    loop = closed_loop(["+experiment=demo"], seconds=1.0, warmup=0.5)
    assert loop["rt_factor"] > 0 and loop["cpu_rt_factor"] > 0


def test_the_report_says_how_busy_the_host_was_and_the_vector_width(monkeypatch):
    from cerebx import bench_cli

    monkeypatch.setattr(bench_cli, "_plant_pd", lambda seconds: {})
    report = bench_cli.main(["--networks", "", "--learning", ""])
    assert report["vector_bits"] in (256, 512)
    for when in ("start", "end"):
        load = report["load_average"][when]
        assert len(load) == 3 and all(isinstance(x, float) and x >= 0 for x in load)
