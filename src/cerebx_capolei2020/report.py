"""Capolei et al. (2020) Fig. 5 (MAE per joint per trial, architectures I-IV, cases A and B) and
Table II (LWPR receptive fields created per module), with the paper's claims beside ours.

Runs are selected by content: task ``wrist_oscillation`` on plant ``icub_wrist``, controller preset
``capolei_arch1..4``; case B = ``plant.sensor_noise`` > 0. Trials are numbered from 1 as in the paper.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from cerebx.report.convergence import Convergence, plateau  # noqa: E402
from cerebx.report.plot import save  # noqa: E402
from cerebx.report.registry import Check, Figure, MissingRuns, figure, studies  # noqa: E402
from cerebx.report.runs import Run, RunSet  # noqa: E402
from cerebx.report.studies import study_plateau  # noqa: E402

studies(Path(__file__).with_name("studies.yaml"))

ARCHS = {"capolei_arch1": ("I", "C2"), "capolei_arch2": ("II", "C0"), "capolei_arch3": ("III", "C9"),
         "capolei_arch4": ("IV", "C6")}
JOINTS = ("1 pronosupination", "2 yaw", "3 pitch")
STUDIES = ("capolei2020_caseA", "capolei2020_caseB")
# Table II of the paper: receptive fields created, (case A, case B) per architecture and module
PAPER_RFS = {("II", "inverse"): (8, 14), ("IV", "inverse"): (11, 16), ("III", "forward"): (78, 146),
             ("IV", "forward"): (436, 510)}
MODULES = {"capolei_inverse": "inverse", "capolei_forward": "forward"}


def _case(r: Run) -> str:
    return "B" if float(r.get("plant.sensor_noise", 0.0) or 0.0) > 0 else "A"


def groups(runs: RunSet) -> dict[tuple[str, str], list[Run]]:
    """(architecture, case) -> its completed repetitions."""
    sel = runs.where(lambda r: r.completed and r.controller_preset in ARCHS, task="wrist_oscillation")
    sel = sel.where(lambda r: r.summary.get("plant") == "icub_wrist")
    out: dict[tuple[str, str], list[Run]] = {}
    for r in sel:
        out.setdefault((ARCHS[r.controller_preset][0], _case(r)), []).append(r)
    return out


def mae_per_joint(rs: list[Run]) -> np.ndarray:
    """(repetitions, trials, joints), cut to the shortest run."""
    arrs = [np.asarray(r.summary["mae_per_joint_per_trial"], float) for r in rs]
    n = min(a.shape[0] for a in arrs)
    return np.stack([a[:n] for a in arrs])


def receptive_fields(r: Run) -> dict[str, float]:
    """Module ('forward'/'inverse') -> RFs created over the run (all joints), from the last /weights message."""
    parts = (r.summary.get("controller_info") or {}).get("parts", [])
    last: dict = {}
    for _, _, msg in r.messages(["/weights"]):
        last = msg
    out = {}
    for i, p in enumerate(parts):
        module = MODULES.get(p.get("kind"))
        if module is not None and f"{i}.rf_created" in last:
            out[module] = float(last[f"{i}.rf_created"])
    return out


def convergence(g: dict[tuple[str, str], list[Run]]) -> Convergence:
    """The plateau test of each learning architecture's (II-IV) mean MAE per trial over its repetitions, in each
    case, against the paper's trial count (the full profile's)."""
    curves = []
    for (label, case), rs in sorted(g.items()):
        if label != "I":  # architecture I is the PID alone: nothing learns
            curves.append(plateau(mae_per_joint(rs).mean(axis=(0, 2)), study_plateau(f"capolei2020_case{case}"),
                                  f"{label}{case}"))
    return Convergence(tuple(curves))


def _correct_from(rs: list[Run]) -> int:
    for r in rs:
        for p in (r.get("controller.parts") or []):
            if "correct_from_trial" in p:
                return int(p["correct_from_trial"])
    return 7


def _drop(g, joint: int, k0: int, k1: int) -> float | None:
    """Relative MAE change of IV against I, mean over trials k0..k1-1 (0-based); None when the runs are shorter."""
    if ("I", "A") not in g or ("IV", "A") not in g:
        return None
    a, b = mae_per_joint(g[("I", "A")]), mae_per_joint(g[("IV", "A")])
    if min(a.shape[1], b.shape[1]) < k1:
        return None
    a, b = a[:, k0:k1, joint].mean(), b[:, k0:k1, joint].mean()
    return 100.0 * (a - b) / a


@figure("capolei2020_fig5", "Capolei et al. 2020 Fig. 5: MAE per joint and trial, architectures I-IV", STUDIES)
def fig5(runs: RunSet, stem: Path) -> Figure:
    g = groups(runs)
    if not g:
        raise MissingRuns("no wrist_oscillation runs of capolei_arch1..4 on icub_wrist")
    cases = [c for c in ("A", "B") if any(k[1] == c for k in g)]
    fig, axes = plt.subplots(3, len(cases), figsize=(5.2 * len(cases), 8.5), squeeze=False, sharex=True)
    k_corr = _correct_from(next(iter(g.values())))
    for ci, case in enumerate(cases):
        for label, color in ARCHS.values():
            rs = g.get((label, case))
            if not rs:
                continue
            m = mae_per_joint(rs)
            trials = np.arange(1, m.shape[1] + 1)
            for j in range(3):
                ax = axes[j, ci]
                mu, sd = m[:, :, j].mean(0), m[:, :, j].std(0)
                ax.plot(trials, mu, color=color, lw=1.6, label=f"{label}{case} (n = {len(rs)})")
                ax.fill_between(trials, np.maximum(mu - 3 * sd, 0), mu + 3 * sd, color=color, alpha=0.18, lw=0)
        for j in range(3):
            ax = axes[j, ci]
            ax.axvline(k_corr + 1, color="green", lw=1)
            ax.set_ylabel(f"MAE joint {JOINTS[j]} (rad)")
            ax.grid(alpha=0.3)
        axes[0, ci].set_title(f"case {case}: " + ("ball" if case == "A" else "ball + sensor noise U(-0.1, 0.1)"))
        axes[0, ci].legend(fontsize=8)
        axes[-1, ci].set_xlabel("trial k (4 s period)")
    fig.tight_layout()
    png = save(fig, stem)

    table = [["claim (paper)", "paper", "cerebx"]]
    checks = []
    k5 = k_corr + 5  # 0-based index of the trial 5 trials after the first corrected one
    for j, paper in ((0, "12 %"), (1, "90 %")):
        d = _drop(g, j, k5, k5 + 1)
        table.append([f"IV vs I, joint {j + 1}: MAE drop at trial {k5 + 1} (corrections from trial {k_corr + 1})",
                      paper, "–" if d is None else f"{d:.0f} %"])
        if d is not None:
            checks.append(Check(f"IV below I on joint {j + 1} at trial {k5 + 1}", bool(d > 0),
                                f"{d:.0f} % lower (paper {paper})"))
    late = {label: mae_per_joint(rs)[:, k_corr:k_corr + 8, 2].mean() for (label, case), rs in g.items()
            if case == "A" and mae_per_joint(rs).shape[1] >= k_corr + 8}
    if late:
        vals = ", ".join(f"{label} {v:.4f}" for label, v in sorted(late.items()))
        table.append([f"joint 3 deviation corrected in trials {k_corr + 1}-{k_corr + 8} (mean MAE, case A, rad)",
                      "only IV", f"lowest: {min(late, key=late.get)} ({vals})"])
        checks.append(Check(f"IV corrects joint 3's deviation best in trials {k_corr + 1}-{k_corr + 8} (case A)",
                            min(late, key=late.get) == "IV", vals + " rad"))
    noisy = {label: mae_per_joint(rs)[:, -5:].mean((0, 1)) for (label, case), rs in g.items() if case == "B"}
    if noisy:
        table.append(["case B: MAE per joint of the last 5 trials (rad)", "I degrades; III, IV filter the noise",
                      "; ".join(f"{label} " + "/".join(f"{v:.3f}" for v in vals)
                                for label, vals in sorted(noisy.items()))])
        if "I" in noisy and {"III", "IV"} & set(noisy):
            checks.append(Check("with sensor noise (case B) III and IV below I on every joint (last 5 trials)",
                                all((noisy[a] < noisy["I"]).all() for a in ("III", "IV") if a in noisy),
                                "; ".join(f"{a} " + "/".join(f"{v:.3f}" for v in noisy[a])
                                          for a in ("I", "III", "IV") if a in noisy)))
    for label in ("I", "II", "III", "IV"):
        if (label, "A") in g and (label, "B") in g:
            a = mae_per_joint(g[(label, "A")])[:, -5:].mean((0, 1))
            b = mae_per_joint(g[(label, "B")])[:, -5:].mean((0, 1))
            paper = {"I": "clearly worse", "III": "barely affected", "IV": "barely affected"}.get(label, "–")
            change = ", ".join(f"j{j + 1} {bj:.4f} vs {aj:.4f} ({100 * (bj - aj) / aj:+.0f} %)"
                               for j, (aj, bj) in enumerate(zip(a, b)))
            table.append([f"{label}: MAE of the last 5 trials, B vs A", paper, change])
    return Figure([png], "MAE per joint and trial: mean over the repetitions (line) and mean ± 3 SD (99.7 % band); "
                  f"green line: corrections start (trial {k_corr + 1}).", table, checks=checks,
                  convergence=convergence(g))


@figure("capolei2020_table2", "Capolei et al. 2020 Table II: LWPR receptive fields created", STUDIES)
def table2(runs: RunSet, stem: Path) -> Figure:
    g = groups(runs)
    rows = [["architecture", "module", "case", "paper", "cerebx (mean ± SD over repetitions, all joints)"]]
    for (label, module), (pa, pb) in PAPER_RFS.items():
        for case, paper in (("A", pa), ("B", pb)):
            rs = g.get((label, case), [])
            vals = [receptive_fields(r).get(module) for r in rs]
            vals = [v for v in vals if v is not None]
            ours = f"{np.mean(vals):.1f} ± {np.std(vals):.1f} (n = {len(vals)})" if vals else "–"
            rows.append([label, module, case, str(paper), ours])
    if all(r[-1] == "–" for r in rows[1:]):
        raise MissingRuns("no capolei_arch2..4 runs with receptive-field counts")
    fig, ax = plt.subplots(figsize=(8, 0.4 + 0.3 * len(rows)))
    ax.axis("off")
    ax.table(cellText=rows[1:], colLabels=rows[0], loc="center").auto_set_font_size(True)
    png = save(fig, stem)
    return Figure([png], "Receptive fields created by each module's LWPR (the paper: one count per module).", rows,
                  convergence=convergence(g))
