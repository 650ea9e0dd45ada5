"""Learning from scratch: thesis Fig. 2.6 (circle) and 2.7 (eight) with their stages and MAE per joint,
Tables 2.3 / 2.4 (MAE per learning stage, as bars) and Fig. 3.3 (convergence curves of chapter 3's
network). The snn run of each task is the longest one learning from scratch with the chapter's kernel."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from cerebx.metrics import final_mae  # noqa: E402
from cerebx.report.plot import save  # noqa: E402
from cerebx.report.registry import Check, Figure, MissingRuns, figure  # noqa: E402
from cerebx.report.runs import RunSet  # noqa: E402
from cerebx_thesis.report import stages  # noqa: E402
from cerebx_thesis.report.common import (  # noqa: E402
    CH2_KERNEL_MS,
    CH3_STUDY,
    CH3_TASKS,
    LEARN_STUDY,
    TASK_NAMES,
    baseline_text,
    baselines,
    from_scratch,
    learnt,
    short_path,
    snn_rows,
)

CONVERGENCE_TOL = 0.10


def _trajectory_learning(runs: RunSet, stem: Path, task: str, fig_no: str, study: str) -> Figure:
    """Fig. 2.6 / 2.7: the stage figure and the MAE-per-joint figure of ``task``, with Table 2.3's rows."""
    run = from_scratch(runs, task, CH2_KERNEL_MS)
    if run is None:
        raise MissingRuns(f"no {task} run of snn learning from scratch (study {study})")
    base = baselines(runs, task)
    table, wins = stages.stage_table(run, task, base)
    files = [stages.stages_figure(run.dir, run.summary, stem.with_name(stem.name + "_stages")),
             stages.mae_per_joint_figure(run.summary, [b.summary for _, b in base],
                                         stem.with_name(stem.name + "_mae"),
                                         labels=[name for name, _ in base], windows=wins)]
    ks = stages.stage_trials(run.trials)
    notes = [] if base else [f"no {task} baseline runs (pd / position_factory without delay): MAE figure without "
                             "baselines"]
    conv = learnt(runs, [(task, run, LEARN_STUDY[task])], snn_rows)
    total = stages.PAPER_STAGES[task][0]
    caption = (f"Thesis Fig. {fig_no} ({TASK_NAMES[task]}): the snn controller learning from scratch, run "
               f"{short_path(run)} with {run.n_measured} trials of {run.period_s:.0f} s (thesis: {total}). "
               f"Stage figure (a–f): trials {', '.join(map(str, ks))} (thesis: 18–20 s, 318–320 s, 998–1000 s, "
               "scaled by fraction of the run); end-effector density of the previous 10 trials. "
               "MAE figure (g): MAE per trial of each joint and their mean; shaded: the table windows "
               f"({', '.join(f'{a}–{b}' for a, b in wins)}); {baseline_text(base)}.")
    return Figure(files, caption, table, notes, stages.stage_checks(run, task, base, wins), conv)


@figure("fig2_6", "Circle learnt from scratch: stages and MAE per joint (Fig. 2.6, Table 2.3)",
        studies=("learn_circle", "baselines_circle"))
def fig2_6(runs: RunSet, stem: Path) -> Figure:
    """The circle learnt from scratch (Fig. 2.6, Table 2.3)."""
    return _trajectory_learning(runs, stem, "circle", "2.6", "learn_circle")


@figure("fig2_7", "Eight learnt from scratch: stages and MAE per joint (Fig. 2.7, Table 2.3)",
        studies=("learn_eight", "baselines_eight"))
def fig2_7(runs: RunSet, stem: Path) -> Figure:
    """The eight learnt from scratch (Fig. 2.7, Table 2.3)."""
    return _trajectory_learning(runs, stem, "eight", "2.7", "learn_eight")


@figure("table2_3", "Tables 2.3 / 2.4: MAE per learning stage beside the thesis",
        studies=("learn_circle", "learn_eight", "learn_reaching", "baselines_circle", "baselines_eight",
                 "baselines_reaching"))
def table2_3(runs: RunSet, stem: Path) -> Figure:
    """The thesis's stage windows (mean ± std) beside ours for every task learnt from scratch, as bars."""
    found = {task: from_scratch(runs, task, CH2_KERNEL_MS) for task in stages.PAPER_STAGES}
    found = {t: r for t, r in found.items() if r is not None}
    if not found:
        raise MissingRuns("no run of snn learning circle, eight or reaching from scratch (studies learn_circle, "
                          "learn_eight, learn_reaching)")
    fig, axes = plt.subplots(1, len(found), figsize=(4.6 * len(found), 3.8), squeeze=False)
    table = [["quantity", "paper", "cerebx"]]
    checks: list[Check] = []
    for ax, (task, run) in zip(axes[0], found.items(), strict=True):
        total, ref, factory = stages.PAPER_STAGES[task]
        base = baselines(runs, task)
        rows, wins = stages.stage_table(run, task, base)
        checks += stages.stage_checks(run, task, base, wins)
        table += [[f"{task}: {q}", p, c] for q, p, c in rows[1:]]
        x = np.arange(len(ref))
        ours = [run.mae[lo:hi] for lo, hi in wins]
        ax.bar(x - 0.2, [m for *_, m, _ in ref], 0.4, yerr=[sd for *_, sd in ref], capsize=3, color="0.6",
               label=f"thesis ({total} trials)")
        ax.bar(x + 0.2, [o.mean() for o in ours], 0.4, yerr=[o.std() for o in ours], capsize=3, color="C0",
               label=f"cerebx ({run.n_measured} trials)")
        ax.axhline(float(factory.split()[0]), color="0.4", ls="--", lw=1, label="factory position, thesis")
        for name, b in base:
            if name == "factory position":
                ax.axhline(b.mae.mean(), color="C2", ls="--", lw=1.2, label="factory position, cerebx")
        ax.set_xticks(x, [f"{a}–{b}\n[{lo}–{hi}]" if (lo, hi) != (a, b) else f"{a}–{b}"
                          for (a, b, *_), (lo, hi) in zip(ref, wins, strict=True)], fontsize=8)
        ax.set_xlabel("trials (thesis) [cerebx window]")
        ax.set_ylabel("position MAE (rad)")
        ax.set_title(TASK_NAMES[task])
        ax.grid(alpha=0.3, axis="y")
        ax.legend(fontsize=7)
    fig.suptitle("Thesis Tables 2.3 / 2.4 beside cerebx: MAE (mean ± std) per learning stage")
    fig.tight_layout()
    caption = ("Thesis Tables 2.3 (circle, eight) and 2.4 (reaching): the cerebellar controller's position MAE "
               "(mean ± std over the trials of each window) at the initial, intermediate and final stage of "
               "learning from scratch, beside the factory position controller. Runs shorter than the thesis's "
               "use the same fractions of their length (the window in brackets). Runs: "
               + ", ".join(f"{t} {short_path(r)}" for t, r in found.items()) + ".")
    notes = [f"{t}: no run learning from scratch" for t in stages.PAPER_STAGES if t not in found]
    conv = learnt(runs, [(t, r, LEARN_STUDY[t]) for t, r in found.items()], snn_rows)
    return Figure([save(fig, stem)], caption, table, notes, checks, conv)


def convergence_trial(mae: np.ndarray, tol: float = CONVERGENCE_TOL) -> tuple[int | None, int, float | None]:
    """(first trial where the trailing running mean is within ``tol`` of the final level, window, level).

    Running mean over a trailing window of max(5, n/50) trials (10 of 500; at most n); the final level is
    the mean of the last 10 % of trials.
    """
    n = len(mae)
    level = final_mae(list(mae))
    w = max(1, min(n, max(5, n // 50)))
    if level is None:
        return None, w, None
    run_mean = np.convolve(mae, np.ones(w) / w, mode="valid")
    hits = np.nonzero(run_mean <= (1 + tol) * level)[0]
    return (int(hits[0]) + w - 1 if hits.size else None), w, level


@figure("fig3_3", "Trajectory learning convergence curves (Fig. 3.3)",
        studies=("learn_circle_ch3", "learn_inclined_circle", "learn_circle_eight"))
def fig3_3(runs: RunSet, stem: Path) -> Figure:
    """MAE per trial, its running mean and the stabilization trial of each chapter 3 task."""
    found = {task: from_scratch(runs, task) for task in CH3_TASKS}
    if not any(found.values()):
        raise MissingRuns("no snn runs learning circle / inclined_circle / circle_eight from scratch "
                          "(studies learn_circle_ch3, learn_inclined_circle, learn_circle_eight)")
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.3))
    table = [["quantity", "paper", "cerebx"]]
    notes, used = [], []
    conv = learnt(runs, [(TASK_NAMES[t], r, CH3_STUDY[t]) for t, r in found.items()])
    for ax, letter, task in zip(axes, "ABC", CH3_TASKS, strict=True):
        ax.set_title(f"{letter}  {TASK_NAMES[task]}", loc="left", fontweight="bold", fontsize=10, pad=30)
        run = found[task]
        if run is None:
            notes.append(f"no {task} run of snn learning from scratch: panel {letter} empty")
            ax.text(0.5, 0.5, "no run", transform=ax.transAxes, ha="center")
            continue
        mae, period = run.mae, run.period_s
        k, w, level = convergence_trial(mae)
        ax.plot(mae, color="0.6", lw=0.7, label="MAE per trial")
        ax.plot(np.arange(w - 1, len(mae)), np.convolve(mae, np.ones(w) / w, mode="valid"), "C0", lw=1.5,
                label=f"running mean ({w} trials)")
        if level is not None:
            ax.axhline(level, color="C3", ls="--", lw=1, label="final level (last 10 %)")
        if k is not None:
            ax.axvline(k, color="C2", lw=1.2, label=f"within {CONVERGENCE_TOL:.0%}: trial {k}")
        ax.set_yscale("log")
        ax.set_xlabel("trial")
        ax.set_ylabel("position MAE (rad)")
        ax.secondary_xaxis("top", functions=(lambda x, p=period: x * p, lambda s, p=period: s / p)).set_xlabel(
            "time (s)", fontsize=8)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7)
        name, secs = TASK_NAMES[task], 500 * (4 if task == "circle_eight" else 2)
        table += [[f"{name}: MAE first 10 trials (rad)", "figure only", f"{mae[:10].mean():.3f}"],
                  [f"{name}: MAE last 10 trials (rad)", "figure only", f"{mae[-10:].mean():.3f}"],
                  [f"{name}: trials to stabilize", f"about 500 trials ({secs} s)",
                   "not reached" if k is None else f"{k} ({k * period:.0f} s) of {len(mae)}"]]
        used.append(f"{letter}: {short_path(run)}, {len(mae)} trials of {period:.0f} s")
    fig.tight_layout()
    checks = [Check(f"{c.label}: the MAE levels off (plateau test)", c.level, c.numbers())
              for c in conv.curves]
    caption = ("Thesis Fig. 3.3: MAE per trial of the snn controller learning from scratch (thesis: stabilization "
               f"after about 500 trials). Runs: {'; '.join(used)}. Stabilization trial: the first trial where the "
               f"trailing running mean (max(5, n/50) trials) is within {CONVERGENCE_TOL:.0%} of the final level "
               "(mean of the last 10 % of trials).")
    return Figure([save(fig, stem)], caption, table, notes, checks, conv)

