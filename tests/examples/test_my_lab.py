"""The how-tos "add a plant", "add a stage", "add a task" and "add a figure or study" (examples/my_lab, shown in
the docs) work as written: a package that cerebx finds through its entry point, whose pendulum, rate limiter and
swing task run together, keep the plant and stage contracts, and whose figure is drawn by `cerebx report` from
the study it declares. The package is made visible as pip would install it (a dist-info folder with its entry
points), and every command runs in a subprocess, so nothing of it leaks into the other tests."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest
from installed_plugin import plugin_env, run_python

from cerebx.recording.reader import read_messages

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "my_lab"


@pytest.fixture(scope="module")
def env(tmp_path_factory) -> dict[str, str]:
    return plugin_env(tmp_path_factory.mktemp("site"), "my_lab")


def test_the_pendulum_swings_through_the_rate_limiter(env, tmp_path):
    payload = "events=[{at_trial: 2, action: {kind: attach_payload, mass_kg: 0.5}}]"
    done = run_python(env, tmp_path, "-m", "cerebx", "run", "+experiment=pendulum_demo", "trials=4", payload,
                "hydra.run.dir=demo")
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "demo" / "summary.json").read_text())
    assert (summary["status"], summary["plant"], summary["task"]) == ("completed", "pendulum", "swing")
    mae = summary["mae_per_trial"]
    assert mae[0] < 0.1 and min(mae[2:]) > 1.3 * max(mae[:2])  # PD sags under the object the bob picks up
    control = [m for _, _, m in read_messages(tmp_path / "demo", ["/control"])]
    assert len(control) == 4000 and len(control[0]["tau_rate_cut"]) == 1  # the stage's record() in the log
    labels = {m["label"] for _, _, m in read_messages(tmp_path / "demo", ["/trial_metrics"])}
    assert labels <= {"target 0", "target 1", "target 2"}


def test_a_task_that_does_not_fit_is_refused_in_one_line(env, tmp_path):
    done = run_python(env, tmp_path, "-m", "cerebx", "validate", "+experiment=pendulum_demo", "task.move_s=1.2")
    assert done.returncode == 2
    assert done.stderr.strip() == "task.move_s: two movements of 1.2 s do not fit in period_s 2.0 s"


def test_the_plant_and_the_stages_keep_their_contracts(env, tmp_path):
    done = run_python(env, tmp_path, str(EXAMPLE / "check_contracts.py"))
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "pendulum, pd and ['hold', 'rate_limit'] keep their contracts"


def test_the_report_draws_the_figure_from_its_study(env, tmp_path):
    listed = run_python(env, tmp_path, "-m", "cerebx", "report", "--list")
    assert "my_lab_rate_limit" in listed.stdout and "studies: my_lab_rate_limits" in listed.stdout
    done = run_python(env, tmp_path, "-m", "cerebx", "report", "--profile", "quick", "--figures", "my_lab_rate_limit")
    assert done.returncode == 0, done.stdout + done.stderr
    assert (tmp_path / "reports" / "figures" / "my_lab_rate_limit.png").stat().st_size > 10_000
    assert len(list((tmp_path / "runs" / "report" / "quick" / "my_lab_rate_limits").glob("*/summary.json"))) == 4
    rows = list(csv.reader((tmp_path / "reports" / "paper_vs_cerebx.csv").open()))
    assert ["my_lab_rate_limit", "the error falls as the limit loosens", "yes", "yes"] in [r[:4] for r in rows]
    again = run_python(env, tmp_path, "-m", "cerebx", "report", "--profile", "quick", "--figures", "my_lab_rate_limit")
    assert "2 multiruns, 2 reused, 0 to run" in again.stdout  # finished runs are reused (the sweep's two parts)
