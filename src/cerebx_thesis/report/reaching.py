"""Reaching learnt from scratch: thesis Fig. 2.9 (end-effector paths and speed profiles at three stages,
MAE per joint) with the reaching rows of Table 2.4."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from cerebx.report.api import Figure, MissingRuns, Run, RunSet, figure, panel_letter, save  # noqa: E402
from cerebx_thesis.report import stages  # noqa: E402
from cerebx_thesis.report.common import (  # noqa: E402
    CH2_KERNEL_MS,
    LEARN_STUDY,
    baseline_text,
    baselines,
    from_scratch,
    learnt,
    seed_runs,
    short_path,
    snn_rows,
    trial_range,
)

# Fig. 2.9: stages at t1 = 160 s, t2 = 600 s, t3 = 2000 s of 1000 trials; density of the last 80 trials
REACH_STAGES = (0.08, 0.3, 1.0)
REACH_DENSITY = 0.08


def reach_target(ee_des: np.ndarray, n_targets: int) -> int:
    """Target index from the direction of ee_des at its farthest point from the first sample
    (targets at angles pi + 2 pi k / n in the xy plane, as the reaching task lays them out)."""
    d = ee_des[:, :2] - ee_des[0, :2]
    far = d[int(np.argmax(np.hypot(d[:, 0], d[:, 1])))]
    step = 2 * np.pi / n_targets
    return int(round((np.arctan2(far[1], far[0]) - np.pi) / step)) % n_targets


def _label_target(label: str | None) -> int | None:
    """The target index in a trial label such as ``reaching:target3``, None without one."""
    if label and "target" in label:
        tail = label.rsplit("target", 1)[1]
        return int(tail) if tail.isdigit() else None
    return None


def _reach_window(run: Run, first: int, stop: int, n_targets: int) -> dict[int, dict[str, np.ndarray]]:
    """Per trial in [first, stop): t, ee, ee_des and its target (label if logged, else derived)."""
    period = run.period_s
    rows: dict[int, dict[str, list]] = {}
    labels: dict[int, int | None] = {}
    for topic, t, msg in run.messages(["/control", "/trial_metrics"], first * period, stop * period + period / 2):
        k = int(msg.get("trial", -1))
        if not first <= k < stop:
            continue
        if topic == "/trial_metrics":
            labels[k] = _label_target(msg.get("label"))
        elif "ee" in msg and "ee_des" in msg:
            row = rows.setdefault(k, {"t": [], "ee": [], "ee_des": []})
            row["t"].append(t - k * period)
            row["ee"].append(msg["ee"])
            row["ee_des"].append(msg["ee_des"])
    out = {}
    for k, row in rows.items():
        arr = {key: np.asarray(v, dtype=float) for key, v in row.items()}
        target = labels.get(k)
        arr["target"] = np.asarray(reach_target(arr["ee_des"], n_targets) if target is None else target)
        out[k] = arr
    return out


def _speed(tr: dict[str, np.ndarray], key: str) -> np.ndarray:
    """End-effector speed (m/s) along ``key`` (ee or ee_des) of one trial."""
    if len(tr["t"]) < 2:
        return np.zeros(len(tr["t"]))
    return np.linalg.norm(np.gradient(tr[key], tr["t"], axis=0), axis=1)


@figure("fig2_9", "Reaching learnt from scratch: paths, speed profiles and MAE (Fig. 2.9, Table 2.4)",
        studies=("learn_reaching", "baselines_reaching"))
def fig2_9(runs: RunSet, stem: Path) -> Figure:
    """Paths and speed profiles at three stages, and MAE per joint, of the reaching run."""
    run = from_scratch(runs, "reaching", CH2_KERNEL_MS)
    if run is None:
        raise MissingRuns("no reaching run of snn learning from scratch (study learn_reaching)")
    n, n_targets = run.trials, int(run.get("task.targets", 8))
    base = baselines(runs, "reaching")
    seeds = seed_runs(runs, lambda rs: from_scratch(rs, "reaching", CH2_KERNEL_MS), like=run)
    table, wins, intervals = stages.stage_table(run, "reaching", base, seeds)
    ends = sorted({max(1, int(round(f * n))) for f in REACH_STAGES})
    width = max(1, int(round(REACH_DENSITY * n)))
    windows = [_reach_window(run, max(0, e - width), e, n_targets) for e in ends]
    last = [{int(tr["target"]): k for k, tr in sorted(w.items())} for w in windows]
    # the starred target: performed in the last window and in as many of the others as possible
    star = min(last[-1], key=lambda g: (-sum(g in d for d in last), g)) if last and last[-1] else None
    fig = plt.figure(figsize=(4.4 * len(ends), 11.5))
    gs = fig.add_gridspec(3, len(ends), height_ratios=[1.25, 0.8, 1.0])
    hsv = plt.get_cmap("hsv")

    def colors(target: int):
        return hsv(0.9 * target / n_targets)
    for c, (e, w, lastk) in enumerate(zip(ends, windows, last, strict=True)):
        ax = fig.add_subplot(gs[0, c])
        if w:
            pts = np.concatenate([tr["ee"] for tr in w.values()])
            stages.density(ax, pts[:, 0], pts[:, 1], bins=70, cmap="Greys", alpha=0.6)
        for target, k in sorted(lastk.items()):
            tr = w[k]
            ax.plot(tr["ee_des"][:, 0], tr["ee_des"][:, 1], "k--", lw=0.7)
            ax.plot(tr["ee"][:, 0], tr["ee"][:, 1], color=colors(target), lw=1.2, label=f"target {target}")
            if target == star:
                far = tr["ee_des"][int(np.argmax(np.linalg.norm(tr["ee_des"] - tr["ee_des"][0], axis=1)))]
                ax.plot(far[0], far[1], "k*", ms=12)
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("x (m)")
        ax.set_ylabel("y (m)")
        t_end = e * run.period_s
        ax.set_title(f"before t = {t_end:.0f} s (trial {e}); density: {trial_range(max(0, e - width), e)}",
                     fontsize=9)
        panel_letter(ax, "abc"[c])
        ax.legend(fontsize=6, ncol=2, loc="upper right")
        ax = fig.add_subplot(gs[1, c])
        if star in lastk:
            tr = w[lastk[star]]
            ax.plot(tr["t"], _speed(tr, "ee_des"), "k--", lw=1, label="desired")
            ax.plot(tr["t"], _speed(tr, "ee"), color=colors(star), lw=1.4, label="actual")
            ax.set_title(f"target {star} (*), trial {lastk[star]}", fontsize=9)
            ax.legend(fontsize=7)
        else:
            ax.text(0.5, 0.5, f"target {star} not performed in this window", transform=ax.transAxes,
                    ha="center", fontsize=8)
        ax.set_xlabel("time in trial (s)")
        ax.set_ylabel("end-effector speed (m/s)")
        panel_letter(ax, "def"[c])
    ax = fig.add_subplot(gs[2, :])
    stages.mae_per_joint_axes(ax, run.summary, [b.summary for _, b in base], [name for name, _ in base], wins)
    ax.set_title(f"reaching / snn: MAE per joint, {n} trials (table windows shaded)", fontsize=10)
    panel_letter(ax, "g")
    fig.tight_layout()
    files = [save(fig, stem)]
    notes = []
    if star is None:
        notes.append("no trial in the last stage window: no speed profiles")
    if not base:
        notes.append("no reaching baseline runs (pd / position_factory without delay)")
    caption = (f"Thesis Fig. 2.9 (reaching, {n_targets} targets): run {short_path(run)}, {n} trials of "
               f"{run.period_s:.0f} s (thesis: 1000). (a–c) end-effector paths in the xy plane: the last trial of "
               f"each target before trials {', '.join(map(str, ends))} (thesis t1 = 160 s, t2 = 600 s, t3 = 2000 s, "
               f"scaled by fraction of the run), over the density of the last {width} trials (thesis: 80). "
               f"(d–f) speed profile of the starred target at those stages. (g) MAE per trial of each joint and "
               f"their mean; {baseline_text(base)}. Targets from /trial_metrics labels, else from the direction "
               "of the farthest desired point."
               + (f" Stage MAE over {len(seeds)} independently learned seeds: mean and 95 % interval in the table; "
                  "the checks decide on the mean over seeds." if len(seeds) > 1 else ""))
    conv = learnt(runs, [("reaching", run, LEARN_STUDY["reaching"])], snn_rows)
    checks = stages.stage_checks("reaching", stages.seed_means(intervals), base)
    return Figure(files, caption, table, notes, checks, conv, intervals)
