"""Plant realism (not a thesis figure): which plant features the chapter 3 orderings depend on. PD and the
SNN on the circle on each plant variant (series elastic actuators, sensor noise, torque lag, the URDF's
armature) at 0 and 50 ms constant round trips, as a bar chart and a table."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from cerebx.report.api import Check, Figure, MissingRuns, Run, RunSet, figure, fmt, save  # noqa: E402
from cerebx_thesis.report.common import CH3_STUDY, learnt  # noqa: E402

REALISM_PLANTS = ("baxter", "baxter_sea", "baxter_noise", "baxter_lag5", "baxter_lag10", "baxter_urdf_armature")
REALISM_DELAYS_MS = (0.0, 50.0)


def _plant_preset(run: Run) -> str:
    """The run's plant preset (else its plant kind)."""
    return (run.summary.get("presets") or {}).get("plant", run.summary.get("plant", ""))


def realism_cells(runs: RunSet) -> dict[tuple[str, str, float], Run]:
    """(plant preset, controller, round trip ms) -> the run of the plant realism study: PD with the ``pd``
    preset, the SNN with the default ``snn`` preset and one kernel (not the chapter 3 studies' ``snn_delays``
    or multikernel runs on the same plant and delays, which have more trials and would win ``best``)."""
    study = runs.where(lambda r: r.trials > 0 and r.delay == "constant" and _plant_preset(r) in REALISM_PLANTS
                       and r.delay_total_ms in REALISM_DELAYS_MS and r.task == "circle" and not r.events)
    out = {}
    for ctrl, sel in (("pd", study.where(controller="pd", controller_preset="pd")),
                      ("snn", study.where(lambda r: r.learned_from is not None and len(r.kernel_peaks_ms) == 1,
                                          controller="snn", controller_preset="snn"))):
        for r in sel:
            key = (_plant_preset(r), ctrl, r.delay_total_ms)
            if key not in out or RunSet([r, out[key]]).best() is r:
                out[key] = r
    return out


@figure("plant_realism", "Plant realism: PD and SNN on each plant variant, 0 and 50 ms",
        studies=("realism_pd", "realism_snn"))
def plant_realism(runs: RunSet, stem: Path) -> Figure:
    """Bars of MAE per plant variant for PD and SNN at 0 and 50 ms, and the PD ÷ SNN ratio at 50 ms."""
    cells = realism_cells(runs)
    if not cells:
        raise MissingRuns("no runs of the plant realism study (studies realism_pd, realism_snn)")
    fig, ax = plt.subplots(figsize=(10, 4))
    width = 0.2
    table = [["quantity", "paper", "cerebx"]]
    notes = []
    ratios = {}
    for j, (ctrl, d) in enumerate((("pd", 0.0), ("pd", 50.0), ("snn", 0.0), ("snn", 50.0))):
        vals = [float(np.mean(cells[(p, ctrl, d)].mae)) if (p, ctrl, d) in cells else np.nan for p in REALISM_PLANTS]
        ax.bar(np.arange(len(REALISM_PLANTS)) + (j - 1.5) * width, vals, width, label=f"{ctrl.upper()} {d:.0f} ms")
    for p in REALISM_PLANTS:
        vals = {}
        for ctrl, d in (("pd", 0.0), ("pd", 50.0), ("snn", 0.0), ("snn", 50.0)):
            r = cells.get((p, ctrl, d))
            vals[(ctrl, d)] = float(np.mean(r.mae)) if r is not None else None
        pd50, snn50 = vals[("pd", 50.0)], vals[("snn", 50.0)]
        ratio = f"{pd50 / snn50:.1f}" if pd50 and snn50 else "–"
        if pd50 and snn50:
            ratios[p] = pd50 / snn50
        table.append([f"{p}: MAE (rad) PD 0 / 50 ms, SNN 0 / 50 ms; PD ÷ SNN at 50 ms",
                      "real robot: PD 0.076 → ~0.12 at 50 ms; SNN flat",
                      " / ".join(fmt(v) for v in vals.values()) + f"; {ratio}"])
        if any(v is None for v in vals.values()):
            notes.append(f"{p}: some runs missing")
    ax.set_xticks(np.arange(len(REALISM_PLANTS)), [p.replace("baxter_", "") for p in REALISM_PLANTS])
    ax.set_ylabel("MAE (rad), measured trials")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    caption = ("Plant realism study (not a thesis figure: does a feature of the real arm change the ordering?): "
               "MAE on the circle (mean of the measured trials) of PD (original PD_circle gains) and of the SNN "
               "(the chapter 3 learned circle, 10 more learning trials on each plant, delay-robust default "
               "controller) on each plant variant: the default rigid arm, series elastic actuators, sensor noise "
               "(0.5 mrad, 5 mrad/s), a 5 / 10 ms first-order torque lag, and the URDF's armature (none). "
               "Constructed noise and lag levels; 0 and 50 ms constant round trips.")
    checks = [Check("SNN below PD at 50 ms on every plant variant", all(v > 1 for v in ratios.values()),
                    "PD ÷ SNN " + ", ".join(f"{p.replace('baxter_', '')} {v:.1f}" for p, v in ratios.items()))]
    conv = learnt(runs, [("SNN", r, CH3_STUDY["circle"]) for (_, c, _), r in cells.items() if c == "snn"])
    return Figure([save(fig, stem)], caption, table, notes, checks if ratios else [], conv)
