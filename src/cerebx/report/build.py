"""``cerebx report``: rebuild reports/ (index.html, figures, tables) from run folders.

    cerebx report                         every run under runs/
    cerebx report RUN_DIR...              only those runs (a folder of runs is searched)
    cerebx report runs/report/quick       a quick profile's runs, with those it draws from the full profile
    cerebx report --profile quick|full    first run the studies whose runs are missing, then draw them

Every registered figure (report/registry.py) is drawn from the runs it finds; one whose runs are
missing, and any run that is missing or unreadable, gives one line and the rest is still built.
``index.html`` opens with a table of every figure: whether the paper's shapes hold in these runs, whether
the learning behind it has converged (``report/convergence.py``) and the command that makes it converge;
an unconverged figure carries a badge on its images and in its caption. Besides index.html and the tables,
``figures.json`` holds every drawn figure (title, caption, table, notes, shape checks, convergence, files)
and how the report was made (command, profile, cerebx version, the runs' count and dates), for tools that
publish a report elsewhere. ``paper_vs_cerebx.csv`` gives each number beside the paper's, and for a headline
number learned from several seeds its 95 % interval and whether the paper's number is inside
(``report/stats.py``); a failing shape check whose cause is written up links to it (``explained_at``,
``report/explain.py``).
"""

from __future__ import annotations

import argparse
import csv
import dataclasses
import html
import json
import shlex
import subprocess
import sys
import time
from collections import defaultdict
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

from cerebx import __version__, runfiles
from cerebx.config import load_jobs
from cerebx.errors import CerebxError
from cerebx.estimate import duration, estimate, total
from cerebx.report import figures
from cerebx.report.badge import stamp
from cerebx.report.delays import delay_rows
from cerebx.report.explain import explain, load_explanations
from cerebx.report.pace import left_fraction, profile_pace, remaining_wall_s
from cerebx.report.plot import fmt
from cerebx.report.registry import Figure, FigureSpec, MissingRuns, all_figures
from cerebx.report.runs import RunSet, find_run_dirs, load_runs
from cerebx.report.studies import REPLICA, execute, group, plan, profile_of, study_runner
from cerebx.report.summary import checks_list, shape_rows, summary_table

MAX_TRACKING_RUNS = 12  # per-run joint-tracking figures only for small run sets


def _markdown(rows: list[list[str]]) -> str:
    out = ["| " + " | ".join(rows[0]) + " |", "|" + "---|" * len(rows[0])]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows[1:]]
    return "\n".join(out) + "\n"


def _html_table(rows: list[list[str]]) -> str:
    head = "".join(f"<th>{html.escape(str(c))}</th>" for c in rows[0])
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>" for r in rows[1:])
    return f"<table><tr>{head}</tr>{body}</table>"


def _converged(fig: Figure, quantity: str) -> str:
    """The ``converged`` cell of one paper-vs-cerebx row: yes, no (why), or – when nothing learns."""
    return "–" if fig.convergence is None else fig.convergence.flag(quantity)


PAPER_HEADER = ["figure", "quantity", "paper", "cerebx", "converged", "seeds", "ci_low", "ci_high", "paper_in_ci"]


def paper_row(name: str, fig: Figure, row: list[str]) -> list[str]:
    """One row of ``paper_vs_cerebx.csv``: the figure's table row, whether it converged, and its interval over
    seeds when the figure gives one for this quantity (else one seed's number and – for the interval)."""
    quantity = str(row[0])
    iv = fig.intervals.get(quantity)
    if iv is None:
        tail = ["1", "–", "–", "–"]
    elif iv.has_interval:
        tail = [str(iv.n), f"{iv.low:.4g}", f"{iv.high:.4g}", iv.paper_in_ci]
    else:
        tail = [str(iv.n), "–", "–", "–"]
    return [name, *row, _converged(fig, quantity), *tail]


def _badge(fig: Figure) -> str | None:
    """Badge an unconverged figure: a band on each image, the same words ahead of its caption; the badge."""
    badge = fig.convergence.badge if fig.convergence is not None else None
    if badge:
        for png in fig.files:
            stamp(png, badge)
        fig.caption = f"[{badge}] {fig.caption}"
    return badge


def _write_table(out: Path, name: str, rows: list[list[str]]) -> None:
    (out / f"{name}.md").write_text(_markdown(rows))
    with open(out / f"{name}.csv", "w", newline="") as fh:
        csv.writer(fh).writerows(rows)


def _runs_table(runs: RunSet) -> list[list[str]]:
    rows = [["run", "status", "task", "controller", "plant", "delay", "network", "trials", "final MAE (rad)",
             "rt factor"]]
    for r in runs:
        s = r.summary
        rows.append([str(r.dir), s["status"], r.task, r.controller_preset, s["plant"], r.delay_preset, r.network,
                     str(r.trials), fmt(s.get("final_mae"), 4), fmt(s.get("rt_factor"), 1)])
    return rows


def _general_figures(runs: RunSet, fig_dir: Path, problems: list[str]) -> list[str]:
    """Learning curves of every task, and joint tracking of each run when there are few."""
    sections = []
    by_task: dict[str, list] = defaultdict(list)
    for r in runs:
        by_task[r.task].append((r.dir, r.summary))
    for task, rs in sorted(by_task.items()):
        png = figures.learning_curves(rs, task, fig_dir / f"learning_{task}")
        sections.append(_img(png, f"MAE per trial of every {task} run (log scale)."))
    if len(runs) <= MAX_TRACKING_RUNS:
        for r in runs:
            if not r.trials:
                continue
            try:
                png = figures.joint_tracking(r.dir, r.summary, fig_dir / f"tracking_{r.task}_{r.name}")
            except (CerebxError, ValueError) as err:
                problems.append(str(err))
                continue
            sections.append(_img(png, f"{r.dir}: desired (dashed) vs actual joint positions, last trial."))
    return sections


def _iso(t: float) -> str:
    return datetime.fromtimestamp(t, timezone.utc).isoformat(timespec="seconds")


def source_commit() -> str | None:
    """The commit of the cerebx checkout this report runs from (with ``-dirty`` when it has uncommitted
    changes), or None outside a git checkout."""
    here = Path(__file__).resolve().parent
    try:
        out = subprocess.run(["git", "-C", str(here), "describe", "--always", "--dirty", "--abbrev=12"],
                             capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None if out.returncode == 0 else None


def _disk_bytes(d: Path) -> int:
    try:
        return sum(f.stat().st_size for f in d.rglob("*") if f.is_file())
    except OSError:
        return 0


def provenance(runs: RunSet, command: str | None, profile: str | None,
               wall_seconds: float | None = None) -> dict[str, Any]:
    """How a report was made: the command, the profile, this cerebx's version and commit, when, how long the
    command took (``wall_seconds``: running the missing studies and drawing), and the runs it drew from (how
    many, the first and last start time their summaries record, the versions that ran them, their summed wall
    time and their size on disk)."""
    started = sorted(float(t) for r in runs if isinstance(t := r.summary.get("started_at"), int | float))
    return {
        "command": command,
        "profile": profile,
        "cerebx_version": __version__,
        "commit": source_commit(),
        "built_at": _iso(time.time()),
        "wall_seconds": None if wall_seconds is None else round(wall_seconds, 1),
        "runs": {
            "count": len(runs),
            "first_started_at": _iso(started[0]) if started else None,
            "last_started_at": _iso(started[-1]) if started else None,
            "versions": sorted({str(v) for r in runs if (v := r.summary.get("version"))}),
            "wall_seconds": round(sum(float(r.summary.get("wall_seconds") or 0.0) for r in runs), 1),
            "disk_bytes": sum(_disk_bytes(r.dir) for r in runs),
        },
    }


def figure_entry(spec: FigureSpec, fig: Figure, out: Path) -> dict[str, Any]:
    """One drawn figure as JSON: its spec (name, title, studies, the module that draws it) and every field
    of its :class:`Figure`, files as paths relative to the report folder."""
    entry: dict[str, Any] = {"name": spec.name, "title": spec.title, "studies": list(spec.studies),
                             "module": getattr(spec.draw, "__module__", None)}
    for f in dataclasses.fields(fig):
        value = getattr(fig, f.name)
        if f.name == "files":
            value = [p.relative_to(out).as_posix() if p.is_relative_to(out) else p.name for p in value]
        elif f.name == "checks":
            value = [dataclasses.asdict(c) for c in value]
        elif f.name == "convergence" and value is not None:
            value = value.as_json()
        elif f.name == "intervals":
            value = {k: iv.as_json() for k, iv in value.items()}
        entry[f.name] = value
    return entry


def _img(png: Path, caption: str) -> str:
    return (f"<figure><a href='figures/{png.name}'><img src='figures/{png.name}'></a>"
            f"<figcaption>{html.escape(caption)} <a href='figures/{png.with_suffix('.svg').name}'>SVG</a>"
            "</figcaption></figure>")


def build(run_dirs: list[Path], out: Path, names: list[str] | None = None, log=lambda line: None,
          command: str | None = None, profile: str | None = None,
          started: float | None = None, lacking: frozenset[str] = frozenset()) -> tuple[Path, list[str], int]:
    """Draw every figure (or the named ones) from ``run_dirs`` into ``out``; returns (index, problems, runs).
    ``command`` and ``profile`` are recorded in figures.json (the profile is read from the runs' folders
    when not given), and the wall time since ``started`` (a ``time.monotonic()``) when given. ``lacking``: the
    studies a quick report draws from the full profile whose runs are missing there; a figure that needs one
    (:meth:`FigureSpec.needs`) is not drawn (from other runs it would stand for a figure it is not)."""
    runs, problems = load_runs(run_dirs)
    return build_from(runs, out, names, log, problems, command, profile, started, lacking)


def build_from(runs: RunSet, out: Path, names: list[str] | None = None, log=lambda line: None,
               problems: list[str] | None = None, command: str | None = None,
               profile: str | None = None, started: float | None = None,
               lacking: frozenset[str] = frozenset()) -> tuple[Path, list[str], int]:
    """Draw every figure (or the named ones) from ``runs`` into ``out``; ``problems``: lines already found
    (unreadable runs); the rest as :func:`build`."""
    problems = list(problems or [])
    profile = profile or profile_of([r.dir for r in runs])
    known = load_explanations()
    out.mkdir(parents=True, exist_ok=True)
    fig_dir = out / "figures"
    specs = all_figures()
    unknown = [n for n in names or [] if n not in specs]
    if unknown:
        raise CerebxError(f"--figures: unknown figure(s) {', '.join(unknown)} (known: {', '.join(specs)})")
    chosen = [specs[n] for n in names] if names else list(specs.values())
    drawn: list[tuple[FigureSpec, Figure]] = []
    missing: list[str] = []
    paper_rows = [PAPER_HEADER]
    for spec in chosen:
        t0 = time.monotonic()
        if without := [s for s in spec.studies if s in lacking and spec.needs(s)]:
            missing.append(f"{spec.name}: drawn from the full profile's runs of {', '.join(without)}, which are "
                           "missing (cerebx report --profile full)")
            continue
        try:
            fig: Figure = spec.draw(runs, fig_dir / spec.name)
        except MissingRuns as err:
            missing.append(f"{spec.name}: {err}")
            continue
        except Exception as err:  # one broken figure must not cost the others
            problems.append(f"{spec.name}: could not be drawn ({type(err).__name__}: {err})")
            continue
        explain(spec.name, fig, profile, known)
        badge = _badge(fig)
        took = f"  {spec.name}: {len(fig.files)} image(s) in {time.monotonic() - t0:.1f} s"
        log(took + (f"; {badge}" if badge else ""))
        drawn.append((spec, fig))
        paper_rows += [paper_row(spec.name, fig, row) for row in fig.table[1:]]
    toc, sections = [], []
    for spec, fig in drawn:
        toc.append(f"<li><a href='#{spec.name}'>{html.escape(spec.title)}</a></li>")
        imgs = "".join(f"<a href='figures/{p.name}'><img src='figures/{p.name}'></a>" for p in fig.files)
        svgs = " ".join(f"<a href='figures/{p.with_suffix('.svg').name}'>{p.stem}.svg</a>" for p in fig.files)
        table = (f"<div class='side'><h4>Paper beside cerebx</h4>{_html_table(fig.table)}</div>"
                 if len(fig.table) > 1 else "")
        notes = "".join(f"<li>{html.escape(n)}</li>" for n in fig.notes)
        checks = checks_list(fig.checks)
        plateaus = "".join(f"<li>{html.escape(line)}</li>" for line in
                           (fig.convergence.describe() if fig.convergence is not None else []))
        sections.append(
            f"<section id='{spec.name}'><h2>{html.escape(spec.title)}</h2><div class='row'><div class='imgs'>{imgs}"
            f"<p class='cap'>{html.escape(fig.caption)} ({svgs})</p>"
            f"{'<h4>Shape checks</h4><ul class=checks>' + checks + '</ul>' if checks else ''}"
            f"{'<h4>Plateau tests</h4><ul class=plateaus>' + plateaus + '</ul>' if plateaus else ''}"
            f"{'<ul class=notes>' + notes + '</ul>' if notes else ''}</div>{table}</div>"
            f"<p class='runs'>studies: {html.escape(', '.join(spec.studies))}</p></section>")
    general = _general_figures(runs, fig_dir, problems) if runs else []
    runs_rows = _runs_table(runs)
    _write_table(out, "runs", runs_rows)
    _write_table(out, "paper_vs_cerebx", paper_rows)
    _write_table(out, "shapes", shape_rows(drawn))
    _write_table(out, "delays", delay_rows(runs))
    made = provenance(runs, command, profile, None if started is None else time.monotonic() - started)
    (out / "figures.json").write_text(json.dumps(
        {**made, "figures": [figure_entry(spec, fig, out) for spec, fig in drawn], "not_drawn": missing},
        indent=1, ensure_ascii=False, default=str) + "\n")
    miss = "".join(f"<li>{html.escape(m)}</li>" for m in missing)
    probs = "".join(f"<li>{html.escape(p)}</li>" for p in problems)
    page = f"""<!doctype html><html><head><meta charset="utf-8"><title>cerebx report</title>
<style>body{{font-family:sans-serif;max-width:1500px;margin:2em auto;padding:0 1em}}img{{max-width:100%}}
.row{{display:flex;gap:1.5em;align-items:flex-start}}.imgs{{flex:3}}.side{{flex:1.3;font-size:13px}}
table{{border-collapse:collapse;font-size:13px}}td,th{{border:1px solid #ccc;padding:3px 6px;vertical-align:top}}
.cap{{font-size:14px;color:#333}}.runs{{font-size:12px;color:#777}}section{{border-top:1px solid #ddd;
margin-top:2em}}.summary td{{font-size:13px}}.ok{{color:#1b5e20}}.bad{{color:#b71c1c}}.na{{color:#777}}
ul.checks,ul.plateaus{{margin:2px 0;padding-left:1.1em;font-size:13px}}
ul.checks li{{list-style:none;text-indent:-1em}}
td.ok,td.bad{{background:none}}code{{font-size:12px}}.summary{{width:100%}}.summary td:last-child{{width:24em}}
</style></head><body>
<h1>cerebx report</h1>
<p class='runs'>{html.escape(made["built_at"])}: <code>{html.escape(made["command"] or "cerebx report")}</code>,
cerebx {html.escape(made["cerebx_version"])}</p>
<p>{len(runs)} runs, {len(drawn)} of {len(chosen)} figures drawn from their logs. For each figure: whether
the paper's shapes (orderings, trends) hold in these runs, and whether the learning behind it has levelled off
(the plateau test of each learning curve, set by its study: by default the means of its last two windows of a
tenth of the paper's learning trials within 10 %). A figure that has not converged carries a red badge: its
numbers are not yet a reproduction.</p>
{summary_table(chosen, {s.name: f for s, f in drawn})}
<p>Each figure is shown with the paper's numbers beside cerebx's (all numbers in paper_vs_cerebx.csv, with a
column <i>converged</i>; the shape checks in shapes.csv). Absolute numbers depend on the plant (a real robot vs
a MuJoCo model); the shapes and orderings are what should hold.</p>
<ul>{''.join(toc)}</ul>
{'<h3>Not drawn (runs missing)</h3><ul>' + miss + '</ul>' if miss else ''}
{''.join(sections)}
<section><h2>All runs</h2>{''.join(general)}{_html_table(runs_rows)}</section>
{'<h3>Problems</h3><ul>' + probs + '</ul>' if probs else ''}
</body></html>"""
    index = out / "index.html"
    index.write_text(page)
    return index, problems + missing, len(runs)


def borrowed_missing(jobs: list) -> str | None:
    """The line saying which studies a quick report draws from the full profile lack runs there (None: none)."""
    lacking = list(dict.fromkeys(j.study for j in jobs if j.borrowed and not j.done()))
    if not lacking:
        return None
    return (f"report: {len(lacking)} studies cannot converge in this profile and are drawn from the full profile's "
            f"runs, which are missing ({', '.join(lacking)}): run cerebx report --profile full to draw their figures")


def with_borrowed(quick: Path, names: list[str] | None = None) -> tuple[list[Path], frozenset[str]]:
    """A quick profile's folder given to the report (``<root>/quick``) is drawn as ``--profile quick`` draws it:
    with the runs of the studies it borrows from the full profile (``from_full``) in ``<root>/full``, those
    of the ``names`` figures. Returns those runs and the borrowed studies without runs there (their figures
    are left out with a line)."""
    lent = list(dict.fromkeys(j.study for j in plan("quick", quick.parent, needed_studies(names)) if j.borrowed))
    found = {s: find_run_dirs(quick.parent / "full" / s) for s in lent}  # (none for a missing folder)
    absent = frozenset(s for s, d in found.items() if not d and REPLICA not in s)
    return [d for s in lent for d in found[s]], absent


def dry_run(jobs: list, folder: Path, parallel: int) -> None:
    """Print each job (reused or to run; ``full``: a full-profile run a quick report draws on, ``lacks``: one that
    does not exist yet) and the estimate of those to run: on a quiet machine (``cerebx.estimate``) and at the pace
    of the profile's finished runs (``report/pace.py``) when some are."""
    lent = [j for j in jobs if j.borrowed]
    for j in lent:
        print(f"{'full ' if j.done() else 'lacks'} {j.run_dir}  (from the full profile: not run by this one)")
    if lacking := borrowed_missing(lent):
        print(lacking)
    jobs = [j for j in jobs if not j.borrowed]
    done = [j.done() for j in jobs]
    for j, d in zip(jobs, done, strict=True):
        print(f"{'reuse' if d else 'run  '} {j.run_dir}  cerebx run {' '.join(j.overrides())}")
    exps, problems = load_jobs([j.overrides() for j in jobs])
    todo = [(j, e) for j, e, d in zip(jobs, exps, done, strict=True) if not d and e is not None]
    left = [e for _, e in todo]
    bad = [p for p, d in zip(problems, done, strict=True) if p is not None and not d]
    ests = [estimate(e) for e in left]
    print(f"{done.count(False)} runs to do: {total(ests, parallel).line()}", *bad, sep="\n")
    if ests:
        print(where_the_time_goes([j.study for j, _ in todo], ests, parallel))
    pace = profile_pace(folder, {j.run_dir: estimate(e).wall_s
                                 for j, e, d in zip(jobs, exps, done, strict=True) if d and e is not None})
    fractions = [left_fraction(j.run_dir, e.trials) for j, e in todo]
    resumed = sum(f < 1.0 for f in fractions)
    if pace.runs:
        print(f"at the pace of this profile's {pace.runs} finished runs (by kind of run, --jobs {parallel}"
              f"{f'; {resumed} resume from their checkpoints' if resumed else ''}): "
              f"~{duration(remaining_wall_s(pace, left, parallel, fractions))}")


def where_the_time_goes(studies: list[str], ests: list, parallel: int, top: int = 6) -> str:
    """One line: the studies that take most of the estimated time (their seeds counted together), each with
    its share of it: of the CPU when runs share the cores, of the wall time one at a time."""
    whole = total(ests, parallel).wall_s
    part = "cpu_s" if parallel > 1 else "wall_s"
    spent: dict[str, float] = {}
    for study, e in zip(studies, ests, strict=True):
        base = study.split(REPLICA)[0]
        spent[base] = spent.get(base, 0.0) + getattr(e, part)
    summed = sum(spent.values()) or 1.0
    ranked = sorted(spent.items(), key=lambda kv: -kv[1])
    shown = [f"{name} ~{duration(whole * t / summed)} ({100 * t / summed:.0f} %)" for name, t in ranked[:top]]
    rest = len(ranked) - len(shown)
    return "where the time goes: " + ", ".join(shown) + (f"; {rest} other studies the rest" if rest > 0 else "")


def needed_studies(names: list[str] | None) -> list[str]:
    specs = all_figures()
    chosen = [specs[n] for n in names if n in specs] if names else list(specs.values())
    out: list[str] = []
    for spec in chosen:
        out += [s for s in spec.studies if s not in out]
    return out


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(prog="cerebx report", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="*", type=Path, help="run folders or folders of runs (default: runs/)")
    ap.add_argument("--profile", choices=("quick", "full"),
                    help="run the missing studies of this profile into runs/report/PROFILE first")
    ap.add_argument("--figures", help="comma-separated figure names (default: all; --list shows them)")
    ap.add_argument("--jobs", type=int, default=2, help="multiruns at once (default 2); each is one "
                    "`cerebx run -m`, whose launcher runs its jobs; a sweep is split into this many multiruns "
                    "side by side (by its swept key with the most values), so one long sweep keeps every core busy")
    ap.add_argument("-o", "--override", action="append", default=[], metavar="OVERRIDE",
                    help="Hydra override for every study's multirun, e.g. -o hydra/launcher=slurm "
                    "(repeatable; see docs/guide/sweeps.md)")
    ap.add_argument("--seeds", type=int, metavar="N", help="with --profile: at most N seeds of each study "
                    "learned from several (their first; default: as many as the profile asks)")
    ap.add_argument("--dry-run", action="store_true", help="with --profile: list the jobs, run nothing")
    ap.add_argument("--out", type=Path, default=Path("reports"), help="output folder (default reports/)")
    ap.add_argument("--list", action="store_true", help="list the figures and the studies they need")
    a = ap.parse_args(argv)
    names = [n.strip() for n in a.figures.split(",") if n.strip()] if a.figures else None
    t0 = time.monotonic()
    try:
        if a.list:
            for spec in all_figures().values():
                print(f"{spec.name:8s} {spec.title}\n         studies: {', '.join(spec.studies)}")
            return 0
        failed: list[str] = []
        if a.profile:
            root = Path("runs") / "report"
            if a.seeds is not None and a.seeds < 1:
                raise CerebxError(f"--seeds: {a.seeds} is not a number of seeds (at least 1)")
            jobs = plan(a.profile, root, needed_studies(names), max_seeds=a.seeds)
            if a.dry_run:
                dry_run(jobs, root / a.profile, a.jobs)
                return 0
            try:
                failed = execute(group([j for j in jobs if not j.borrowed], a.jobs), runner=study_runner(a.override),
                                 parallel=a.jobs)
            except KeyboardInterrupt:
                print("report: interrupted; finished runs are kept (run the same command again to resume)",
                      file=sys.stderr)
                return 130
            if lacking := borrowed_missing(jobs):
                print(lacking, file=sys.stderr)
            dirs = [j.run_dir for j in jobs if not j.borrowed or j.done()]
            # (a figure is drawn from the first seed; the other seeds only give its intervals)
            absent = frozenset(j.study for j in jobs if j.borrowed and not j.done() and REPLICA not in j.study)
        else:
            dirs = []
            for p in a.runs or [Path("runs")]:
                dirs.extend(find_run_dirs(p) if p.is_dir() and not (p / runfiles.SUMMARY).exists() else [p])
            absent = frozenset()
            if quick := [p for p in a.runs or [] if p.name == "quick" and p.is_dir()]:
                lent, absent = with_borrowed(quick[0], names)
                dirs, a.profile = [*dirs, *lent], "quick"
        index, problems, n = build(dirs, a.out, names, log=print, command=shlex.join(["cerebx", "report", *argv]),
                                   profile=a.profile, started=t0, lacking=absent)
    except CerebxError as err:
        for line in str(err).splitlines():
            print(line, file=sys.stderr)
        return 2
    for p in problems:
        print(p, file=sys.stderr)
    print(f"report: {index} ({n} runs) in {time.monotonic() - t0:.0f} s")
    return 1 if failed else 0
