"""The how-to "add a cerebellum model" (examples/my_cerebellum, shown in the docs) works as written: a package
that cerebx finds through its entry point, whose model runs, learns, keeps its state and passes the contract
checker. The package is made visible as pip would install it (a dist-info folder with its entry points), in a
subprocess, so nothing of it leaks into the other tests."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from installed_plugin import plugin_env, run_python

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE = ROOT / "examples" / "my_cerebellum"


@pytest.fixture(scope="module")
def env(tmp_path_factory) -> dict[str, str]:
    return plugin_env(tmp_path_factory.mktemp("site"), "my_cerebellum")


def test_the_model_learns_and_starts_again_from_its_state(env, tmp_path):
    run = ("-m", "cerebx", "run", "+experiment=adaptive_filter_demo")
    first = run_python(env, tmp_path, *run, "trials=12", "hydra.run.dir=first")
    assert first.returncode == 0, first.stderr
    mae = json.loads((tmp_path / "first" / "summary.json").read_text())["mae_per_trial"]
    assert mae[-1] < 0.4 * mae[0]  # the filter takes over from the weak PD
    again = run_python(env, tmp_path, *run, "trials=2", "init_from=first", "hydra.run.dir=again")
    assert again.returncode == 0, again.stderr
    assert json.loads((tmp_path / "again" / "summary.json").read_text())["mae_per_trial"][0] < 0.5 * mae[0]
    other = run_python(env, tmp_path, *run, "init_from=first", "controller.parts.1.filters=4", "hydra.run.dir=other")
    assert other.returncode == 2
    assert other.stderr.strip().startswith("init_from: ") and "8 filters" in other.stderr
    assert not (tmp_path / "other").exists()


def test_the_model_keeps_the_stage_contract(env, tmp_path):
    code = ("from cerebx.build import build_components\nfrom cerebx.config import load\n"
            "from cerebx.stages.check import check_experiment\n"
            "cfg, _ = load(['+experiment=adaptive_filter_demo'])\n"
            "check_experiment(lambda: build_components(cfg))\nprint('ok')")
    done = run_python(env, tmp_path, "-c", code)
    assert done.returncode == 0 and done.stdout.strip() == "ok", done.stderr
