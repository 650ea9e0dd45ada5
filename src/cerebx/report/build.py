"""``cerebx report``: rebuild reports/ (index.html, figures, tables) from run folders.

Without arguments every run under ``runs/`` is used; with RUN_DIR arguments only those. A run that
is missing or unreadable is reported in one line and skipped; the rest of the report is built.
"""

from __future__ import annotations

import html
import sys
from collections import defaultdict
from pathlib import Path
from typing import Any

from cerebx.errors import CerebxError
from cerebx.metrics import window_stats
from cerebx.recording.reader import read_summary

# Thesis Tables 2.3 / 2.4: (task) -> windows [(start, stop, mean, std)] and the factory controller.
PAPER = {
    "circle": {"snn": [(0, 100, 0.115, 0.055), (100, 200, 0.036, 0.013), (400, 500, 0.019, 0.003)],
               "position": (0.077, 0.0004)},
    "eight": {"snn": [(0, 100, 0.111, 0.034), (100, 200, 0.046, 0.013), (400, 500, 0.017, 0.003)],
              "position": (0.063, 0.0003)},
    "reaching": {"snn": [(0, 100, 0.155, 0.050), (300, 400, 0.043, 0.024), (900, 1000, 0.019, 0.006)],
                 "position": (0.026, 0.006)},
}


def find_runs(root: Path) -> list[Path]:
    return sorted(p.parent for p in root.rglob("summary.json"))


def _fmt(x: float | None, nd: int = 4) -> str:
    return "–" if x is None else f"{x:.{nd}f}"


def paper_table(runs: list[tuple[Path, dict]]) -> list[list[str]]:
    """Rows: task, window, paper mean±std, cerebx mean±std (best matching completed snn run)."""
    rows = [["task", "controller", "trials", "paper MAE (rad)", "cerebx MAE (rad)", "run"]]
    for task, ref in PAPER.items():
        snn = [(p, s) for p, s in runs if s["task"] == task and s["controller"] == "snn" and s["delay"] == "none"]
        snn.sort(key=lambda ps: len(ps[1].get("mae_per_trial") or []), reverse=True)
        for a, b, m, sd in ref["snn"]:
            ours = window_stats(snn[0][1]["mae_per_trial"], a, b) if snn else None
            rows.append([task, "snn", f"{a}-{b}", f"{m:.3f} ± {sd:.3f}",
                         f"{ours[0]:.3f} ± {ours[1]:.3f}" if ours else "not run", snn[0][0].name if snn else ""])
        pos = [(p, s) for p, s in runs
               if s["task"] == task and s.get("presets", {}).get("controller") == "position_factory"]
        m, sd = ref["position"]
        if pos:
            ours = window_stats(pos[0][1]["mae_per_trial"], 0, len(pos[0][1]["mae_per_trial"]))
            cell = f"{ours[0]:.3f} ± {ours[1]:.4f}"
        else:
            cell = "not run"
        rows.append([task, "position (factory)", "all", f"{m:.3f} ± {sd:.4f}", cell, pos[0][0].name if pos else ""])
    return rows


def _markdown(rows: list[list[str]]) -> str:
    out = ["| " + " | ".join(rows[0]) + " |", "|" + "---|" * len(rows[0])]
    out += ["| " + " | ".join(r) + " |" for r in rows[1:]]
    return "\n".join(out) + "\n"


def _html_table(rows: list[list[str]]) -> str:
    head = "".join(f"<th>{html.escape(c)}</th>" for c in rows[0])
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>" for r in rows[1:])
    return f"<table><tr>{head}</tr>{body}</table>"


def build(run_dirs: list[Path], out: Path) -> tuple[Path, list[str], int]:
    from cerebx.report import figures

    problems: list[str] = []
    runs: list[tuple[Path, dict[str, Any]]] = []
    for d in run_dirs:
        try:
            runs.append((d, read_summary(d)))
        except CerebxError as err:
            problems.append(str(err))
    out.mkdir(parents=True, exist_ok=True)
    fig_dir = out / "figures"
    sections: list[str] = []
    by_task: dict[str, list] = defaultdict(list)
    for d, s in runs:
        by_task[s["task"]].append((d, s))
    for task, rs in sorted(by_task.items()):
        png = figures.learning_curves(rs, task, fig_dir / f"learning_{task}")
        sections.append(f"<figure><img src='figures/{png.name}'><figcaption>MAE per trial, task "
                        f"{html.escape(task)}: every run of this task (log scale).</figcaption></figure>")
        baselines = [s for _, s in rs if s["controller"] in ("pd", "position") and s.get("final_mae") is not None]
        for d, s in rs:
            if not s.get("trials_completed"):
                continue
            if s["controller"] in ("snn", "ann") and s["trials_completed"] >= 10:
                from cerebx.report import stages

                try:
                    png = stages.stages_figure(d, s, fig_dir / f"stages_{task}_{d.name}")
                    sections.append(f"<figure><img src='figures/{png.name}'><figcaption>{html.escape(str(d))}: "
                                    "thesis Fig. 2.6/2.7 — DCN activity, torques, desired vs actual joints and the "
                                    "end-effector path (density of the previous 10 trials) at an initial, "
                                    "intermediate and final stage.</figcaption></figure>")
                    png = stages.mae_per_joint_figure(s, baselines, fig_dir / f"mae_joints_{task}_{d.name}")
                    sections.append(f"<figure><img src='figures/{png.name}'><figcaption>{html.escape(str(d))}: "
                                    "thesis Fig. 2.6 g / 2.7 g — MAE per trial per joint and mean, with the "
                                    "baselines' final MAE.</figcaption></figure>")
                except (CerebxError, ValueError) as err:
                    problems.append(str(err))
            try:
                png = figures.joint_tracking(d, s, fig_dir / f"tracking_{task}_{d.name}")
            except (CerebxError, ValueError) as err:
                problems.append(str(err))
                continue
            sections.append(f"<figure><img src='figures/{png.name}'><figcaption>{html.escape(str(d))}: desired "
                            f"(dashed) vs actual joint positions over the last trial.</figcaption></figure>")
    runs_rows = [["run", "status", "task", "controller", "plant", "delay", "trials", "final MAE (rad)", "rt factor"]]
    for d, s in runs:
        runs_rows.append([str(d), s["status"], s["task"], s["controller"], s["plant"], s["delay"],
                          str(s.get("trials_completed")), _fmt(s.get("final_mae")), _fmt(s.get("rt_factor"), 1)])
    paper = paper_table(runs)
    from cerebx.report.delays import delay_rows

    delays = delay_rows(runs)
    (out / "runs.md").write_text(_markdown(runs_rows))
    (out / "paper_vs_cerebx.md").write_text(_markdown(paper))
    import csv

    (out / "delays.md").write_text(_markdown(delays))
    for name, rows in (("runs.csv", runs_rows), ("paper_vs_cerebx.csv", paper), ("delays.csv", delays)):
        with open(out / name, "w", newline="") as fh:
            csv.writer(fh).writerows(rows)
    notes = "".join(f"<li>{html.escape(p)}</li>" for p in problems)
    page = f"""<!doctype html><html><head><meta charset="utf-8"><title>cerebx report</title>
<style>body{{font-family:sans-serif;max-width:1200px;margin:2em auto}}img{{max-width:100%}}
table{{border-collapse:collapse;font-size:13px}}td,th{{border:1px solid #ccc;padding:3px 6px}}</style></head><body>
<h1>cerebx report</h1>
<h2>Paper (thesis Tables 2.3 / 2.4) beside cerebx</h2>{_html_table(paper)}
<h2>Delay studies (thesis Fig. 3.4, 3.7, 3.8)</h2>
<p>Thesis: the SNN stays near its no-delay MAE (about 0.02-0.03 rad) up to 80 ms; PD and the rate-based
ANN degrade 3-4x and oscillate above about 20 ms (torque variability PD 0.019 to 0.036 N·m/ms, ANN 0.016
to 0.026 N·m/ms from 0 to 50 ms).</p>{_html_table(delays) if len(delays) > 1 else '<p>No delay runs.</p>'}
<h2>Figures</h2>{''.join(sections) or '<p>No runs found.</p>'}
<h2>Runs</h2>{_html_table(runs_rows)}
{'<h2>Skipped</h2><ul>' + notes + '</ul>' if notes else ''}
</body></html>"""
    index = out / "index.html"
    index.write_text(page)
    return index, problems, len(runs)


def main(args: list[str]) -> int:
    out = Path("reports")
    if args:
        dirs = []
        for a in args:
            p = Path(a)
            dirs.extend(find_runs(p) if p.is_dir() and not (p / "summary.json").exists() else [p])
    else:
        dirs = find_runs(Path("runs"))
    index, problems, n = build(dirs, out)
    for p in problems:
        print(p, file=sys.stderr)
    print(f"report: {index} ({n} runs)")
    return 0
