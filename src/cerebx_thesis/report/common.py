"""What the thesis's figure families share: its task names and PF-PC kernels, the choice of runs by
content, the labels captions give runs, and the finishing of a multi-panel figure.

Runs are chosen by content:

- learning from scratch: snn controller, no delay, no ``init_from``, no plant events, one PF-PC kernel
  peaking at the chapter's kernel (this keeps the multikernel and kernel-sweep runs out);
- the factory position controller: ``Run.is_factory_position``;
- the PD baseline: controller preset ``pd`` (the launch gains), no delay;
- chapter 3's delay figures: circle runs without plant events, those from a learned state first.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import numpy as np

from cerebx.report.api import (
    Convergence,
    Run,
    RunSet,
    learning_convergence,
    panel_letter,
    save,
    study_plateau,
)

THESIS_KERNEL_MS = 150.0  # chapter 3 ([D]) kernel peak
CH2_KERNEL_MS = 100.0  # chapter 2 ([B]) kernel peak
TASK_NAMES = {"circle": "horizontal circle", "inclined_circle": "inclined circle",
              "circle_eight": "circle-Lissajous sequence", "eight": "eight", "reaching": "reaching"}
CH3_TASKS = ("circle", "inclined_circle", "circle_eight")
HEADER = ["quantity", "paper", "cerebx"]
# the study whose runs learn each task from scratch, with chapter 2's network (LEARN_STUDY), chapter 3's
# (CH3_STUDY) or the ANN (ANN_STUDY): its full profile has the trials where the thesis's shape appears
LEARN_STUDY = {"circle": "learn_circle", "eight": "learn_eight", "reaching": "learn_reaching"}
CH3_STUDY = {"circle": "learn_circle_ch3", "inclined_circle": "learn_inclined_circle",
             "circle_eight": "learn_circle_eight"}
ANN_STUDY = {"circle": "learn_ann_circle", "inclined_circle": "learn_ann_inclined_circle",
             "circle_eight": "learn_ann_circle_eight"}


def from_scratch(runs: RunSet, task: str, kernel_ms: float = THESIS_KERNEL_MS) -> Run | None:
    """The longest snn run learning ``task`` from scratch without delay, with the kernel peaking at
    ``kernel_ms`` (the chapter's network)."""
    return runs.where(lambda r: r.learned_from is None and not r.events and r.trials > 0
                      and r.kernel_peaks_ms == [kernel_ms],
                      task=task, controller="snn", delay="none").best()


def learnt(runs: RunSet, curves: Iterable[tuple[str, Run | None, str]],
           rows: Callable[[str], bool] | None = None, own: bool = False) -> Convergence:
    """The convergence of the learning behind (label, run, study that learns it) triples (runs that are None
    left out): the plateau test of each run's learning curve, or of the curve of the run whose state it
    started from (``own``: of the run itself), against the full profile's trials of that study (where the
    thesis's shape appears)."""
    return learning_convergence([(label, r, study_plateau(study)) for label, r, study in curves if r is not None],
                                runs, rows, own)


def seed_runs(runs: RunSet, pick: Callable[[RunSet], Run | None], like: Run | None = None) -> list[Run]:
    """The run ``pick`` chooses among each seed's runs, lowest seed first (a study learned from several seeds:
    one run per seed); with ``like``, only those with as many trials as it (a seed still learning is left out)."""
    out = [r for rs in runs.seeds().values() if (r := pick(rs)) is not None]
    return [r for r in out if like is None or r.trials == like.trials]


def snn_rows(quantity: str) -> bool:
    """The table rows of the SNN (whose numbers depend on its learning; not those of the baselines)."""
    return "SNN" in quantity


def baselines(runs: RunSet, task: str) -> list[tuple[str, Run]]:
    """(label, run) of the PD and factory-position baselines on ``task`` without delay, those present."""
    none = runs.where(lambda r: r.trials > 0 and not r.events, task=task, delay="none")
    found = [("PD", none.where(controller="pd", controller_preset="pd").best()),
             ("factory position", none.where(lambda r: r.is_factory_position).best())]
    return [(name, r) for name, r in found if r is not None]


def baseline_text(base: list[tuple[str, Run]]) -> str:
    """Caption text naming the baselines drawn as dashed lines."""
    if not base:
        return "no baseline run"
    return "dashed: mean MAE of " + ", ".join(f"{name} ({b.n_measured} trials, {short_path(b)})" for name, b in base)


def plain_circle(r: Run) -> bool:
    """A circle run with logged trials and no perturbation events."""
    return r.task == "circle" and not r.events and r.mae.size > 0


def prefer_learned(rs: RunSet) -> Run | None:
    """The best run, among those started from a learned state when there are any."""
    learned = rs.where(lambda r: r.learned_from is not None)
    return (learned or rs).best()


def delay_sweep(runs: RunSet, controller: str, multikernel: bool = False) -> tuple[dict[float, Run], list[str]]:
    """Best circle run per constant round-trip delay of one controller kind (learned-state runs first), all
    started from the same state (the one most delays used); a note for each delay left out for that."""
    def ok(r: Run) -> bool:
        if not (plain_circle(r) and r.delay == "constant" and r.controller == controller
                and r.delay_total_ms is not None):
            return False
        return controller != "snn" or (len(r.kernel_peaks_ms) > 1) == multikernel and bool(r.kernel_peaks_ms)
    picked = runs.where(ok).by(lambda r: r.delay_total_ms, prefer_learned)
    origins = Counter(r.learned_from for r in picked.values())
    main = max(origins, key=lambda o: (origins[o], sum(r.trials for r in picked.values() if r.learned_from == o)),
               default=None)
    notes = [f"{controller} δT = {d:g} ms left out: its run started from {r.learned_from}, the others from {main}"
             for d, r in picked.items() if r.learned_from != main]
    return {d: r for d, r in picked.items() if r.learned_from == main}, notes


def reference_run(runs: RunSet, controller: str) -> Run | None:
    """A no-delay circle run of the PD (the fig3_4_pd δT = 0 run first) or factory position controller."""
    rs = runs.where(lambda r: plain_circle(r) and r.controller == controller and r.delay_total_ms == 0)
    if controller == "position":
        rs = rs.where(lambda r: r.is_factory_position) or rs
    if controller == "pd":  # the launch gains (preset pd), and the δT = 0 run of the fig3_4 sweep first
        rs = rs.where(lambda r: r.controller_preset == "pd") or rs
        rs = rs.where(lambda r: r.delay == "constant") or rs
    return rs.best()


def short_path(r: Run | str) -> str:
    """The run's folder as ``study/run``, for captions."""
    d = Path(r) if isinstance(r, str) else r.dir
    return f"{d.parent.name}/{d.name}"


def origin(run: Run) -> str:
    """Where the run started: the learned state it was loaded from, or from scratch."""
    return f"learned state ({'/'.join(Path(run.learned_from).parts[-2:])})" if run.learned_from else "from scratch"


def trial_range(a: int, b: int) -> str:
    """Trials [a, b) as text."""
    return f"trial {a}" if b - a == 1 else f"trials {a}–{b - 1}"


def trial_counts(rs: Iterable[Run]) -> str:
    """The runs' measured trial counts as text (one count, or the range)."""
    n = sorted({r.n_measured for r in rs})
    if not n:
        return "no trials"
    return f"{n[0]} trials" if len(n) == 1 else f"{n[0]}–{n[-1]} trials"


def mean_and_std(values: np.ndarray) -> tuple[float, float]:
    """Mean and standard deviation as numbers (NaN for no values), for error bars."""
    return (float(np.mean(values)), float(np.std(values))) if len(values) else (np.nan, np.nan)


def legend(ax, size: int = 8) -> None:
    """A legend, when the axes has labelled artists."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=size)


def finish(fig, stem: Path, panels: dict[str, Any], legend_size: int = 8, others: Iterable[Any] = ()) -> Path:
    """Grid and legend on every axes, a letter on each of ``panels``; save PNG + SVG."""
    for s, ax in panels.items():
        panel_letter(ax, s)
    for ax in (*panels.values(), *others):
        ax.grid(alpha=0.3)
        legend(ax, legend_size)
    fig.tight_layout()
    return save(fig, stem)
