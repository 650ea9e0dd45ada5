"""Learning from scratch: thesis Fig. 2.6 (circle) and 2.7 (eight) with their stages and MAE per joint,
Tables 2.3 / 2.4 (MAE per learning stage, as bars) and Fig. 3.3 (convergence curves of chapter 3's
network). The snn run of each task is the longest one learning from scratch with the chapter's kernel."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from cerebx.api import final_mae  # noqa: E402
from cerebx.report.api import (  # noqa: E402
    Check,
    Figure,
    Interval,  # noqa: E402
    MissingRuns,
    Run,
    RunSet,
    figure,
    save,  # noqa: E402
)
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
    seed_runs,
    short_path,
    snn_rows,
)

CONVERGENCE_TOL = 0.10


# §2.3.1: "the cerebellar controller needed about 300 trials (i.e., 600 seconds) to converge" (circle)
PAPER_CONVERGED_TRIAL = {"circle": 300}
ABOUT = 0.5  # "about 300 trials": within ±50 % of it (constructed)
# §2.3.2: the eight's MAE at the initial stage (Fig. 2.7 a, t1 = 18-20 s) "was high (0.165 rad)"
PAPER_EIGHT_INITIAL = 0.165


def seed_stage_runs(runs: RunSet, task: str, run: Run) -> list[Run]:
    """One run of each seed learning ``task`` from scratch with chapter 2's kernel, as long as ``run``."""
    return seed_runs(runs, lambda rs: from_scratch(rs, task, CH2_KERNEL_MS), like=run)


def _trajectory_learning(runs: RunSet, stem: Path, task: str, fig_no: str, study: str) -> Figure:
    """Fig. 2.6 / 2.7: the stage figure and the MAE-per-joint figure of ``task``, with Table 2.3's rows."""
    run = from_scratch(runs, task, CH2_KERNEL_MS)
    if run is None:
        raise MissingRuns(f"no {task} run of snn learning from scratch (study {study})")
    base = baselines(runs, task)
    seeds = seed_stage_runs(runs, task, run)
    table, wins, intervals = stages.stage_table(run, task, base, seeds)
    files = [stages.stages_figure(run.dir, run.summary, stem.with_name(stem.name + "_stages")),
             stages.mae_per_joint_figure(run.summary, [b.summary for _, b in base],
                                         stem.with_name(stem.name + "_mae"),
                                         labels=[name for name, _ in base], windows=wins)]
    ks = stages.stage_trials(run.trials)
    checks = stages.stage_checks(task, stages.seed_means(intervals), base)
    if task == "circle":
        checks.append(_converged_check(run, task))
    if task == "eight":
        table.append([f"SNN MAE at the initial stage, trial {ks[0]} (rad)", f"{PAPER_EIGHT_INITIAL:.3f}",
                      f"{run.mae[ks[0]]:.3f}"])
        checks.append(_initial_high_check(run, ks[0], base))
    notes = [] if base else [f"no {task} baseline runs (pd / position_factory without delay): MAE figure without "
                             "baselines"]
    conv = learnt(runs, [(task, run, LEARN_STUDY[task])], snn_rows)
    total = stages.PAPER_STAGES[task][0]
    caption = (f"Thesis Fig. {fig_no} ({TASK_NAMES[task]}): the snn controller learning from scratch, run "
               f"{short_path(run)} with {run.n_measured} trials of {run.period_s:.0f} s (thesis: {total}). "
               f"Stage figure (a–f): trials {', '.join(map(str, ks))} (thesis: 18–20 s, 318–320 s, 998–1000 s, "
               "scaled by fraction of the run); end-effector density of the previous 10 trials. "
               "MAE figure (g): MAE per trial of each joint and their mean; shaded: the table windows "
               f"({', '.join(f'{a}–{b}' for a, b in wins)}); {baseline_text(base)}."
               + _seeds_text(seeds))
    return Figure(files, caption, table, notes, checks, conv, intervals)


def _seeds_text(seeds: list[Run]) -> str:
    if len(seeds) < 2:
        return ""
    return (f" Stage MAE over {len(seeds)} independently learned seeds ({', '.join(str(r.seed) for r in seeds)}): "
            "mean and 95 % interval in the table; the checks decide on the mean over seeds; figures show the "
            "first seed.")


def _converged_check(run: Run, task: str) -> Check:
    """§2.3.1: the circle converged in about 300 trials (judged on runs at least as long as the thesis's)."""
    paper = PAPER_CONVERGED_TRIAL[task]
    lo, hi = paper * (1 - ABOUT), paper * (1 + ABOUT)
    claim = (f"{task}: the SNN converges in about {paper} trials (thesis; constructed: the first trial whose running "
             f"mean is within {CONVERGENCE_TOL:.0%} of the final level, between {lo:g} and {hi:g})")
    total = stages.PAPER_STAGES[task][0]
    if run.trials < total:
        return Check(claim, None, f"run of {run.trials} trials, shorter than the thesis's {total}")
    k, _, _ = convergence_trial(run.mae)
    return Check(claim, None if k is None else lo <= k <= hi, "not reached" if k is None else f"trial {k}")


def _initial_high_check(run: Run, k: int, base: list[tuple[str, Run]]) -> Check:
    """§2.3.2: the eight's MAE at the initial stage was high (0.165 rad): above the factory position
    controller's (0.063 rad in Table 2.3)."""
    factory = next((b for name, b in base if name == "factory position"), None)
    claim = (f"eight: MAE at the initial stage high, above the factory position controller's (thesis: "
             f"{PAPER_EIGHT_INITIAL} vs {stages.PAPER_STAGES['eight'][2].split()[0]} rad)")
    if factory is None or not factory.mae.size:
        return Check(claim, None, "no factory position run")
    f = float(factory.mae.mean())
    return Check(claim, bool(run.mae[k] > f), f"trial {k}: {run.mae[k]:.3f} vs {f:.3f} rad")


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
    intervals: dict[str, Interval] = {}
    seeds = {task: seed_stage_runs(runs, task, run) for task, run in found.items()}
    for ax, (task, run) in zip(axes[0], found.items(), strict=True):
        total, ref, factory = stages.PAPER_STAGES[task]
        base = baselines(runs, task)
        rows, wins, ivs = stages.stage_table(run, task, base, seeds[task])
        checks += stages.stage_checks(task, stages.seed_means(ivs), base)
        table += [[f"{task}: {q}", p, c] for q, p, c in rows[1:]]
        intervals |= {f"{task}: {q}": iv for q, iv in ivs.items()}
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
    checks += _across_tasks(found, seeds)
    fig.suptitle("Thesis Tables 2.3 / 2.4 beside cerebx: MAE (mean ± std) per learning stage")
    fig.tight_layout()
    n_seeds = max(len(v) for v in seeds.values())
    caption = ("Thesis Tables 2.3 (circle, eight) and 2.4 (reaching): the cerebellar controller's position MAE "
               "(mean ± std over the trials of each window) at the initial, intermediate and final stage of "
               "learning from scratch, beside the factory position controller. Runs shorter than the thesis's "
               "use the same fractions of their length (the window in brackets). Runs: "
               + ", ".join(f"{t} {short_path(r)}" for t, r in found.items()) + "."
               + (f" Each stage's mean over up to {n_seeds} independently learned seeds with its 95 % interval "
                  "follows in the table; the checks decide on the mean over seeds; the bars show the first seed."
                  if n_seeds > 1 else ""))
    notes = [f"{t}: no run learning from scratch" for t in stages.PAPER_STAGES if t not in found]
    conv = learnt(runs, [(t, r, LEARN_STUDY[t]) for t, r in found.items()], snn_rows)
    return Figure([save(fig, stem)], caption, table, notes, checks, conv, intervals)


def _final_std(seeds: list[Run], task: str) -> float:
    """The trial-to-trial std of the MAE in the final stage window, mean over the seeds."""
    return float(np.mean([stages.stage_slices(r, task)[-1].std() for r in seeds]))


def _across_tasks(found: dict[str, Run], seeds: dict[str, list[Run]]) -> list[Check]:
    """Tables 2.3 / 2.4 across tasks: the eight converges more slowly than the circle (its intermediate stage
    further from its initial one); reaching has the higher std between trials at the final stage and needs more
    trials to reach stability than the circle and the eight."""
    checks = []
    means = {t: np.mean([stages.stage_means(r, t) for r in seeds[t]], axis=0) for t in found}
    if {"circle", "eight"} <= set(found):
        paper = {t: stages.PAPER_STAGES[t][1][1][2] / stages.PAPER_STAGES[t][1][0][2] for t in ("circle", "eight")}
        ours = {t: float(means[t][1] / means[t][0]) for t in ("circle", "eight")}
        checks.append(Check("the eight converges more slowly than the circle: intermediate / initial stage MAE "
                            f"higher (thesis: {paper['eight']:.2f} vs {paper['circle']:.2f})",
                            ours["eight"] > ours["circle"],
                            f"eight {ours['eight']:.2f}, circle {ours['circle']:.2f}"))
    others = [t for t in ("circle", "eight") if t in found]
    if "reaching" in found and others:
        std = {t: _final_std(seeds[t], t) for t in found}
        checks.append(Check("reaching: higher std between trials at the final stage than " + " and ".join(others)
                            + " (thesis: 0.006 vs 0.003 rad)", all(std["reaching"] > std[t] for t in others),
                            ", ".join(f"{t} {v:.4f}" for t, v in std.items()) + " rad"))
        k = {t: convergence_trial(found[t].mae)[0] for t in found}
        claim = ("reaching needs more trials to reach stability than " + " and ".join(others) + " (constructed: "
                 f"the first trial whose running mean is within {CONVERGENCE_TOL:.0%} of the final level)")
        decided = None if any(v is None for v in k.values()) else all(k["reaching"] > k[t] for t in others)
        checks.append(Check(claim, decided, ", ".join(f"{t} trial {v}" for t, v in k.items())))
    return checks


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

