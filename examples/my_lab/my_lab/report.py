"""The lab's figure for `cerebx report`: how the torque rate limit costs the pendulum's tracking. Importing this
module registers the figure and the studies file whose runs it draws from."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from cerebx.report.api import Figure, MissingRuns, Run, RunSet, figure, panel_letter, save, studies

studies(Path(__file__).with_name("studies.yaml"))


def rate_limit(r: Run) -> float | None:
    """The run's torque rate limit (N·m/ms), read from its recorded configuration; None without one."""
    stages = r.get("robot") or []
    return next((s["max_rate_Nm_per_ms"] for s in stages if s.get("kind") == "rate_limit"), None)


@figure("my_lab_rate_limit", "Pendulum swings under a torque rate limit", studies=("my_lab_rate_limits",))
def draw_rate_limit(runs: RunSet, stem: Path) -> Figure:
    pendulum = runs.where(lambda r: r.get("plant.kind") == "pendulum" and r.task == "swing")
    by_limit = pendulum.by(rate_limit)  # one run per limit, selected by content, never by folder name
    if len(by_limit) < 2:
        raise MissingRuns("fewer than 2 rate limits of pendulum swings (study my_lab_rate_limits)")
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(11, 3.8))
    table = [["quantity", "expected", "cerebx"]]
    finals = []
    for i, (limit, r) in enumerate(by_limit.items()):
        first = r.control(["tau_controller", "tau_rate_cut"], 0.0, r.period_s)
        applied = first["tau_controller"][:, 0] - first["tau_rate_cut"][:, 0]
        ax_a.plot(first["t"], applied, color=f"C{i}", lw=1.2, label=f"{limit:g} N·m/ms")
        finals.append(float(np.mean(r.mae)))
        table.append([f"MAE at {limit:g} N·m/ms (rad, mean over trials)", "–", f"{finals[-1]:.4f}"])
    ax_a.set(xlabel="time in the first trial (s)", ylabel="torque let through (N·m)")
    ax_a.legend(fontsize=8)
    ax_b.loglog(list(by_limit), finals, "o-")
    ax_b.set(xlabel="rate limit (N·m/ms)", ylabel="MAE (rad)")
    for letter, ax in zip("AB", (ax_a, ax_b)):
        ax.grid(alpha=0.3)
        panel_letter(ax, letter)
    fig.tight_layout()
    png = save(fig, stem)
    falls = all(a >= b for a, b in zip(finals, finals[1:]))
    table.insert(1, ["the error falls as the limit loosens", "yes", "yes" if falls else "no"])
    return Figure([png], "A: the torque the limiter lets through in the first swing, per limit; B: tracking "
                  "error against the limit. A tight limit delays the torque that lifts the bob.", table)
