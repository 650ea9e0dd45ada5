"""The platform runs without any paper, and the papers reach it only through the ``cerebx.plugins`` entry
point, as a third party's package would."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from importlib.metadata import entry_points
from pathlib import Path

import pytest

from cerebx import registry

ROOT = Path(__file__).resolve().parents[2]
PAPERS = {"thesis": "cerebx_thesis", "luque2011": "cerebx_luque2011", "capolei2020": "cerebx_capolei2020"}

CORE_ONLY = r"""
import json, sys
from cerebx import registry
from cerebx.config import load
from cerebx.errors import ConfigError
from cerebx.loop.runner import run_experiment

out = {"plugins": registry.loaded_plugins(), "status": {}}
for name, overrides in {"pd": ["+task=circle", "controller=pd"],
                        "snn": ["+task=circle", "+experiment=small_snn"]}.items():
    cfg, plain = load([*overrides, "trials=1", "recording.progress=off"])
    out["status"][name] = run_experiment(cfg, sys.argv[1] + "/" + name, plain)["status"]
try:
    load(["+task=circle", "+experiment=learn_circle"])
    out["paper_preset"] = "accepted"
except ConfigError as err:
    out["paper_preset"] = err.problems[0]
out["paper_modules"] = sorted(m for m in sys.modules if m.split(".")[0].startswith("cerebx_"))
print(json.dumps(out))
"""


@pytest.mark.integration
def test_a_pd_and_an_snn_experiment_run_with_no_paper_plugin(tmp_path):
    env = {**os.environ, registry.ONLY_ENV: "core"}
    done = subprocess.run([sys.executable, "-c", CORE_ONLY, str(tmp_path)], capture_output=True, text=True, env=env,
                          cwd=tmp_path, timeout=600)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout.strip().splitlines()[-1])
    assert out["plugins"] == ["core"]
    assert out["status"] == {"pd": "completed", "snn": "completed"}
    assert out["paper_modules"] == []
    assert out["paper_preset"].startswith("experiment: unknown option 'learn_circle'")


def test_the_papers_are_plugins_on_the_public_entry_point():
    eps = {ep.name: ep.value for ep in entry_points(group=registry.ENTRY_POINTS)}
    assert eps["core"] == "cerebx.builtin:register"
    for name, package in PAPERS.items():
        assert eps[name] == f"{package}:register"
    registry.load_plugins()
    by_plugin = {e.plugin for g in registry.GROUPS.values() for e in g._entries.values()}
    assert by_plugin == {"core", *PAPERS}
    assert registry.controllers["ann"].plugin == "thesis"
    assert registry.plants["lwr3"].plugin == "luque2011" and registry.plants["icub_wrist"].plugin == "capolei2020"
    assert {s.plugin for s in registry.config_sources} == set(PAPERS)


def test_no_platform_module_names_a_paper_package():
    """The import contract checks imports; this also catches a paper named by string (e.g. a builder path)."""
    offenders = [f"{p.relative_to(ROOT)}:{i}" for p in (ROOT / "src" / "cerebx").rglob("*.py")
                 for i, line in enumerate(p.read_text().splitlines(), 1)
                 if any(pkg in line for pkg in PAPERS.values())]
    assert offenders == []
