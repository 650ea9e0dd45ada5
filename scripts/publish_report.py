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

A docs page includes a figure with ``--8<-- "docs/results/<figure>.md"`` and the stamp with
``--8<-- "docs/results/stamp.md"``; the snippets' image links are relative to the including page
(``--link-base``, default ``../results`` for pages one folder below docs/).
"""

from __future__ import annotations

import argparse
import json
import shlex
import shutil
import sys
from collections.abc import Iterable
from datetime import datetime
from pathlib import Path
from typing import Any

from PIL import Image

KNOWN = {"name", "title", "studies", "module", "files", "caption", "table", "notes"}
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


def stamp(report: dict[str, Any]) -> str:
    """One admonition saying how the published report was made."""
    runs = report.get("runs") or {}
    first, last = _day(runs.get("first_started_at")), _day(runs.get("last_started_at"))
    dates = first if first == last else f"{first} and {last}"
    versions = ", ".join(runs.get("versions") or []) or "unknown"
    profile = report.get("profile")
    source = PROFILE_TEXT.get(profile, f"the {profile} profile" if profile else "runs given on the command line")
    return "\n".join([
        '!!! info "Where these figures and tables come from"',
        f"    `{report.get('command') or 'cerebx report'}` drew them on {_day(report.get('built_at'))} (cerebx "
        f"{report.get('cerebx_version', 'unknown')}) from {runs.get('count', 0)} runs of {source}, started "
        f"{'on' if first == last else 'between'} {dates} by cerebx {versions}. `scripts/publish_report.py` "
        "copied them here; none is typed by hand.",
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
    profile = report.get("profile")
    out += [f"<small>Studies: {', '.join(entry.get('studies') or [])}"
            f"{f' ({profile} profile)' if profile else ''}; report of {_day(report.get('built_at'))}.</small>", ""]
    return "\n".join(out)


def readme(report: dict[str, Any]) -> str:
    rows = "\n".join(f"| `{e['name']}` | {_cell(e['title'])} | {', '.join(Path(f).name for f in e.get('files') or [])} "
                     "|" for e in report.get("figures") or [])
    return "\n".join([
        "# Published report", "",
        "Made by `scripts/publish_report.py` from a `cerebx report` output; do not edit by hand, publish again. "
        "The reproduction pages (`docs/reproductions/`) include `<figure>.md` and `stamp.md` with `--8<--`.", "",
        stamp(report), "| figure | title | images |", "|---|---|---|", rows, ""])


def _png(src: Path, dst: Path) -> None:
    """A palette PNG of ``src`` (matplotlib figures keep their look at 256 colours, at a third of the size)."""
    with Image.open(src) as im:
        im.convert("RGB").quantize(colors=256, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE).save(
            dst, optimize=True)


def render(report: dict[str, Any], link_base: str = "../results") -> dict[str, str]:
    """Every text file the published folder holds, by name, made from the report's figures.json alone."""
    report = {**report, "command": portable(report.get("command"))}
    files = {"figures.json": json.dumps(report, indent=1, ensure_ascii=False) + "\n",
             "stamp.md": stamp(report), "README.md": readme(report)}
    for entry in report.get("figures") or []:
        files[f"{entry['name']}.md"] = figure_markdown(entry, report, link_base)
    return files


def publish(report_dir: Path, out: Path, link_base: str = "../results") -> list[str]:
    """Replace ``out`` with the published form of the report in ``report_dir``; returns the figure names."""
    report_dir, out = Path(report_dir), Path(out)
    report = load_report(report_dir)
    images = [(report_dir / f, Path(f).name) for e in report.get("figures") or [] for f in e.get("files") or []]
    absent = [str(src) for src, _ in images if not src.is_file()]
    if absent:
        raise PublishError(f"{report_dir}: images listed in figures.json are missing: {', '.join(absent)}")
    if out.exists() and any(out.iterdir()) and not (out / "figures.json").is_file():
        raise PublishError(f"{out}: not empty and not a published report (no figures.json): not replaced")
    if out.exists():
        shutil.rmtree(out)
    (out / "figures").mkdir(parents=True)
    for name, text in render(report, link_base).items():
        (out / name).write_text(text)
    for src, name in images:
        _png(src, out / "figures" / name)
    return [e["name"] for e in report.get("figures") or []]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("report", type=Path, help="a folder `cerebx report` wrote (holding figures.json)")
    ap.add_argument("--out", type=Path, default=Path("docs/results"), help="published folder (default docs/results)")
    ap.add_argument("--link-base", default="../results",
                    help="the published folder as the including pages see it (default ../results)")
    a = ap.parse_args(argv)
    try:
        names = publish(a.report, a.out, a.link_base)
    except PublishError as err:
        print(f"publish_report: {err}", file=sys.stderr)
        return 2
    print(f"publish_report: {len(names)} figures into {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
