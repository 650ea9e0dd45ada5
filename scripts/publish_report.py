"""Publish a built report into the docs: per figure its images, a Markdown snippet (images, caption, the
paper's numbers beside cerebx's, notes) and a stamp saying which command drew it from which runs.

    .venv/bin/python scripts/publish_report.py REPORT_DIR --out docs/results

It reads REPORT_DIR/figures.json (written by ``cerebx report``; a report made before it existed is redrawn
from its runs without running anything: ``cerebx report RUNS --out REPORT_DIR``) and replaces OUT with:

    figures.json       the report's figures.json, the command's absolute paths shortened: what the rest is made from
    stamp.md           how the report was made: command, profile, number of runs and their dates, cerebx version
    README.md          what the folder is, with the stamp and the list of figures
    <figure>.md        one per figure: images, caption, table and notes (a page includes it with --8<--)
    figures/<f>.png    the images, PNG only, reduced to a 256-colour palette (a few MB for every figure)
    checks.md          every figure's shape checks: how many hold, fail with an explanation, fail without
    page_<page>.md     for each reproduction page (docs/reproductions/<page>.md, found by the figures it
                       includes): the table it opens with, its paper numbers beside cerebx's interval over
                       seeds (inside or not) and its figures' checks

With ``--keep-missing``, a figure the new report did not draw (its runs not finished yet) keeps its earlier
published entry and images, marked with the profile and date it came from (``kept_from``), and the stamp
lists it. It rewrites the README's hero block (between ``<!-- hero:start -->`` and ``<!-- hero:end -->``) from the
hero figure's entry (``--hero``, default fig3_4): its image, caption and the paper's ratios beside cerebx's; and
the same block of the docs' home page (``--home``, default docs/index.md).

A docs page includes a figure with ``--8<-- "docs/results/<figure>.md"`` and the stamp with
``--8<-- "docs/results/stamp.md"``; the snippets' image links are relative to the including page
(``--link-base``, default ``../results`` for pages one folder below docs/).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shlex
import shutil
import sys
from collections.abc import Iterable
from datetime import datetime
from pathlib import Path
from typing import Any

from PIL import Image

KNOWN = {"name", "title", "studies", "module", "files", "caption", "table", "notes", "checks", "intervals",
         "convergence", "kept_from"}
HERO_START, HERO_END = "<!-- hero:start -->", "<!-- hero:end -->"
# the hero table's rows: the quantities of the hero figure's table whose quantity starts with one of these
HERO_ROWS = ("PD average MAE ÷ SNN", "ANN average MAE ÷ SNN", "SNN MAE ratio", "SNN average MAE over")
PROFILE_TEXT = {
    "quick": "the quick profile (shortened trial counts, minutes to hours on two cores: not every learning curve "
             "has levelled off; `cerebx report --profile full` runs the papers' counts)",
    "full": "the full profile (the papers' trial counts)",
}


class PublishError(Exception):
    """The report cannot be published (the message says why)."""


def load_report(report_dir: Path) -> dict[str, Any]:
    path = Path(report_dir) / "figures.json"
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        raise PublishError(f"{path}: not found; redraw the report with this cerebx (`cerebx report RUNS --out "
                           f"{report_dir}` draws from the logs without running anything)") from None
    except json.JSONDecodeError as err:
        raise PublishError(f"{path}: not valid JSON ({err})") from None


def portable(command: str | None) -> str | None:
    """The command with every absolute path shortened: from its ``runs`` folder on, else to its last part."""
    if not command:
        return command
    out = []
    for token in shlex.split(command):
        key, eq, value = token.rpartition("=") if token.startswith("-") and "=" in token else ("", "", token)
        if value.startswith("/"):
            parts = Path(value).parts
            value = "/".join(parts[parts.index("runs"):]) if "runs" in parts else parts[-1]
        out.append(f"{key}{eq}{value}")
    return shlex.join(out)


def _day(iso: str | None) -> str:
    return datetime.fromisoformat(iso).date().isoformat() if iso else "unknown"


def _hours(seconds: Any) -> str:
    if not isinstance(seconds, int | float):
        return "unknown"
    return f"{seconds / 3600:.1f} h" if seconds >= 5400 else f"{seconds / 60:.0f} min"


def stamp(report: dict[str, Any]) -> str:
    """One admonition saying how the published report was made: the command, profile, date, commit, wall
    time, the runs (count, dates, versions, summed run time, size on disk)."""
    runs = report.get("runs") or {}
    first, last = _day(runs.get("first_started_at")), _day(runs.get("last_started_at"))
    dates = first if first == last else f"{first} and {last}"
    versions = ", ".join(runs.get("versions") or []) or "unknown"
    profile = report.get("profile")
    source = PROFILE_TEXT.get(profile, f"the {profile} profile" if profile else "runs given on the command line")
    commit = f", commit `{report['commit']}`" if report.get("commit") else ""
    size = f", {runs['disk_bytes'] / 1e9:.1f} GB on disk" if runs.get("disk_bytes") else ""
    took = ""
    if report.get("wall_seconds"):
        summed = f"; its runs took {_hours(runs['wall_seconds'])} summed" if runs.get("wall_seconds") else ""
        took = f" The command took {_hours(report['wall_seconds'])} of wall time{summed}."
    kept = [e for e in report.get("figures") or [] if e.get("kept_from")]
    if kept:
        names = ", ".join(f"`{e['name']}` ({e['kept_from'].get('profile')} profile, "
                          f"{_day(e['kept_from'].get('built_at'))})" for e in kept)
        took += f" Not yet in this report, so kept from an earlier one: {names}."
    return "\n".join([
        '!!! info "Where these figures and tables come from"',
        f"    `{report.get('command') or 'cerebx report'}` drew them on {_day(report.get('built_at'))} (cerebx "
        f"{report.get('cerebx_version', 'unknown')}{commit}) from {runs.get('count', 0)} runs of {source}, started "
        f"{'on' if first == last else 'between'} {dates} by cerebx {versions}{size}.{took} "
        "`scripts/publish_report.py` copied them here; none is typed by hand.",
        "",
    ])


def _cell(value: Any) -> str:
    return str(value).replace("|", "\\|").replace("<", "&lt;").replace("\n", " ")


def _text(value: Any) -> str:
    return str(value).replace("<", "&lt;").replace("*", "\\*")


def table_markdown(rows: list[list[Any]]) -> str:
    """A figure's table (header row first) as Markdown; rows shorter than the header are padded."""
    if len(rows) < 2:
        return ""
    width = max(len(r) for r in rows)
    padded = [[*map(_cell, r), *[""] * (width - len(r))] for r in rows]
    out = ["| " + " | ".join(padded[0]) + " |", "|" + "---|" * width]
    out += ["| " + " | ".join(r) + " |" for r in padded[1:]]
    return "\n".join(out) + "\n"


def _extras(entry: dict[str, Any]) -> Iterable[str]:
    """Fields a newer report adds to its figures (simple values only), one line each."""
    for key, value in entry.items():
        if key in KNOWN or value in (None, "", [], {}):
            continue
        if isinstance(value, str | int | float | bool):
            yield f"- {key.replace('_', ' ')}: {_text(value)}"
        elif isinstance(value, list) and all(isinstance(v, str | int | float | bool) for v in value):
            yield f"- {key.replace('_', ' ')}: {_text(', '.join(map(str, value)))}"


def figure_markdown(entry: dict[str, Any], report: dict[str, Any], link_base: str) -> str:
    """The snippet of one figure: images, caption, the paper-vs-cerebx table, notes and where it came from."""
    out = [f"<!-- made by scripts/publish_report.py from figures.json: {entry['name']} -->", ""]
    for f in entry.get("files") or []:
        src = f"{link_base}/figures/{Path(f).name}"
        out.append(f"[![{_text(entry['title'])}]({src})]({src})")
    out += ["", f"**{_text(entry['title'])}.** {_text(entry.get('caption', ''))}", ""]
    table = table_markdown(entry.get("table") or [])
    if table:
        out += [table]
    notes = [f"- {_text(n)}" for n in entry.get("notes") or []] + list(_extras(entry))
    if notes:
        out += [*notes, ""]
    source = entry.get("kept_from") or report
    profile = source.get("profile")
    if entry.get("kept_from"):
        out += [f"!!! warning \"From an earlier report\"\n    This figure is from the {profile} profile of "
                f"{_day(source.get('built_at'))}: its {report.get('profile')}-profile runs were not finished when "
                "this report was published.", ""]
    out += [f"<small>Studies: {', '.join(entry.get('studies') or [])}"
            f"{f' ({profile} profile)' if profile else ''}; report of {_day(source.get('built_at'))}.</small>", ""]
    return "\n".join(out)


def readme(report: dict[str, Any]) -> str:
    rows = "\n".join(f"| `{e['name']}` | {_cell(e['title'])} | {', '.join(Path(f).name for f in e.get('files') or [])} "
                     "|" for e in report.get("figures") or [])
    return "\n".join([
        "# Published report", "",
        "Made by `scripts/publish_report.py` from a `cerebx report` output; do not edit by hand, publish again. "
        "The reproduction pages (`docs/reproductions/`) include `<figure>.md` and `stamp.md` with `--8<--`.", "",
        stamp(report), "| figure | title | images |", "|---|---|---|", rows, ""])


def _checks(entry: dict[str, Any]) -> tuple[int, int, int, int]:
    """(told, held, failed and explained, failed unexplained) of a figure's shape checks."""
    told = [c for c in entry.get("checks") or [] if c.get("holds") is not None]
    failed = [c for c in told if not c["holds"]]
    explained = sum(1 for c in failed if c.get("explained_at"))
    return len(told), len(told) - len(failed), explained, len(failed) - explained


def _doc_link(at: str, link_base: str) -> str:
    """A docs-relative ``docs/<page>#anchor`` as a link from a page one folder below docs/."""
    return f"{link_base.rsplit('/', 1)[0]}/{at.removeprefix('docs/')}"


def _why(check: dict[str, Any], link_base: str) -> str:
    at = check.get("explained_at")
    return f"[why]({_doc_link(at, link_base)})" if at else "**not explained**"


def _kept_note(figures: list[dict[str, Any]]) -> list[str]:
    kept = [e for e in figures if e.get("kept_from")]
    if not kept:
        return []
    return ["", "Not counted here (kept from an earlier report, their runs not finished): "
            + ", ".join(f"`{e['name']}` ({e['kept_from'].get('profile')} profile)" for e in kept) + "."]


def checks_markdown(figures: list[dict[str, Any]], link_base: str = "../results") -> str:
    """Per figure: its checks, how many hold, and each failing one with its explanation (or none); figures
    kept from an earlier report are named, not counted."""
    note = _kept_note(figures)
    figures = [e for e in figures if not e.get("kept_from")]
    out = ["| figure | checks | hold | fail, explained | fail, not explained | converged |",
           "|---|---|---|---|---|---|"]
    totals = [0, 0, 0, 0]
    for e in figures:
        counts = _checks(e)
        totals = [a + b for a, b in zip(totals, counts, strict=True)]
        conv = e.get("convergence") or {}
        converged = "–" if not conv else ("yes" if conv.get("converged") else "no")
        out.append(f"| `{e['name']}` | {counts[0]} | {counts[1]} | {counts[2]} | {counts[3]} | {converged} |")
    out.append(f"| all | {totals[0]} | {totals[1]} | {totals[2]} | {totals[3]} | |")
    out += note
    failing = [(e["name"], c) for e in figures for c in e.get("checks") or [] if c.get("holds") is False]
    if failing:
        out += ["", "Checks that fail:", ""]
        out += [f"- `{name}`: {_text(c['claim'])} ({_text(c.get('numbers') or '')}): " + _why(c, link_base)
                for name, c in failing]
    return "\n".join(out) + "\n"


def intervals_markdown(figures: list[dict[str, Any]]) -> str:
    """The headline numbers: the paper's beside cerebx's mean and 95 % interval over seeds, and whether the
    paper's number falls inside (– with one seed). A quantity the paper gives no number for (what a figure's
    table adds to explain one) stays in its figure's table and the CSV, not here."""
    rows = [(e["name"], q, iv, next((r[1] for r in e.get("table") or [] if r and r[0] == q), "–"))
            for e in figures if not e.get("kept_from") for q, iv in (e.get("intervals") or {}).items()]
    rows = [row for row in rows if row[3] != "–"]
    if not rows:
        return ""
    out = ["| figure | quantity | paper | cerebx, mean [95 % interval] | seeds | paper inside |",
           "|---|---|---|---|---|---|"]
    for name, q, iv, paper in rows:
        lo, hi = iv.get("ci_low"), iv.get("ci_high")
        ci = f"{iv['mean']:.4g} [{lo:.4g}, {hi:.4g}]" if lo is not None and hi is not None else f"{iv['mean']:.4g}"
        out.append(f"| `{name}` | {_cell(q)} | {_cell(paper)} | {ci} | {iv.get('n', 1)} "
                   f"| {iv.get('paper_in_ci', '–')} |")
    inside = sum(1 for *_, iv, _p in rows if iv.get("paper_in_ci") == "yes")
    judged = sum(1 for *_, iv, _p in rows if iv.get("paper_in_ci") in ("yes", "no"))
    return "\n".join(out) + f"\n\nThe paper's number falls inside cerebx's interval in {inside} of {judged} rows " \
        "that have both.\n"


INCLUDE = re.compile(r'--8<-- "docs/results/([\w-]+)\.md"')


def reproduction_pages(pages_dir: Path) -> dict[str, list[str]]:
    """Each reproduction page's stem and the figures it includes (in order)."""
    out: dict[str, list[str]] = {}
    for page in sorted(Path(pages_dir).glob("*.md")):
        names = [n for n in INCLUDE.findall(page.read_text())
                 if n not in ("stamp", "checks") and not n.startswith("page_")]
        if names:
            out[page.stem] = names
    return out


def page_markdown(names: list[str], report: dict[str, Any], link_base: str) -> str:
    """What a reproduction page opens with: its paper numbers beside cerebx's intervals, and its checks."""
    figures = [e for e in report.get("figures") or [] if e["name"] in names]
    if not figures:
        return "No figure of this page was drawn in the published report.\n"
    counted = [e for e in figures if not e.get("kept_from")] or [{}]
    told, held, explained, unexplained = (sum(c) for c in zip(*(_checks(e) for e in counted), strict=True))
    head = (f"**In the published report ({report.get('profile') or 'runs'} profile):** {held} of {told} shape checks "
            f"hold, {explained} fail with an explanation, {unexplained} fail without one.\n\n")
    intervals = intervals_markdown(figures)
    return head + (intervals + "\n" if intervals else "") + checks_markdown(figures, link_base)


def hero_block(report: dict[str, Any], name: str, image_path: str) -> str | None:
    """The README's hero: the hero figure's image, its caption's first sentence, and its ratio rows."""
    entry = next((e for e in report.get("figures") or [] if e["name"] == name), None)
    if entry is None or not entry.get("files"):
        return None
    rows = [r for r in entry.get("table") or [] if r and str(r[0]).startswith(HERO_ROWS)]
    image = f"{image_path}/{Path(entry['files'][0]).name}"
    out = [f"![{_text(entry['title'])}]({image})", "",
           f"*{_text(entry['title'])} (`{name}`). Drawn by `cerebx report` from cerebx's own runs "
           f"({report.get('profile')} profile, {_day(report.get('built_at'))}, "
           f"commit `{report.get('commit') or 'unknown'}`); its reproduction page "
           "puts every number of the paper beside cerebx's, with the checks that hold and those that do not.*", ""]
    if rows:
        out += [table_markdown([["quantity", "paper", "cerebx"], *[r[:3] for r in rows]])]
    return "\n".join(out)


def update_readme(readme_path: Path, block: str) -> bool:
    """Replace the README's hero block with ``block``; False when the README has no hero markers."""
    text = readme_path.read_text()
    if HERO_START not in text or HERO_END not in text:
        return False
    a, b = text.index(HERO_START) + len(HERO_START), text.index(HERO_END)
    readme_path.write_text(text[:a] + "\n" + block.rstrip() + "\n" + text[b:])
    return True


def _png(src: Path, dst: Path) -> None:
    """A palette PNG of ``src`` (matplotlib figures keep their look at 256 colours, at a third of the size)."""
    with Image.open(src) as im:
        im.convert("RGB").quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(
            dst, optimize=True)


def render(report: dict[str, Any], link_base: str = "../results",
           pages: dict[str, list[str]] | None = None) -> dict[str, str]:
    """Every text file the published folder holds, by name, made from the report's figures.json alone
    (``pages``: each reproduction page's figures, for its opening table)."""
    report = {**report, "command": portable(report.get("command"))}
    files = {"figures.json": json.dumps(report, indent=1, ensure_ascii=False) + "\n",
             "stamp.md": stamp(report), "README.md": readme(report),
             "checks.md": checks_markdown(report.get("figures") or [], link_base)}
    for entry in report.get("figures") or []:
        files[f"{entry['name']}.md"] = figure_markdown(entry, report, link_base)
    for page, names in (pages or {}).items():
        files[f"page_{page}.md"] = page_markdown(names, report, link_base)
    return files


def _kept(report: dict[str, Any], out: Path) -> tuple[list[dict[str, Any]], dict[str, bytes]]:
    """The earlier published figures (in ``out``) that ``report`` does not draw, marked with where they came
    from, and their images' bytes."""
    old = load_report(out) if (out / "figures.json").is_file() else {}
    drawn = {e["name"] for e in report.get("figures") or []}
    entries, images = [], {}
    for e in old.get("figures") or []:
        if e["name"] in drawn:
            continue
        source = e.get("kept_from") or {k: old.get(k) for k in ("profile", "built_at", "commit")}
        entries.append({**e, "kept_from": source})
        for f in e.get("files") or []:
            src = out / "figures" / Path(f).name
            if not src.is_file():
                raise PublishError(f"{out}: the kept figure {e['name']}'s image {src.name} is missing")
            images[src.name] = src.read_bytes()
    return entries, images


def publish(report_dir: Path, out: Path, link_base: str = "../results", pages_dir: Path | None = None,
            readme_path: Path | None = None, hero: str = "fig3_4", keep_missing: bool = False,
            home_path: Path | None = None) -> list[str]:
    """Replace ``out`` with the published form of the report in ``report_dir`` (with an opening table for
    each reproduction page of ``pages_dir``, and the hero blocks of ``readme_path`` and of the docs' home page
    ``home_path`` rewritten; ``keep_missing``: the earlier published figures the report does not draw are kept,
    marked); returns the figure names."""
    report_dir, out = Path(report_dir), Path(out)
    report = load_report(report_dir)
    images = [(report_dir / f, Path(f).name) for e in report.get("figures") or [] for f in e.get("files") or []]
    absent = [str(src) for src, _ in images if not src.is_file()]
    if absent:
        raise PublishError(f"{report_dir}: images listed in figures.json are missing: {', '.join(absent)}")
    if out.exists() and any(out.iterdir()) and not (out / "figures.json").is_file():
        raise PublishError(f"{out}: not empty and not a published report (no figures.json): not replaced")
    kept, kept_images = _kept(report, out) if keep_missing and out.exists() else ([], {})
    report = {**report, "figures": [*(report.get("figures") or []), *kept]}
    if out.exists():
        shutil.rmtree(out)
    (out / "figures").mkdir(parents=True)
    pages = reproduction_pages(pages_dir) if pages_dir is not None and Path(pages_dir).is_dir() else {}
    for name, text in render(report, link_base, pages).items():
        (out / name).write_text(text)
    for src, name in images:
        _png(src, out / "figures" / name)
    for name, data in kept_images.items():
        (out / "figures" / name).write_bytes(data)
    portable_report = {**report, "command": portable(report.get("command"))}
    for page in (readme_path, home_path):
        if page is not None and Path(page).is_file():
            rel = Path(os.path.relpath(out, Path(page).parent)).as_posix()
            block = hero_block(portable_report, hero, f"{rel}/figures")
            if block is not None:
                update_readme(Path(page), block)
    return [e["name"] for e in report.get("figures") or []]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("report", type=Path, help="a folder `cerebx report` wrote (holding figures.json)")
    ap.add_argument("--out", type=Path, default=Path("docs/results"), help="published folder (default docs/results)")
    ap.add_argument("--link-base", default="../results",
                    help="the published folder as the including pages see it (default ../results)")
    ap.add_argument("--pages", type=Path, default=Path("docs/reproductions"),
                    help="the reproduction pages whose opening tables to write (default docs/reproductions)")
    ap.add_argument("--readme", type=Path, default=Path("README.md"),
                    help="the README whose hero block to rewrite (default README.md; a missing one is skipped)")
    ap.add_argument("--home", type=Path, default=Path("docs/index.md"),
                    help="the docs' home page whose hero block to rewrite (default docs/index.md; a missing one "
                         "is skipped)")
    ap.add_argument("--hero", default="fig3_4", help="the hero figure (default fig3_4)")
    ap.add_argument("--keep-missing", action="store_true",
                    help="keep the earlier published figures this report does not draw, marked as such")
    a = ap.parse_args(argv)
    try:
        names = publish(a.report, a.out, a.link_base, a.pages, a.readme, a.hero, a.keep_missing, a.home)
    except PublishError as err:
        print(f"publish_report: {err}", file=sys.stderr)
        return 2
    print(f"publish_report: {len(names)} figures into {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
