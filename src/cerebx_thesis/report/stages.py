"""The learning process at an initial, intermediate and final stage, shared by the learning-from-scratch
and reaching figures: thesis Fig. 2.6 / 2.7 a-f and g, drawn from a run's MCAP (time-windowed reads
through the file's index), and the stage windows of Tables 2.3 / 2.4 beside the run's. Where the task was
learned from several seeds, each stage's mean MAE is also given over the seeds (mean and 95 % interval)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import PowerNorm  # noqa: E402

from cerebx.api import read_messages  # noqa: E402
from cerebx.report.api import (  # noqa: E402
    Check,  # noqa: E402
    Interval,
    Run,  # noqa: E402
    interval,
    mean_std,
    panel_letter,
    save,
    with_intervals,
)

# thesis stages for a 500-trial run: t1 = 18-20 s, t2 = 318-320 s, t3 = 998-1000 s
STAGE_FRACTIONS = (0.02, 0.32, 1.0)
# Tables 2.3 / 2.4: thesis run length, snn windows (start, stop, mean, std), factory position MAE as printed
PAPER_STAGES: dict[str, tuple[int, list[tuple[int, int, float, float]], str]] = {
    "circle": (500, [(0, 100, 0.115, 0.055), (100, 200, 0.036, 0.013), (400, 500, 0.019, 0.003)], "0.077 ± 0.0004"),
    "eight": (500, [(0, 100, 0.111, 0.034), (100, 200, 0.046, 0.013), (400, 500, 0.017, 0.003)], "0.063 ± 0.0003"),
    "reaching": (1000, [(0, 100, 0.155, 0.050), (300, 400, 0.043, 0.024), (900, 1000, 0.019, 0.006)],
                 "0.026 ± 0.006"),
}


def stage_trials(n_trials: int) -> list[int]:
    """The trials drawn as the three stages: the thesis's stage times as fractions of the run."""
    return sorted({max(0, min(n_trials - 1, int(round(f * n_trials)) - 1)) for f in STAGE_FRACTIONS})


ALL_TOPICS = ("/joint_states/actual", "/joint_states/desired", "/spikes/dcn", "/control")


def _window(run_dir: Path, t0: float, t1: float, topics: tuple[str, ...] = ALL_TOPICS) -> dict[str, Any]:
    """Joint states, torques, DCN spikes and end-effector positions between t0 and t1 (s)."""
    out: dict[str, list] = {"t": [], "q": [], "q_des": [], "tau": [], "spk_t": [], "spk_i": [], "ee": [],
                            "ee_des": []}
    lo, hi = int(t0 * 1e9), int(t1 * 1e9)
    for topic, t, msg in read_messages(run_dir, list(topics), start_ns=lo, end_ns=hi):
        if topic == "/joint_states/actual":
            out["t"].append(t / 1e9)
            out["q"].append([j["position"] for j in msg["joints"]])
            out["tau"].append([j["effort"] for j in msg["joints"]])
        elif topic == "/joint_states/desired":
            out["q_des"].append([j["position"] for j in msg["joints"]])
        elif topic == "/spikes/dcn":
            out["spk_t"] += [t / 1e9] * len(msg["indices"])
            out["spk_i"] += msg["indices"]
        elif "ee" in msg:
            out["ee"].append(msg["ee"])
            if "ee_des" in msg:
                out["ee_des"].append(msg["ee_des"])
    return {k: np.asarray(v) for k, v in out.items()}


def density(ax, x: np.ndarray, y: np.ndarray, bins: int = 60, cmap: str = "Blues", alpha: float = 1.0) -> None:
    """2-D histogram of (x, y) as one raster image, square-root colour scale, empty bins blank."""
    if not len(x):
        return
    h, xe, ye = np.histogram2d(x, y, bins=bins)
    ax.imshow(np.ma.masked_equal(h.T, 0), origin="lower", extent=(xe[0], xe[-1], ye[0], ye[-1]), cmap=cmap,
              norm=PowerNorm(0.5), alpha=alpha, aspect="auto", interpolation="nearest")


def stages_figure(run_dir: Path, summary: dict, out: Path) -> Path:
    """Thesis Fig. 2.6 / 2.7 a-f: DCN spikes, torques, joint and end-effector paths at three stages."""
    n = summary.get("trials_completed") or 0
    if n < 1:
        raise ValueError(f"{run_dir}: no completed trial for the stage figure")
    period = summary["sim_seconds"] / n
    trials = stage_trials(n)
    fig, axes = plt.subplots(4, len(trials), figsize=(4.2 * len(trials), 11), squeeze=False)
    for c, k in enumerate(trials):
        t0, t1 = k * period, (k + 1) * period
        w = _window(run_dir, t0, t1)
        ax = axes[0, c]
        if w["spk_t"].size:
            ax.plot(w["spk_t"], w["spk_i"], "k.", ms=0.8, mew=0)
        ax.set_title(f"trial {k} ({t0:.0f}-{t1:.0f} s)")
        ax.set_ylabel("DCN neuron index")
        panel_letter(ax, "abc"[c])
        ax = axes[1, c]
        if w["tau"].size:
            for j in range(w["tau"].shape[1]):
                ax.plot(w["t"], w["tau"][:, j], lw=0.8, label=f"joint {j + 1}")
            ax.legend(fontsize=6, ncol=3, loc="lower left")
        ax.set_ylabel("torque (N·m)")
        ax = axes[2, c]
        if w["q"].size:
            for j in range(w["q"].shape[1]):
                ax.plot(w["t"], w["q_des"][:, j], "k--", lw=0.7)
                ax.plot(w["t"], w["q"][:, j], lw=1.0)
        ax.set_ylabel("joints (rad): desired -- / actual")
        ax.set_xlabel("t (s)")
        ax = axes[3, c]
        hist = (_window(run_dir, max(0.0, t0 - 10 * period), t0, ("/control",))["ee"] if k >= 1
                else np.zeros((0, 3)))
        if hist.size:
            density(ax, hist[:, 0], hist[:, 1])
        if w["ee_des"].size:
            ax.plot(w["ee_des"][:, 0], w["ee_des"][:, 1], "k--", lw=1, label="desired")
        if w["ee"].size:
            ax.plot(w["ee"][:, 0], w["ee"][:, 1], "C3", lw=1, label="actual")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        ax.legend(fontsize=7, loc="upper right")
        panel_letter(ax, "def"[c])
    fig.suptitle(f"{summary['task']} / {summary['controller']}: initial, intermediate and final stage "
                 "(end-effector: previous 10 trials as density)", fontsize=11)
    fig.tight_layout()
    return save(fig, out)


def _baseline_label(b: dict) -> str:
    """A baseline's controller preset (else its controller kind), for the legend."""
    return (b.get("presets") or {}).get("controller", b["controller"])


def mae_per_joint_axes(ax, summary: dict, baselines: list[dict], labels: list[str] | None = None,
                       windows: list[tuple[int, int]] | None = None) -> None:
    """MAE per trial of each joint and their mean, each baseline's mean MAE over its trials as a line,
    and the table windows shaded."""
    per_joint = np.asarray(summary.get("mae_per_joint_per_trial") or [])
    if per_joint.size:
        thin = len(per_joint) > 300
        for j in range(per_joint.shape[1]):
            ax.plot(per_joint[:, j], lw=0.5 if thin else 0.7, alpha=0.45 if thin else 0.7, label=f"joint {j + 1}")
        ax.plot(per_joint.mean(1), "k", lw=1.6, label="mean of joints")
    for i, b in enumerate(baselines):
        name = labels[i] if labels else _baseline_label(b)
        level = float(np.mean(b.get("mae_per_trial") or [b["final_mae"]]))
        ax.axhline(level, ls="--", lw=1.2, color=f"C{(i + 6) % 10}", label=f"{name} baseline")
    for i, (a, b) in enumerate(windows or []):
        ax.axvspan(a - 0.5, b - 0.5, color="0.8" if i % 2 else "0.88", alpha=0.6, lw=0)
        ax.annotate(f"{a}–{b}", ((a + b - 1) / 2, 1), xycoords=("data", "axes fraction"), xytext=(0, -10),
                    textcoords="offset points", ha="center", fontsize=7, color="0.3")
    ax.set_yscale("log")
    ax.set_xlabel("trial")
    ax.set_ylabel("position MAE (rad)")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, ncol=2, loc="lower left")


def mae_per_joint_figure(summary: dict, baselines: list[dict], out: Path, labels: list[str] | None = None,
                         windows: list[tuple[int, int]] | None = None) -> Path:
    """Thesis Fig. 2.6 g / 2.7 g: MAE per trial of each joint and their mean, beside baselines."""
    fig, ax = plt.subplots(figsize=(7.5, 4))
    mae_per_joint_axes(ax, summary, baselines, labels, windows)
    ax.set_title(f"{summary['task']} / {summary['controller']}: MAE per joint"
                 + (" (table windows shaded)" if windows else ""))
    panel_letter(ax, "g")
    fig.tight_layout()
    return save(fig, out)


def scaled_windows(n: int, total: int, windows: list[tuple[int, int, float, float]]) -> list[tuple[int, int]]:
    """The thesis trial windows, scaled by n / total for runs shorter than the thesis's (at least 1 trial)."""
    f = min(1.0, n / total)
    out = []
    for a, b, _, _ in windows:
        lo = min(int(round(a * f)), n - 1)
        out.append((lo, max(lo + 1, int(round(b * f)))))
    return out


def stage_slices(run: Run, task: str) -> list[np.ndarray]:
    """The run's MAE per trial in each stage window of Table 2.3 / 2.4 for ``task`` (the thesis's windows,
    scaled to the run's length)."""
    total, ref, _ = PAPER_STAGES[task]
    return [run.mae[lo:hi] for lo, hi in scaled_windows(run.trials, total, ref)]


def stage_means(run: Run, task: str) -> list[float]:
    """The run's mean MAE in each stage window: the headline numbers of Table 2.3 / 2.4, one seed's."""
    return [float(m.mean()) for m in stage_slices(run, task)]


def stage_intervals(seeds: list[Run], task: str) -> list[Interval]:
    """Each stage's mean MAE over the seeds' runs (one run per seed), with the thesis's mean."""
    _, ref, _ = PAPER_STAGES[task]
    per_seed = [stage_means(r, task) for r in seeds]
    return [interval([v[i] for v in per_seed], paper=m) for i, (*_, m, _) in enumerate(ref)]


def stage_table(run: Run, task: str, base: list[tuple[str, Run]], seeds: list[Run] | None = None
                ) -> tuple[list[list[str]], list[tuple[int, int]], dict[str, Interval]]:
    """Rows of Table 2.3 / 2.4 for ``task`` beside ours, the windows used, and each stage's interval over
    ``seeds`` (one run of each seed; default: ``run`` alone) keyed by its row's quantity."""
    total, ref, factory = PAPER_STAGES[task]
    wins = scaled_windows(run.trials, total, ref)
    rows = [["quantity", "paper", "cerebx"]]
    intervals: dict[str, Interval] = {}
    for (a, b, m, s), (lo, hi), mae, iv in zip(ref, wins, stage_slices(run, task),
                                               stage_intervals(seeds or [run], task), strict=True):
        ours = f"trials {lo}–{hi}" if hi - lo > 1 else f"trial {lo}"
        used = "" if (lo, hi) == (a, b) else f" [cerebx: {ours} of {run.trials}]"
        quantity = f"SNN MAE (rad), trials {a}–{b}{used}"
        rows.append([quantity, f"{m:.3f} ± {s:.3f}", mean_std(mae)])
        intervals[quantity] = iv
    for name, b in base:
        paper = factory if name == "factory position" else "not in the thesis table"
        nd = 4 if name == "factory position" else 3
        rows.append([f"{name} MAE (rad), all trials [cerebx: {b.n_measured} trials]", paper, mean_std(b.mae, nd)])
    if not any(name == "factory position" for name, _ in base):
        rows.append(["factory position MAE (rad), all trials", factory, "not run"])
    return with_intervals(rows, intervals), wins, intervals


def stage_checks(task: str, means: list[float], base: list[tuple[str, Run]]) -> list[Check]:
    """The shapes of Tables 2.3 / 2.4 for ``task`` on its stage means (one seed's, or the mean over seeds): the
    SNN's MAE falls from stage to stage and its final stage is below the factory position controller's."""
    checks = [Check(f"{task}: SNN MAE falls from stage to stage", all(a > b for a, b in zip(means, means[1:])),
                    " → ".join(f"{m:.3f}" for m in means) + " rad")]
    factory = next((b for name, b in base if name == "factory position"), None)
    claim = (f"{task}: SNN MAE of the final stage below the factory position controller's (thesis: "
             f"{PAPER_STAGES[task][1][-1][2]:.3f} vs {PAPER_STAGES[task][2].split()[0]} rad)")
    if factory is None or not factory.mae.size:
        checks.append(Check(claim, None, "no factory position run"))
    else:
        f = float(factory.mae.mean())
        checks.append(Check(claim, means[-1] < f, f"{means[-1]:.3f} vs {f:.3f} rad"))
    return checks


def seed_means(intervals: dict[str, Interval]) -> list[float]:
    """The stage means the checks decide on: each stage's mean over the seeds (the table's order)."""
    return [iv.mean for iv in intervals.values()]
