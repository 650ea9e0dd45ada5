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


def test_a_plugin_that_fails_to_load_is_one_line_naming_it(monkeypatch):
    from importlib.metadata import EntryPoint

    from cerebx.errors import CerebxError

    broken = EntryPoint(name="broken_lab", value="broken_lab_not_installed:register", group=registry.ENTRY_POINTS)
    monkeypatch.setattr(registry, "entry_points", lambda group: [broken])
    monkeypatch.setattr(registry, "_done", False)
    monkeypatch.setattr(registry, "_broken", None)
    monkeypatch.setattr(registry, "_loaded", [])
    expected = ("plugin broken_lab (broken_lab_not_installed:register): ModuleNotFoundError: No module named "
                "'broken_lab_not_installed' (uninstall it, or load only the others: CEREBX_PLUGINS=)")
    for _ in range(2):  # every later use says it again
        with pytest.raises(CerebxError) as err:
            registry.load_plugins()
        assert str(err.value) == expected


BROKEN = "def register():\n    raise RuntimeError('the lab key\\nis missing')\n"


@pytest.mark.integration
@pytest.mark.parametrize("command", [["validate", "+task=circle"], ["run", "+experiment=demo", "trials=1"],
                                     ["report", "--list"], ["run", "--help"]])
def test_every_command_says_which_plugin_is_broken_in_one_line(command, tmp_path):
    info = tmp_path / "broken_lab-0.1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: broken-lab\nVersion: 0.1.0\n")
    (info / "entry_points.txt").write_text("[cerebx.plugins]\nbroken_lab = broken_lab:register\n")
    (tmp_path / "broken_lab.py").write_text(BROKEN)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(tmp_path), os.environ.get("PYTHONPATH")]))}
    done = subprocess.run([sys.executable, "-m", "cerebx", *command], capture_output=True, text=True, env=env,
                          cwd=tmp_path, timeout=600)
    assert done.returncode == 2
    assert done.stderr.strip().splitlines() == [
        "plugin broken_lab (broken_lab:register): RuntimeError: the lab key (uninstall it, or load only the others: "
        "CEREBX_PLUGINS=core,capolei2020,luque2011,thesis)"]
    assert not (tmp_path / "runs").exists()
