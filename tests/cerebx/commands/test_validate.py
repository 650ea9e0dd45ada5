"""``cerebx validate`` refuses what ``cerebx run`` refuses, with the same one line (exit code 2, nothing written),
accepts what run accepts (``-m``, ``--config-dir``), and says the real cause of a mistyped command line."""

from __future__ import annotations

from pathlib import Path

import pytest

from cerebx.cli import main

DEMO = ["+experiment=demo"]

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
