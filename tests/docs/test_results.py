"""The published report in docs/results: every registered figure is published and shown on its paper's
reproduction page, the published files are exactly what the publishing step makes from the report they came
from, and the publishing step turns a report built from synthetic runs into the expected snippets."""

from __future__ import annotations

import csv
import importlib.util
import json
import re
import time
from pathlib import Path

import matplotlib.pyplot as plt
import pytest

from cerebx.report.build import build
from cerebx.report.plot import save
from cerebx.report.registry import FIGURES, Figure, FigureSpec, all_figures

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "docs" / "results"
PAGES = ROOT / "docs" / "reproductions"
# the reproduction page of each plugin package; the thesis's figures go to the chapter their name carries
PAGE_OF_PACKAGE = {"cerebx_luque2011": "luque2011.md", "cerebx_capolei2020": "capolei2020.md"}
MACHINE_PATH = re.compile(r"(?<![\w.~])/(?:work|tmp|home|root|Users|mnt|opt|var)/")


def _publisher():
    spec = importlib.util.spec_from_file_location("publish_report", ROOT / "scripts" / "publish_report.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


publisher = _publisher()


def _published() -> dict:
    return json.loads((RESULTS / "figures.json").read_text())


def _page_of(spec: FigureSpec) -> list[str]:
    """The page(s) a figure belongs on: its plugin's page; a thesis figure on its chapter's page (one without a
    chapter number, a study of the thesis that is no figure of it, on any thesis page)."""
    package = spec.draw.__module__.split(".")[0]
    if package == "cerebx_thesis":
        chapter = re.search(r"(\d)_", spec.name)
        return [f"thesis-ch{chapter.group(1)}.md"] if chapter else [p.name for p in PAGES.glob("thesis-ch*.md")]
    assert package in PAGE_OF_PACKAGE, f"{spec.name}: figures of {package} have no reproduction page (add one)"
    return [PAGE_OF_PACKAGE[package]]


def test_every_registered_figure_is_published_and_on_its_page():
    published = {e["name"]: e for e in _published()["figures"]}
    pages = {p.name: p.read_text() for p in PAGES.glob("*.md")}
    for name, spec in all_figures().items():
        assert name in published, f"{name}: not in docs/results (publish a report that draws it)"
        assert (RESULTS / f"{name}.md").is_file(), f"{name}: docs/results/{name}.md missing"
        for f in published[name]["files"]:
            assert (RESULTS / "figures" / Path(f).name).is_file(), f"{name}: image {f} not published"
        include = f'--8<-- "docs/results/{name}.md"'
        on = [page for page, text in pages.items() if include in text]
        assert len(on) == 1, f"{name}: included on {on or 'no page'}; it belongs on one of {_page_of(spec)}"
        assert on[0] in _page_of(spec), f"{name}: on {on[0]}, but it belongs on one of {_page_of(spec)}"
        assert re.search(rf"^#+ .*\{{ *#{name} *\}}", pages[on[0]], re.M), f"{name}: no heading {{ #{name} }}"
        assert f"#{name})" in pages["index.md"], f"{name}: not linked from the reproductions index"


def test_published_files_are_what_the_publishing_step_makes_of_their_report():
    report = _published()
    expected = publisher.render(report, pages=publisher.reproduction_pages(PAGES))
    assert expected["figures.json"] == (RESULTS / "figures.json").read_text()
    for name, text in expected.items():
        assert (RESULTS / name).read_text() == text, f"docs/results/{name} differs from its report: publish again"
    made_by_hand = {p.name for p in RESULTS.glob("*") if p.is_file()} - set(expected)
    assert not made_by_hand, f"docs/results holds files the publishing step does not make: {made_by_hand}"
    images = {Path(f).name for e in report["figures"] for f in e["files"]}
    assert {p.name for p in (RESULTS / "figures").iterdir()} == images


def test_pages_describe_the_profile_that_is_published():
    """A page's "published runs (P profile)" names the published report's profile, or the profile a figure kept
    from an earlier report came from (its runs in the new profile not finished)."""
    published = _published()
    profiles = {published["profile"]} | {e["kept_from"]["profile"] for e in published["figures"] if e.get("kept_from")}
    for page in PAGES.glob("*.md"):
        for said in re.findall(r"published runs \((\w+) profile\)", page.read_text()):
            assert said in profiles, f"{page.name} describes {said}-profile runs; docs/results holds {profiles}"


def test_no_machine_path_in_the_published_results_or_the_pages():
    for path in [*RESULTS.glob("*.md"), RESULTS / "figures.json", *PAGES.glob("*.md")]:
        hit = MACHINE_PATH.search(path.read_text())
        assert hit is None, f"{path.relative_to(ROOT)}: machine path at {hit.start()}"


def _synthetic_runs(root: Path, started: list[float]) -> list[Path]:
    dirs = []
    for i, t in enumerate(started):
        d = root / "runs" / "report" / "quick" / "toy_study" / f"seed={i}"
        d.mkdir(parents=True)
        (d / "summary.json").write_text(json.dumps({
            "status": "completed", "task": "circle", "controller": "pd", "plant": "baxter", "delay": "none",
            "seed": i, "trials": 3, "trials_completed": 0, "mae_per_trial": [0.3, 0.2, 0.1 + i / 100],
            "final_mae": 0.1 + i / 100, "sim_seconds": 6.0, "wall_seconds": 1.0, "started_at": t,
            "version": "0.0.toy"}))
        dirs.append(d)
    return dirs


def _toy_figure(runs, stem: Path) -> Figure:
    fig, ax = plt.subplots()
    ax.plot([r.summary["final_mae"] for r in runs])
    rows = [["quantity", "paper", "cerebx", "runs"], ["final MAE | mean (rad)", "0.1", "0.11", str(len(runs))],
            ["a row <shorter>", "–"]]
    return Figure([save(fig, stem)], "Toy caption with *stars* and a <tag>.", rows, ["a note"])


@pytest.mark.integration
def test_publishing_a_report_built_from_synthetic_runs(tmp_path, monkeypatch):
    started = [time.mktime((2025, 3, 1, 12, 0, 0, 0, 0, -1)), time.mktime((2025, 3, 4, 12, 0, 0, 0, 0, -1))]
    dirs = _synthetic_runs(tmp_path, started)
    all_figures()  # the plugins' figures first, so the toy one is not overwritten by their registration
    monkeypatch.setitem(FIGURES, "toy_fig1", FigureSpec("toy_fig1", "Toy figure", ("toy_study",), _toy_figure))
    report = tmp_path / "reports"
    command = f"cerebx report {tmp_path}/runs/report/quick --figures=toy_fig1 --out {report}"
    build(dirs, report, ["toy_fig1"], command=command)

    made = json.loads((report / "figures.json").read_text())
    assert made["profile"] == "quick" and made["runs"]["count"] == 2 and made["runs"]["versions"] == ["0.0.toy"]
    assert (made["runs"]["first_started_at"][:10], made["runs"]["last_started_at"][:10]) == ("2025-03-01", "2025-03-04")
    (entry,) = made["figures"]
    assert entry["files"] == ["figures/toy_fig1.png"] and entry["studies"] == ["toy_study"]
    # a newer report may add fields to a figure and columns to its CSV tables: both are carried along
    entry["converged"] = False
    (report / "figures.json").write_text(json.dumps(made))
    with open(report / "paper_vs_cerebx.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    with open(report / "paper_vs_cerebx.csv", "w", newline="") as fh:
        csv.writer(fh).writerows([[*r, "extra"] for r in rows])

    out = tmp_path / "docs" / "results"
    assert publisher.publish(report, out) == ["toy_fig1"]
    snippet = (out / "toy_fig1.md").read_text()
    assert "| quantity | paper | cerebx | runs |\n|---|---|---|---|\n" in snippet
    assert "| final MAE \\| mean (rad) | 0.1 | 0.11 | 2 |\n| a row &lt;shorter> | – |  |  |\n" in snippet
    assert "[![Toy figure](../results/figures/toy_fig1.png)](../results/figures/toy_fig1.png)" in snippet
    assert "Toy caption with \\*stars\\* and a &lt;tag>." in snippet and "- a note" in snippet
    assert "- converged: False" in snippet
    stamp = (out / "stamp.md").read_text()
    assert "`cerebx report runs/report/quick --figures=toy_fig1 --out reports`" in stamp
    assert "2 runs of the quick profile" in stamp and "between 2025-03-01 and 2025-03-04" in stamp
    assert MACHINE_PATH.search(stamp + (out / "figures.json").read_text()) is None
    assert (out / "figures" / "toy_fig1.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the README's and the docs' home page's hero blocks, each with the image's path from where it lies
    readme, home = tmp_path / "README.md", tmp_path / "docs" / "index.md"
    for page in (readme, home):
        page.write_text("# x\n<!-- hero:start -->\n<!-- hero:end -->\n")
    publisher.publish(report, out, readme_path=readme, hero="toy_fig1", home_path=home)
    assert "![Toy figure](docs/results/figures/toy_fig1.png)" in readme.read_text()
    assert "![Toy figure](results/figures/toy_fig1.png)" in home.read_text()
    # publishing again gives the same files; a folder that is no published report is not replaced
    first = {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}
    publisher.publish(report, out)
    assert {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()} == first
    (tmp_path / "docs" / "page.md").write_text("mine")
    with pytest.raises(publisher.PublishError, match="not a published report"):
        publisher.publish(report, tmp_path / "docs")
    with pytest.raises(publisher.PublishError, match="figures.json: not found"):
        publisher.publish(tmp_path / "runs", tmp_path / "elsewhere")


def _entry(name: str, checks: list[dict], intervals: dict | None = None, table: list | None = None) -> dict:
    return {"name": name, "title": name, "files": [f"figures/{name}.png"], "caption": "Cap one. Cap two.",
            "table": table or [], "checks": checks, "intervals": intervals or {}}


def test_checks_pages_and_hero_are_made_from_figures_json(tmp_path):
    ok = {"claim": "SNN below PD", "holds": True, "numbers": "", "explained_at": None}
    why = {"claim": "ANN above SNN", "holds": False, "numbers": "1 vs 2",
           "explained_at": "docs/reproductions/thesis-ch3.md#fig3_4"}
    bare = {"claim": "levels off", "holds": False, "numbers": "", "explained_at": None}
    iv = {"mean": 3.5, "ci_low": 3.1, "ci_high": 3.9, "n": 3, "paper_in_ci": "yes"}
    table = [["quantity", "paper", "cerebx"], ["PD average MAE ÷ SNN average MAE", "3 to 4× larger", "3.5"],
             ["unrelated", "1", "1"], ["SNN MAE over trials 170–200 (rad)", "–", "0.06"]]
    no_paper = {"mean": 0.06, "ci_low": 0.05, "ci_high": 0.07, "n": 3, "paper_in_ci": "–"}
    report = {"profile": "full", "commit": "abc123", "built_at": "2026-11-27T12:00:00+00:00",
              "figures": [_entry("fig3_4", [ok, why], {"PD average MAE ÷ SNN average MAE": iv,
                                                       "SNN MAE over trials 170–200 (rad)": no_paper}, table),
                          _entry("fig3_3", [bare])]}
    checks = publisher.checks_markdown(report["figures"])
    assert "| `fig3_4` | 2 | 1 | 1 | 0 |" in checks and "| all | 3 | 1 | 1 | 1 |" in checks
    assert "[why](../reproductions/thesis-ch3.md#fig3_4)" in checks and "levels off (): **not explained**" in checks
    page = publisher.page_markdown(["fig3_4"], report, "../results")
    assert page.startswith("**In the published report (full profile):** 1 of 2 shape checks hold, 1 fail with")
    assert "| `fig3_4` | PD average MAE ÷ SNN average MAE | 3 to 4× larger | 3.5 [3.1, 3.9] | 3 | yes |" in page
    assert "170–200" not in page  # a quantity without a paper number stays in its figure's table
    pages = tmp_path / "pages"
    pages.mkdir()
    (pages / "ch3.md").write_text('--8<-- "docs/results/stamp.md"\n--8<-- "docs/results/fig3_4.md"\n')
    assert publisher.reproduction_pages(pages) == {"ch3": ["fig3_4"]}
    readme = tmp_path / "README.md"
    readme.write_text("# x\n<!-- hero:start -->\nold\n<!-- hero:end -->\nrest\n")
    block = publisher.hero_block(report, "fig3_4", "docs/results/figures")
    assert publisher.update_readme(readme, block)
    text = readme.read_text()
    assert "\nold\n" not in text and text.endswith("<!-- hero:end -->\nrest\n")
    assert "![fig3_4](docs/results/figures/fig3_4.png)" in text and "commit `abc123`" in text
    assert "*fig3_4 (`fig3_4`). Drawn by `cerebx report`" in text
    assert "| PD average MAE ÷ SNN average MAE | 3 to 4× larger | 3.5 |" in text and "unrelated" not in text
    assert not publisher.update_readme(pages / "ch3.md", block)  # no markers: left alone


def test_a_figure_the_new_report_does_not_draw_keeps_its_earlier_entry_marked(tmp_path):
    def report(folder: Path, profile: str, day: str, names: list[str]) -> Path:
        (folder / "figures").mkdir(parents=True)
        for n in names:
            fig, ax = plt.subplots()
            save(fig, folder / "figures" / n)
        (folder / "figures.json").write_text(json.dumps({
            "profile": profile, "built_at": f"{day}T12:00:00+00:00", "commit": "c0ffee",
            "figures": [_entry(n, [{"claim": "c", "holds": False, "numbers": "", "explained_at": None}])
                        for n in names]}))
        return folder

    out = tmp_path / "published"
    publisher.publish(report(tmp_path / "old", "quick", "2026-11-24", ["fig3_4", "fig4_6"]), out)
    publisher.publish(report(tmp_path / "new", "full", "2026-11-27", ["fig3_4"]), out, keep_missing=True)
    made = json.loads((out / "figures.json").read_text())
    assert [e["name"] for e in made["figures"]] == ["fig3_4", "fig4_6"]
    assert made["figures"][1]["kept_from"]["profile"] == "quick" and "kept_from" not in made["figures"][0]
    assert (out / "figures" / "fig4_6.png").is_file()
    assert "From an earlier report" in (out / "fig4_6.md").read_text()
    assert "`fig4_6` (quick profile, 2026-11-24)" in (out / "stamp.md").read_text()
    checks = (out / "checks.md").read_text()
    assert "| all | 1 | 0 | 0 | 1 |" in checks and "kept from an earlier report" in checks
    # published again with the same report: still kept, still marked with where it came from
    publisher.publish(tmp_path / "new", out, keep_missing=True)
    again = json.loads((out / "figures.json").read_text())
    assert again["figures"][1]["kept_from"]["built_at"].startswith("2026-11-24")
    publisher.publish(tmp_path / "new", out)  # without the flag: only what the report drew
    assert [e["name"] for e in json.loads((out / "figures.json").read_text())["figures"]] == ["fig3_4"]
