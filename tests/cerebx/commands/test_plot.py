"""``cerebx plot RUN_DIR``: the learning curve and per-joint errors of a run as a PNG; a bad path is one line."""

from __future__ import annotations

import pytest

from cerebx.cli import main

PNG = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    """Three trials of the PD demo on the two-joint planar arm."""
    folder = tmp_path_factory.mktemp("plot") / "run"
    assert main(["run", "+experiment=demo", "trials=3", f"hydra.run.dir={folder}", "recording.progress=off"]) == 0
    return folder


@pytest.mark.integration
def test_the_learning_curve_is_drawn(short_run, tmp_path, capsys):
    out = tmp_path / "figs" / "curve.png"
    assert main(["plot", str(short_run), "--out", str(out)]) == 0
    assert capsys.readouterr().out.strip() == str(out)
    assert out.read_bytes()[:8] == PNG and out.stat().st_size > 10_000
    assert main(["plot", str(short_run)]) == 0
    assert (short_run / "learning_curve.png").read_bytes()[:8] == PNG


@pytest.mark.parametrize(("args", "line"), [
    (["nowhere"], "nowhere: no such run folder"),
    (["."], "summary.json: no such file (not a cerebx run folder?)"),
    ([], "cerebx plot: the following arguments are required: run_dir"),
])
def test_a_bad_path_is_one_line(args, line, in_tmp, capsys):
    assert main(["plot", *args]) == 2
    assert capsys.readouterr().err.strip() == line
