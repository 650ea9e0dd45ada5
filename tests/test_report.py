"""The report re-plots runs from their logs only, and survives missing or unreadable runs."""

from __future__ import annotations

import matplotlib.image as mpimg
import pytest

from cerebx.loop.runner import run_experiment
from cerebx.report.build import main as report_main


@pytest.fixture(scope="module")
def fixture_runs(tmp_path_factory):
    from cerebx.config import load

    root = tmp_path_factory.mktemp("runs")
    run_experiment(load(["+task=circle", "+experiment=small_snn", "trials=10"])[0], root / "snn")
    run_experiment(load(["+task=circle", "controller=pd", "trials=2", "delay=constant", "delay.total_ms=20"])[0],
                   root / "pd")
    return root


def test_report_draws_every_figure_from_logs(fixture_runs, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert report_main([str(fixture_runs / "snn"), str(fixture_runs / "pd"), str(tmp_path / "missing")]) == 0
    err = capsys.readouterr().err
    assert "missing/summary.json: no such file" in err  # one clear line; the rest is still built
    out = tmp_path / "reports"
    html = (out / "index.html").read_text()
    pngs = sorted((out / "figures").glob("*.png"))
    names = {p.name.split("_")[0] for p in pngs}
    assert {"learning", "stages", "mae", "tracking"} <= names
    for p in pngs:
        assert p.name in html
        img = mpimg.imread(p)
        assert img.ndim == 3 and img.shape[0] > 100 and img.shape[1] > 100
        assert p.with_suffix(".svg").read_text().lstrip().startswith("<?xml")
    assert (out / "paper_vs_cerebx.csv").exists() and (out / "runs.md").exists()
    assert "0.019" in html  # the paper's number beside ours
    rows = (out / "delays.csv").read_text().splitlines()
    assert len(rows) == 2 and ",constant," in rows[1] and ",20.0," in rows[1]  # realised round trip from the log
