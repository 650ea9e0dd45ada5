"""Figures drawn from run folders (summary.json and run.mcap), never from in-memory state."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from cerebx.recording.reader import read_messages  # noqa: E402
from cerebx.report.plot import save  # noqa: E402


def _label(s: dict[str, Any]) -> str:
    p = s.get("presets") or {}
    return (f"{p.get('controller', s['controller'])} · {p.get('plant', s['plant'])} · "
            f"delay {p.get('delay', s['delay'])} · seed {s['seed']}")


def learning_curves(runs: list[tuple[Path, dict]], task: str, out: Path) -> Path:
    """MAE per trial for every run of one task."""
    fig, ax = plt.subplots(figsize=(7.5, 4))
    longest = max((len(s.get("mae_per_trial") or []) for _, s in runs), default=0)
    for i, (_, s) in enumerate(runs):
        mae = s.get("mae_per_trial") or []
        if len(mae) > max(1, longest // 4):
            ax.plot(np.arange(len(mae)), mae, lw=1.2, color=f"C{i % 10}", label=_label(s))
        elif mae:  # a short baseline run: its final error as a reference line
            ax.axhline(s.get("final_mae") or mae[-1], lw=1, ls="--", color=f"C{i % 10}",
                       label=f"{_label(s)} (final, {len(mae)} trials)")
    ax.set_xlabel("trial")
    ax.set_ylabel("position MAE (rad)")
    ax.set_yscale("log")
    ax.set_title(f"{task}: MAE per trial")
    ax.grid(alpha=0.3, which="both")
    if not ax.get_legend_handles_labels()[0]:  # no run has a trial's MAE (failed or damaged runs)
        ax.text(0.5, 0.5, "no completed trial", transform=ax.transAxes, ha="center", va="center")
    elif len(runs) <= 10:  # beyond that a legend hides the curves
        ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    return save(fig, out)


def joint_tracking(run_dir: Path, s: dict, out: Path) -> Path:
    """Desired vs actual joint positions over the last completed trial."""
    n_done = s.get("trials_completed") or 0
    period = s["sim_seconds"] / max(n_done, 1)
    t_start = int((s["sim_seconds"] - period) * 1e9)
    series: dict[str, list] = {"/joint_states/desired": [], "/joint_states/actual": []}
    times: list[float] = []
    names: list[str] = []
    for topic, t, msg in read_messages(run_dir, list(series), start_ns=t_start):
        series[topic].append([j["position"] for j in msg["joints"]])
        if topic == "/joint_states/actual":
            times.append(t / 1e9)
            names = names or [j["name"] for j in msg["joints"]]
    des, act = np.array(series["/joint_states/desired"]), np.array(series["/joint_states/actual"])
    n = min(len(des), len(act))
    if n == 0:
        raise ValueError(f"{run_dir}: no joint states recorded in the last trial")
    des, act, tt = des[:n], act[:n], np.array(times[:n])
    joints = des.shape[1]
    fig, axes = plt.subplots(1, joints, figsize=(2.2 * joints, 2.6), sharex=True)
    for j, ax in enumerate(np.atleast_1d(axes)):
        ax.plot(tt, des[:, j], "k--", lw=1, label="desired")
        ax.plot(tt, act[:, j], "C0", lw=1.2, label="actual")
        ax.set_title(names[j] if j < len(names) else f"joint {j + 1}", fontsize=9)
        ax.set_xlabel("t (s)", fontsize=8)
        ax.tick_params(labelsize=7)
    np.atleast_1d(axes)[0].set_ylabel("rad")
    np.atleast_1d(axes)[0].legend(fontsize=7)
    fig.suptitle(f"{s['task']} / {s['controller']}: last trial", fontsize=10)
    fig.tight_layout()
    return save(fig, out)

