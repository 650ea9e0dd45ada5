"""Human interaction on the learned circle (thesis §2.3.1, Fig. 2.10): the push and grab events as the
report measures them."""

from __future__ import annotations

import pytest

from cerebx.config import compose_with_choices, to_plain
from cerebx.loop.runner import run_experiment
from cerebx.report.runs import Run
from cerebx.schema.experiment import validate
from cerebx_thesis.report.adaptation import interaction_metrics


@pytest.fixture(scope="module")
def pd_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("interaction") / "pd"
    ov = ["+experiment=human_interaction", "controller=pd", "trials=7", "warmup_trials=1",
          "events.0.at_trial=2", "events.1.at_trial=4"]
    cfg, choices = compose_with_choices(ov)
    plain = to_plain(cfg)
    assert run_experiment(validate(plain), out, plain, overrides=ov, choices=choices)["status"] == "completed"
    return Run.load(out)


def test_push_and_grab_are_measured(pd_run):
    push, grab = interaction_metrics(pd_run)
    assert push["kind"] == "finger_push" and grab["kind"] == "grab"
    assert push["force_N"] == pytest.approx(4.0, abs=0.01)  # the half sine's peak, sampled every 2 ms
    # the grab spring (50 N/m) stretches at most by the drag (15 cm) plus the circle's diameter (the
    # hand keeps following its path) and a little: it pulls, with a few newtons to ~20 N
    assert 1.0 < grab["force_N"] < 50.0 * (0.15 + 0.24 + 0.02)
    for m in (push, grab):
        assert m["displacement_mm"] > 1.0
        assert m["mm_per_N"] == pytest.approx(m["displacement_mm"] / m["force_N"])
        before, *_, two_after = m["mae_trials"]
        assert two_after == pytest.approx(before, rel=0.05)  # PD is back on its (periodic) path
    assert push["end_mm"] < 0.1 * push["displacement_mm"]

