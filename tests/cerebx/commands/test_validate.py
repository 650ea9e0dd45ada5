"""``cerebx validate`` refuses what ``cerebx run`` refuses, with the same one line (exit code 2, nothing written),
accepts what run accepts (``-m``, ``--config-dir``), and says the real cause of a mistyped command line."""

from __future__ import annotations

from pathlib import Path
from typing import ClassVar, Literal

import pytest

from cerebx import registry
from cerebx.cli import main
from cerebx.registry import Entry
from cerebx.schema.base import Strict

DEMO = ["+experiment=demo"]
PLASTIC_ONE_TO_ONE = ["+task=circle", "+controller.network.projections.pc_dcn.plasticity={kind: kernel_stdp, "
                      "teacher: cf_dcn_ampa}", "+controller.network.projections.pc_dcn.weight_range_nS=[0,5]"]

REFUSED = [
    # a group that is not in the defaults list needs a '+' (not: "chosen inside another option")
    (["task=circle"], "task: not in the defaults list; add it with +task=circle"),
    (["experiment=demo"], "experiment: not in the defaults list; add it with +experiment=demo"),
    (["+task=circle", "controller=pd", "network=small"],
     "network: none of the chosen options takes a network; it comes with controller=snn"),
    # typos name the closest known names
    (["+task=circle", "contoller=pd"], "contoller: no config group or key of that name; did you mean controller?"),
    (["+task=circle", "trails=3"], "trails: no config group or key of that name; did you mean trials?"),
    (["+task=circle", "controller=pd", "controller.kpp=5"], "controller.kpp: unknown key; did you mean kp?"),
    (["+task=circle", "controller=pd", "+controller.kpp=5"], "controller.kpp: unknown key; did you mean kp?"),
    (["+task=circle", "+plant.colour=red"], "plant.colour: unknown key"),
    (["+task=circle", "contoller.kp=5"], "contoller: unknown key; did you mean controller?"),
    (["+task=circle", "+trails=3"], "trails: unknown key; did you mean trials?"),
    (DEMO + ["seed=1,2"], "seed: several values (1,2): add -m to sweep them"),
    # accepted by validate, then failed in run, before
    (DEMO + ["delay=trace", "delay.path=nowhere.csv"], "delay.path: no such file 'nowhere.csv' (looked in "),
    (PLASTIC_ONE_TO_ONE, "controller.network.projections.pc_dcn: plasticity is supported on all_to_all "
                         "projections only"),
    # an output folder that is no new or run folder
    (DEMO + ["hydra.run.dir="], "hydra.run.dir: empty; give a new folder, e.g. runs/mine"),
    (DEMO + ["hydra.run.dir=."], "hydra.run.dir: .: is the working directory; give a new folder"),
    (DEMO + ["hydra.run.dir=src"], "hydra.run.dir: src: is an existing folder that holds no run; give a new folder"),
    (DEMO + [f"hydra.run.dir={Path(__file__).resolve().parents[3]}"], "hydra.run.dir: "),
]


def _refused_alike(overrides: list[str], folder: Path, capsys) -> str:
    """``validate`` and ``run`` both exit 2 with the same single line, and write nothing in ``folder``."""
    before = sorted(folder.rglob("*"))
    assert main(["validate", *overrides]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert main(["run", *overrides]) == 2
    assert capsys.readouterr().err.strip().splitlines() == err
    assert sorted(folder.rglob("*")) == before
    return err[0]


@pytest.mark.parametrize(("overrides", "expected"), REFUSED, ids=[e for _, e in REFUSED])
def test_validate_refuses_what_run_refuses_in_one_line(overrides, expected, in_tmp, capsys):
    (in_tmp / "src" / "pkg").mkdir(parents=True)
    (in_tmp / "src" / "pkg" / "__init__.py").write_text("")
    assert _refused_alike(overrides, in_tmp, capsys).startswith(expected)


def test_the_repository_root_is_no_run_folder(in_tmp, capsys):
    root = Path(__file__).resolve().parents[3]
    line = _refused_alike([*DEMO, f"hydra.run.dir={root}"], in_tmp, capsys)
    assert line == f"hydra.run.dir: {root}: is the cerebx source checkout; give a new folder, e.g. runs/mine"


@pytest.mark.parametrize("content", [None, "job.log", "summary.json", ".hydra"])
def test_a_new_empty_or_run_folder_is_accepted(content, in_tmp, capsys):
    """The report writes a job's log into its folder before it starts the run; resume reuses a run's folder."""
    folder = in_tmp / "job"
    if content:
        folder.mkdir()
        (folder / content).write_text("")
    assert main(["validate", *DEMO, f"hydra.run.dir={folder}"]) == 0


@pytest.mark.parametrize("multirun", [False, True])
def test_the_default_run_folder_is_accepted_beside_other_files_in_runs(multirun, in_tmp, capsys):
    """Each run makes a folder of its own below runs/ (runs/<date>/<time>_<task>), so runs/ may hold anything:
    a checkout's runs/.gitkeep, a link to a disk with more room."""
    (in_tmp / "runs" / "multirun").mkdir(parents=True)
    (in_tmp / "runs" / ".gitkeep").write_text("")
    (in_tmp / "runs" / "multirun" / "notes.txt").write_text("")
    assert main(["validate", *(["-m"] if multirun else []), *DEMO]) == 0


def test_a_sweep_cut_short_may_go_on_in_its_folder(in_tmp, capsys):
    """A sweep stopped before Hydra wrote multirun.yaml leaves its jobs' folders and the report's study.log."""
    sweep = in_tmp / "sweep"
    (sweep / "delay.total_ms=40" / ".hydra").mkdir(parents=True)
    (sweep / "study.log").write_text("")
    assert main(["validate", "-m", *DEMO, f"hydra.sweep.dir={sweep}"]) == 0
    (sweep / "notes.txt").write_text("")
    assert main(["validate", "-m", *DEMO, f"hydra.sweep.dir={sweep}"]) == 2


def test_multirun_validates_every_job(in_tmp, capsys):
    assert main(["validate", "-m", *DEMO, "seed=1,2"]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert out == [f"# [+experiment=demo seed={s}] valid: task=joint_sine controller=pd plant=planar2 delay=none"
                   for s in (1, 2)]
    assert main(["validate", *DEMO, "--multirun", "plant.physics_dt_ms=0.5,0.3"]) == 2
    assert capsys.readouterr().err.strip() == ("[+experiment=demo plant.physics_dt_ms=0.3] plant.physics_dt_ms: 0.3 ms "
                                               "does not divide the 2.0 ms control step")


def test_a_config_dir_is_searched_as_run_searches_it(in_tmp, capsys):
    presets = in_tmp / "presets" / "experiment"
    presets.mkdir(parents=True)
    (presets / "mine.yaml").write_text("# @package _global_\ndefaults:\n  - /task: joint_sine\n"
                                       "  - override /plant: planar2\n  - override /controller: pd_planar2\nseed: 7\n")
    for flags in (["--config-dir", "presets"], ["-cd", "presets"], ["--config-dir=presets"]):
        assert main(["validate", *flags, "+experiment=mine"]) == 0
        assert "\nseed: 7\n" in capsys.readouterr().out
    assert main(["validate", "+experiment=mine"]) == 2
    assert capsys.readouterr().err.startswith("experiment: unknown option 'mine'")
    line = _refused_alike(["--config-dir", "presets", "+experiment=mine", "trials=0"], in_tmp, capsys)
    assert line == "trials: Input should be greater than or equal to 1"


def test_a_wrong_flag_is_one_line(capsys):
    assert main(["validate", *DEMO, "--bogus"]) == 2
    assert capsys.readouterr().err.strip() == "cerebx validate: unrecognized arguments: --bogus"


class NoRangesEncoder(Strict):
    """A plugin's mossy encoder that forgot the ``ranges`` field the spiking controller reads."""

    role: ClassVar[str] = "mossy"
    kind: Literal["no_ranges"] = "no_ranges"
    fibers_per_signal: int = 10


def test_a_mossy_encoder_without_ranges_is_refused(monkeypatch, in_tmp, capsys):
    monkeypatch.setitem(registry.encoders._entries, "no_ranges",
                        Entry("no_ranges", NoRangesEncoder, "cerebx.snn.encoders:MossyEncoder", "test"))
    line = _refused_alike(["+task=circle", "~controller.mf", "+controller.mf={kind: no_ranges}"], in_tmp, capsys)
    assert line.startswith("controller.mf: encoder kind 'no_ranges' has no 'ranges' field")


def test_the_plasticity_check_is_the_network_engines(load):
    """validate refuses with the very line the network engine would stop the run with."""
    from cerebx.snn.topology import build_topology

    net = load(["+task=circle", "+experiment=small_snn"]).controller.network
    pc_dcn = net.projections["pc_dcn"].model_copy(update={
        "plasticity": net.projections["pf_pc"].plasticity.model_copy(update={"teacher": "cf_dcn_ampa"}),
        "weight_range_nS": (0.0, 5.0)})
    unchecked = net.model_copy(update={"projections": {**net.projections, "pc_dcn": pc_dcn}})
    with pytest.raises(ValueError, match="^projections.pc_dcn: plasticity is supported on all_to_all projections "
                                         "only$"):
        build_topology(unchecked, fill=False)


@pytest.mark.integration
def test_the_shipped_delay_trace_runs_from_any_folder(in_tmp, capsys):
    import json

    assert main(["validate", *DEMO, "delay=trace"]) == 0
    assert main(["run", *DEMO, "delay=trace", "trials=1", "hydra.run.dir=r", "recording.progress=off"]) == 0
    summary = json.loads((in_tmp / "r" / "summary.json").read_text())
    assert (summary["status"], summary["delay"]) == ("completed", "trace")
