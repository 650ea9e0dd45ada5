"""Chapter 3 delay-study figures (thesis Fig. 3.4 and 3.6-3.10), drawn from run logs.

Runs are selected by content (controller kind, task, delay config, PF-PC kernels); realised delays
are read from the R2C/C2R delays recorded in /control over a run's first trials (the delay processes
are stationary, so a window is enough and keeps big runs fast).
"""

from __future__ import annotations

import re
from collections import Counter
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import to_rgb  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

from cerebx.metrics import final_mae  # noqa: E402
from cerebx.report.delays import DELAY_TRIALS, delays  # noqa: E402
from cerebx.report.plot import fmt, mean_std, panel_letter, save  # noqa: E402
from cerebx.report.registry import Figure, MissingRuns, figure  # noqa: E402
from cerebx.report.runs import Run, RunSet  # noqa: E402
from cerebx.snn.schema import KernelSTDP  # noqa: E402
from cerebx.snn.topology import ltd_kernel_table  # noqa: E402
from cerebx_thesis.report.ch2 import TASK_NAMES, THESIS_KERNEL_MS, _rel, from_scratch  # noqa: E402

CONTROLLERS = {"pd": ("PD", "C3"), "ann": ("ANN", "C1"), "snn": ("SNN", "C0")}
HEADER = ["quantity", "paper", "cerebx"]

# thesis §3.3.3: nominal delays of the symmetric (round trip) and asymmetric (R2C, C2R) gamma sets
THESIS_GAMMA = {"gamma15": "15 ± 5", "gamma25": "25 ± 5", "gamma35": "35 ± 5", "gamma45": "45 ± 5",
                "gamma55": "55 ± 5", "gamma65": "65 ± 5", "gamma78": "78 ± 4"}
THESIS_ASYM = {"asym_r2c8_c2r40": ("8 ± 3", "40 ± 3"), "asym_r2c39_c2r9": ("39 ± 2", "9 ± 4")}
# thesis §3.3.4: percentiles (p50, p90, p99) the cloud delays stayed below, and the MAE of each scenario
THESIS_CLOUD = {"cloud": {"r2c": (9, 10, 12), "c2r": (9, 10, 12), "mae": "0.020 ± 0.004"},
                "wifi_cloud": {"r2c": (12, 14, 20), "c2r": (29, 32, 36), "mae": "0.024 ± 0.007"}}
THESIS_FIT = (0.000106, 0.0036)  # Fig. 3.6 C: MAE = slope * peak_ms + intercept


# ---- selection helpers -------------------------------------------------------------------------------
CH3_TASKS = ("circle", "inclined_circle", "circle_eight")
# Chapter 3 text: factory-default position controller MAE without delay (rad)
PAPER_FACTORY_CH3 = {"circle": "0.077", "inclined_circle": "0.055", "circle_eight": "0.068"}
FIG3_5_DELAY_MS = 50.0
FIG3_5_TRIALS = 16  # trials read per run for the densities (evenly spaced)
CONVERGENCE_TOL = 0.10

def _delay_label(run: Run) -> str:
    """The delay preset's name, or for a run that recorded none, its delay config in short."""
    if "delay" in (run.summary.get("presets") or {}):
        return run.delay_preset
    cfg = {k: v for k, v in (run.get("delay") or {}).items() if k != "kind"}
    return f"{run.delay} {cfg}"[:40]


def _plain_circle(r: Run) -> bool:
    """A circle run with logged trials and no perturbation events."""
    return r.task == "circle" and not r.events and r.mae.size > 0


def _prefer_learned(rs: RunSet) -> Run | None:
    """The best run, among those started from a learned state when there are any."""
    learned = rs.where(lambda r: r.learned_from is not None)
    return (learned or rs).best()


def _sweep(runs: RunSet, controller: str, multikernel: bool = False) -> tuple[dict[float, Run], list[str]]:
    """Best circle run per constant round-trip delay of one controller kind (learned-state runs first), all
    started from the same state (the one most delays used); a note for each delay left out for that."""
    def ok(r: Run) -> bool:
        if not (_plain_circle(r) and r.delay == "constant" and r.controller == controller
                and r.delay_total_ms is not None):
            return False
        return controller != "snn" or (len(r.kernel_peaks_ms) > 1) == multikernel and bool(r.kernel_peaks_ms)
    picked = runs.where(ok).by(lambda r: r.delay_total_ms, _prefer_learned)
    origins = Counter(r.learned_from for r in picked.values())
    main = max(origins, key=lambda o: (origins[o], sum(r.trials for r in picked.values() if r.learned_from == o)),
               default=None)
    notes = [f"{controller} δT = {d:g} ms left out: its run started from {r.learned_from}, the others from {main}"
             for d, r in picked.items() if r.learned_from != main]
    return {d: r for d, r in picked.items() if r.learned_from == main}, notes


def _reference(runs: RunSet, controller: str) -> Run | None:
    """A no-delay circle run of the PD (the fig3_4_pd δT = 0 run first) or factory position controller."""
    rs = runs.where(lambda r: _plain_circle(r) and r.controller == controller and r.delay_total_ms == 0)
    if controller == "position":
        rs = rs.where(lambda r: r.is_factory_position) or rs
    if controller == "pd":  # the launch gains (preset pd), and the δT = 0 run of the fig3_4 sweep first
        rs = rs.where(lambda r: r.controller_preset == "pd") or rs
        rs = rs.where(lambda r: r.delay == "constant") or rs
    return rs.best()


def _snn_delay_runs(runs: RunSet, pred: Callable[[Run], bool]) -> dict[str, Run]:
    """Best SNN circle run per delay preset among those ``pred`` accepts."""
    rs = runs.where(lambda r: _plain_circle(r) and r.controller == "snn" and pred(r))
    return rs.by(_delay_label, _prefer_learned)


# ---- data helpers ------------------------------------------------------------------------------------
def kernels(run: Run) -> list[tuple[str, KernelSTDP, np.ndarray, np.ndarray]]:
    """(projection, rule, t in ms, k(t)) of every PF-PC kernel of the run's network, as the SNN builds it."""
    dt = float(run.get("controller.network.dt_ms", 0.5))
    out = []
    for name, p in (run.get("controller.network.projections", {}) or {}).items():
        pl = (p.get("plasticity") or {}) if isinstance(p, dict) else {}
        if pl.get("kind") == "kernel_stdp":
            rule = KernelSTDP(**pl)
            k = ltd_kernel_table(rule.kernel_peak_ms, rule.kernel_onset_ms, rule.kernel_cutoff, dt)
            out.append((name, rule, np.arange(k.size) * dt, k.astype(float)))
    return out


def _mae(run: Run, last: int | None = None) -> np.ndarray:
    m = run.mae
    return m[-last:] if last else m


def _ms(values: np.ndarray) -> tuple[float, float]:
    return (float(np.mean(values)), float(np.std(values))) if len(values) else (np.nan, np.nan)


def _trials(rs: Iterable[Run]) -> str:
    n = sorted({r.n_measured for r in rs})
    if not n:
        return "no trials"
    return f"{n[0]} trials" if len(n) == 1 else f"{n[0]}–{n[-1]} trials"


def _cdf(ax, v: np.ndarray, **kw) -> None:
    q = np.linspace(0.0, 1.0, 401)
    if v.size:
        ax.plot(np.quantile(v, q), q, **kw)


def _legend(ax, size: int = 8) -> None:
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=size)


def _finish(fig, stem: Path, panels: dict[str, Any], legend_size: int = 8, others: Iterable[Any] = ()) -> Path:
    """Grid and legend on every axes, a letter on each of ``panels``; save PNG + SVG."""
    for s, ax in panels.items():
        panel_letter(ax, s)
    for ax in (*panels.values(), *others):
        ax.grid(alpha=0.3)
        _legend(ax, legend_size)
    fig.tight_layout()
    return save(fig, stem)


def _ref_lines(ax, runs: RunSet) -> list[Run]:
    """Dashed lines at the no-delay MAE of the PD and factory position controllers, when such runs exist."""
    used = []
    for kind, label, color in (("pd", "PD, no delay", "C3"), ("position", "factory position, no delay", "0.4")):
        r = _reference(runs, kind)
        if r is not None and r.mae.size:
            ax.axhline(r.mae.mean(), ls="--", lw=1.1, color=color, label=f"{label} ({r.n_measured} trials)")
            used.append(r)
    return used


def _box(ax, data: list[np.ndarray], labels: list[str], color: str = "C0") -> None:
    pos = np.arange(len(data))
    ax.boxplot(data, positions=pos, widths=0.5, showfliers=False, patch_artist=True,
               boxprops={"facecolor": color, "alpha": 0.35}, medianprops={"color": "k"})
    ax.plot(pos, [np.mean(d) for d in data], "D", color=color, ms=4, label="mean")
    ax.set_xticks(pos, labels, rotation=30, ha="right", fontsize=8)


def _origin(run: Run) -> str:
    return f"learned state ({'/'.join(Path(run.learned_from).parts[-2:])})" if run.learned_from else "from scratch"


# ---- Fig. 3.4 ----------------------------------------------------------------------------------------
@figure("fig3_4", "PD, ANN and SNN under constant round-trip delays", studies=("fig3_4_snn", "fig3_4_ann", "fig3_4_pd"))
def fig3_4(runs: RunSet, stem: Path) -> Figure:
    picked = {c: _sweep(runs, c) for c in CONTROLLERS}
    sweeps = {c: s for c, (s, _) in picked.items()}
    if not any(sweeps.values()):
        raise MissingRuns("no circle runs of pd, ann or snn under a constant delay (studies fig3_4_pd/ann/snn)")
    notes = [f"no {CONTROLLERS[c][0]} circle runs under a constant delay (study fig3_4_{c})"
             for c, s in sweeps.items() if not s] + [n for _, ns in picked.values() for n in ns]
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(12, 4.6))
    for c, sweep in sweeps.items():
        if not sweep:
            continue
        name, color = CONTROLLERS[c]
        x = np.array(list(sweep))
        mae = np.array([_ms(r.mae) for r in sweep.values()])
        tv = np.array([_ms(r.series("torque_variability_per_trial")) for r in sweep.values()])
        ax_a.errorbar(x, mae[:, 0], mae[:, 1], marker="o", capsize=3, color=color, label=name)
        ax_b.errorbar(x, tv[:, 0], tv[:, 1], marker="o", capsize=3, color=color, label=name)
    pos = _reference(runs, "position")
    if pos is not None:
        ax_a.axhline(pos.mae.mean(), ls="--", color="0.4", lw=1.1, label="factory position, no delay")
    ax_a.set_ylabel("position MAE (rad), mean ± std over trials")
    ax_b.set_ylabel("torque variability (N·m/ms), mean ± std")
    for ax in (ax_a, ax_b):
        ax.set_xlabel("constant round-trip delay δT (ms)")
    png = _finish(fig, stem, {"A": ax_a, "B": ax_b})

    table = [HEADER]
    paper0 = {"pd": "0.076", "ann": "0.021 ± 0.002", "snn": "0.018 ± 0.004"}
    paper_avg = {"pd": "0.099 ± 0.027 (0–50 ms)", "ann": "0.053 ± 0.026 (0–50 ms)", "snn": "0.024 ± 0.011 (0–80 ms)"}
    paper_tv = {"pd": "0.019 → 0.036", "ann": "0.016 → 0.026", "snn": "0.012 regardless of δT"}
    paper80 = {"snn": "figure only: plateau ≈ 0.02–0.03 rad", "pd": "not run (stopped at 50 ms, unstable > 20 ms)",
               "ann": "not run (stopped at 50 ms, unstable > 10 ms)"}
    paper_ratio = {"snn": "barely deviated", "pd": "degraded significantly", "ann": "degraded significantly"}
    for c, sweep in sweeps.items():
        if not sweep:
            continue
        name = CONTROLLERS[c][0]
        m0 = sweep[min(sweep)].mae if min(sweep) == 0 else None
        hi = max(sweep)
        table.append([f"{name} MAE at δT = 0 ms (rad)", paper0[c], "–" if m0 is None else mean_std(m0)])
        table.append([f"{name} MAE at δT = {hi:g} ms (rad)", paper80[c], mean_std(sweep[hi].mae)])
        ratio = None if m0 is None else sweep[hi].mae.mean() / m0.mean()
        table.append([f"{name} MAE ratio {hi:g} / 0 ms", paper_ratio[c], fmt(ratio, 2)])
        lim = 80 if c == "snn" else 50
        pooled = np.concatenate([r.mae for d, r in sweep.items() if d <= lim])
        table.append([f"{name} average MAE over δT ≤ {lim} ms (rad)", paper_avg[c], mean_std(pooled)])
        if c != "snn" and sweeps["snn"]:
            snn = np.concatenate([r.mae for r in sweeps["snn"].values()]).mean()
            table.append([f"{name} average MAE ÷ SNN average MAE", "3 to 4× larger", fmt(pooled.mean() / snn, 2)])
        x = np.array(list(sweep))
        tv = np.array([r.series("torque_variability_per_trial").mean() for r in sweep.values()])
        tv50 = np.interp(50.0, x, tv) if x.min() <= 50 <= x.max() else None
        at50 = "" if 50 in sweep else " (50 ms interpolated)"
        table.append([f"{name} torque variability 0 → 50 ms (N·m/ms){at50}", paper_tv[c],
                      f"{fmt(tv[0] if x[0] == 0 else None)} → {fmt(tv50)}"])
    counts = "; ".join(f"{CONTROLLERS[c][0]}: δT = {', '.join(f'{d:g}' for d in s)} ms, {_trials(s.values())} "
                       f"per δT, {_origin(next(iter(s.values())))}" for c, s in sweeps.items() if s)
    caption = ("Fig. 3.4 — controllers under constant round-trip delays δT (split evenly between R2C and C2R), "
               "horizontal circle. (A) position MAE, mean ± std over each run's trials; (B) torque variability "
               "(Eq. 3.15: mean |Δτ| per ms over joints), mean ± std over trials. "
               f"Runs — {counts}. The thesis used 100 trials per δT and stopped PD and ANN at 50 ms; every δT "
               "run is shown here. The dashed grey line is the factory position controller without delay "
               "(where such a run exists).")
    return Figure([png], caption, table, notes)


# ---- Fig. 3.6 ----------------------------------------------------------------------------------------
@figure("fig3_6", "MAE vs PF-PC kernel peak", studies=("fig3_6_kernels", "fig3_4_pd"))
def fig3_6(runs: RunSet, stem: Path) -> Figure:
    rs = runs.where(lambda r: _plain_circle(r) and r.controller == "snn" and r.delay_total_ms == 0
                    and len(r.kernel_peaks_ms) == 1)
    by_peak = rs.by(lambda r: r.kernel_peaks_ms[0])
    if not by_peak:
        raise MissingRuns("no single-kernel SNN circle runs without delay (study fig3_6_kernels)")
    notes = []
    pd = _reference(runs, "pd")
    if pd is None:
        notes.append("no PD circle run without delay for the reference line (study fig3_4_pd)")
    peaks = np.array(list(by_peak))
    last = {p: min(100, r.n_measured) for p, r in by_peak.items()}
    stats = np.array([_ms(_mae(r, last[p])) for p, r in by_peak.items()])

    fig, (ax_a, ax_b, ax_c) = plt.subplots(1, 3, figsize=(16, 4.6))
    cmap = plt.get_cmap("viridis")
    for i, r in enumerate(by_peak.values()):
        for _, rule, t, k in kernels(r):
            ax_a.plot(t, k, color=cmap(i / max(1, len(by_peak) - 1)), lw=1.3,
                      label=f"peak {rule.kernel_peak_ms:g} ms (onset {rule.kernel_onset_ms:g})")
    ax_a.set_xlabel("PF spike before CF spike (ms)")
    ax_a.set_ylabel("LTD kernel k (peak = 1)")
    _legend(ax_a, 7)
    ax_b.errorbar(peaks, stats[:, 0], stats[:, 1], marker="o", capsize=3, color="C0", label="SNN")
    if pd is not None:
        ax_b.axhline(pd.mae.mean(), ls="--", color="C3", label=f"PD, no delay ({pd.n_measured} trials)")
    ax_b.set_xlabel("kernel peak τ_LTD (ms)")
    ax_b.set_ylabel("position MAE (rad), mean ± std")
    _legend(ax_b, 8)
    xs = np.linspace(min(90.0, peaks.min()), max(250.0, peaks.max()), 50)
    ax_c.plot(peaks, stats[:, 0], "o", color="C0", label="SNN (mean per kernel)")
    ax_c.plot(xs, THESIS_FIT[0] * xs + THESIS_FIT[1], "k--", label="thesis: y = 0.000106·x + 0.0036")
    fit = None
    if len(peaks) >= 2:
        fit = np.polyfit(peaks, stats[:, 0], 1)
        ax_c.plot(xs, np.polyval(fit, xs), "C0", label=f"cerebx: y = {fit[0]:.6f}·x + {fit[1]:.4f}")
    else:
        notes.append("only one kernel peak: no linear fit")
    ax_c.set_xlabel("kernel peak τ_LTD (ms)")
    ax_c.set_ylabel("position MAE (rad)")
    png = _finish(fig, stem, {"A": ax_a, "B": ax_b, "C": ax_c})

    table = [HEADER,
             ["slope (rad/ms)", f"{THESIS_FIT[0]:.6f}", "–" if fit is None else f"{fit[0]:.6f}"],
             ["intercept (rad)", f"{THESIS_FIT[1]:.4f}", "–" if fit is None else f"{fit[1]:.4f}"]]
    for x in (90.0, 250.0):
        ours = mean_std(_mae(by_peak[x], last[x])) if x in by_peak else "not run"
        line = "" if fit is None else f"; fit {np.polyval(fit, x):.4f}"
        table.append([f"MAE at peak {x:g} ms (rad)", f"{THESIS_FIT[0] * x + THESIS_FIT[1]:.4f} (line)",
                      f"{ours}{line}"])
    best = min(by_peak, key=lambda x: _mae(by_peak[x], last[x]).mean())
    table.append(["kernel peak with the lowest MAE (ms)", "90, the shortest (MAE rises with the peak)", f"{best:g}"])
    table.append(["PD reference, no delay (rad)", "0.076", "–" if pd is None else mean_std(pd.mae)])
    origins: dict[str, list[str]] = {}
    for p, r in by_peak.items():
        origins.setdefault(_origin(r), []).append(f"{p:g} ({r.trials})")
    origin_text = "; ".join(f"{o}: {', '.join(v)}" for o, v in origins.items())
    caption = ("Fig. 3.6 — SNN on the horizontal circle without delay for each PF-PC LTD kernel. (A) the kernels "
               "as the network builds them (ltd_kernel_table of each run's config); (B) MAE, mean ± std over the last "
               "min(100, trials) trials, with the PD reference (no delay); (C) linear fit of the per-kernel mean MAE "
               "vs kernel peak beside the thesis's regression. Kernel peak in ms (trials per run) by how the run "
               f"started — {origin_text}. The thesis learned each kernel from scratch with 100 trials per kernel in "
               "the regression.")
    return Figure([png], caption, table, notes)


# ---- Fig. 3.7 ----------------------------------------------------------------------------------------
def _symmetric(r: Run) -> bool:
    return bool(r.get("delay.symmetric")) or r.get("delay.r2c") == r.get("delay.c2r")


@figure("fig3_7", "SNN under symmetric and asymmetric gamma delays", studies=("fig3_7_gamma",))
def fig3_7(runs: RunSet, stem: Path) -> Figure:
    gamma = _snn_delay_runs(runs, lambda r: r.delay == "gamma")
    if not gamma:
        raise MissingRuns("no SNN circle runs under a gamma delay (study fig3_7_gamma)")
    d = {k: delays(r) for k, r in gamma.items()}
    rt = {k: a + b for k, (a, b) in d.items()}
    sym = sorted((k for k, r in gamma.items() if _symmetric(r)), key=lambda k: np.mean(rt[k]) if rt[k].size else 0)
    order = [*THESIS_ASYM]
    asym = sorted((k for k in gamma if k not in sym), key=lambda k: (order.index(k) if k in order else len(order), k))
    notes = []
    if not sym:
        notes.append("no symmetric gamma runs (panels A-C empty)")
    if not asym:
        notes.append("no asymmetric gamma runs (panels D-E empty)")

    fig = plt.figure(figsize=(15, 8.8))
    gs = fig.add_gridspec(2, 3)
    ax_a, ax_b, ax_c = (fig.add_subplot(gs[0, i]) for i in range(3))
    sub = gs[1, 0:2].subgridspec(1, max(1, len(asym)), wspace=0.3)
    axes_d = [fig.add_subplot(sub[0, i]) for i in range(max(1, len(asym)))]
    ax_e = fig.add_subplot(gs[1, 2])
    cmap = plt.get_cmap("plasma")
    for i, k in enumerate(sym):
        color = cmap(0.85 * i / max(1, len(sym) - 1))
        if rt[k].size:
            bins = np.arange(0.0, rt[k].max() + 2.0, 1.0)
            ax_a.hist(rt[k], bins=bins, density=True, histtype="step", color=color, lw=1.2, label=k)
        _cdf(ax_b, rt[k], color=color, lw=1.3, label=k)
    if sym:
        _box(ax_c, [gamma[k].mae for k in sym], sym)
    refs = _ref_lines(ax_c, runs)
    for ax, k in zip(axes_d, asym):
        _cdf(ax, d[k][0], color="C0", lw=1.4, label="R2C (sensor)")
        _cdf(ax, d[k][1], color="C3", lw=1.4, ls="--", label="C2R (motor)")
        ax.set_title(k, fontsize=9)
    if asym:
        _box(ax_e, [gamma[k].mae for k in asym], asym, color="C2")
    _ref_lines(ax_e, runs)
    ax_a.set(xlabel="realised round-trip delay δT (ms)", ylabel="probability density")
    ax_b.set(xlabel="realised round-trip delay δT (ms)", ylabel="CDF")
    for ax in axes_d:
        ax.set(xlabel="one-way delay (ms)", ylabel="CDF")
    for ax in (ax_c, ax_e):
        ax.set_ylabel("SNN position MAE (rad) per trial")
    png = _finish(fig, stem, dict(zip("ABCDE", (ax_a, ax_b, ax_c, axes_d[0], ax_e))), 7, others=axes_d[1:])

    table = [HEADER]
    for k in sym:
        table.append([f"{k}: round trip (ms)", THESIS_GAMMA.get(k, "–"), mean_std(rt[k], 1)])
        table.append([f"{k}: SNN MAE (rad)", "figure only (below the factory position MAE)", mean_std(gamma[k].mae)])
    for k in asym:
        p = THESIS_ASYM.get(k, ("–", "–"))
        table.append([f"{k}: R2C / C2R (ms)", f"{p[0]} / {p[1]}",
                      f"{mean_std(d[k][0], 1)} / {mean_std(d[k][1], 1)}"])
        table.append([f"{k}: SNN MAE (rad)", "figure only (coped with the delay)", mean_std(gamma[k].mae)])
    pos = _reference(runs, "position")
    if pos is not None:
        worst = max(gamma[k].mae.mean() for k in gamma)
        table.append(["SNN MAE below the no-delay factory position MAE for every preset",
                      "yes (factory position 0.077 rad)",
                      f"{'yes' if worst < pos.mae.mean() else 'no'} (worst {worst:.3f} vs {pos.mae.mean():.3f})"])
    else:
        notes.append("no factory position controller circle run without delay for the reference")
    caption = ("Fig. 3.7 — SNN on the horizontal circle under random gamma delays. (A) PDF and (B) CDF of the "
               "realised round trip δT = R2C + C2R of the symmetric presets; (C) SNN MAE per trial per preset "
               "(box: quartiles, diamond: mean); (D) CDFs of R2C (solid) and C2R (dashed) of the asymmetric presets; "
               f"(E) their MAE. Delays are the values recorded in /control over the first {DELAY_TRIALS} trials "
               f"(every 2 ms step). Runs: {_trials(gamma.values())} per preset "
               f"({', '.join(sorted({_origin(r) for r in gamma.values()}))}); thesis: 100 trials per preset. "
               + ("Dashed lines: " + ", ".join(f"{r.controller_preset} without delay ({r.n_measured} trials)"
                                               for r in refs) + "." if refs else ""))
    return Figure([png], caption, table, notes)


# ---- Fig. 3.8 ----------------------------------------------------------------------------------------
def _load_mbps(name: str) -> int | None:
    m = re.fullmatch(r"wifi(\d+)", name)
    return int(m.group(1)) if m else None


@figure("fig3_8", "SNN behind a Wi-Fi gateway", studies=("fig3_8_wifi",))
def fig3_8(runs: RunSet, stem: Path) -> Figure:
    wifi = _snn_delay_runs(runs, lambda r: _load_mbps(r.delay_preset) is not None)
    if not wifi:
        raise MissingRuns("no SNN circle runs under the Wi-Fi delay presets wifi15/30/54 (study fig3_8_wifi)")
    loads = sorted(wifi, key=_load_mbps)
    d = {k: delays(wifi[k]) for k in loads}
    labels = [f"{_load_mbps(k)} Mbps" for k in loads]
    fig, (ax_c, ax_d) = plt.subplots(1, 2, figsize=(12, 4.6))
    _box(ax_c, [wifi[k].mae for k in loads], labels)
    ax_c.set(xlabel="bandwidth load", ylabel="SNN position MAE (rad) per trial")
    for i, k in enumerate(loads):
        _cdf(ax_d, d[k][0], color=f"C{i}", lw=1.4, label=f"{labels[i]}: R2C (sensor)")
        _cdf(ax_d, d[k][1], color=f"C{i}", lw=1.4, ls="--", label=f"{labels[i]}: C2R (motor)")
    ax_d.axvline(20.0, color="0.5", lw=0.8, ls=":")
    ax_d.set(xlabel="one-way delay (ms)", ylabel="CDF")
    png = _finish(fig, stem, {"C": ax_c, "D": ax_d}, legend_size=7)

    pooled = np.concatenate([wifi[k].mae for k in loads])
    table = [HEADER, ["average MAE over loads (rad)", "0.025 ± 0.007", mean_std(pooled)]]
    for k, lab in zip(loads, labels):
        r2c, c2r = d[k]
        share = 100.0 * np.mean(c2r > 20.0) if c2r.size else np.nan
        table.append([f"{lab}: MAE (rad)", "figure only", mean_std(wifi[k].mae)])
        table.append([f"{lab}: motor (C2R) delays above 20 ms", '"50 % … above 20 ms" at every load', f"{share:.0f} %"])
        med = [fmt(float(np.median(v)) if v.size else None, 1) for v in (r2c, c2r)]
        table.append([f"{lab}: median R2C / C2R (ms)", "figure only", " / ".join(med)])
    notes = [] if len(loads) == 3 else [f"only {len(loads)} of the 3 Wi-Fi loads were run"]
    caption = ("Fig. 3.8 — SNN on the horizontal circle behind a Wi-Fi gateway at three bandwidth loads. (C) MAE per "
               "trial per load (box: quartiles, diamond: mean); (D) CDFs of the sensor (R2C, solid) and motor "
               f"(C2R, dashed) delays recorded in /control over the first {DELAY_TRIALS} trials. The delay tables "
               "are constructed (conf/delay/wifi*.yaml): the thesis shows these CDFs only as a figure, so the tables "
               "honour its two stated facts (asymmetric paths; half the motor delays above 20 ms at every load). "
               f"Runs: {_trials(wifi.values())} per load ({', '.join(sorted({_origin(r) for r in wifi.values()}))}); "
               "thesis: 100 trials per load.")
    return Figure([png], caption, table, notes)


# ---- Fig. 3.9 ----------------------------------------------------------------------------------------
@figure("fig3_9", "SNN in cloud robotics", studies=("fig3_9_cloud",))
def fig3_9(runs: RunSet, stem: Path) -> Figure:
    cloud = _snn_delay_runs(runs, lambda r: r.delay_preset in THESIS_CLOUD)
    if not cloud:
        raise MissingRuns("no SNN circle runs under the cloud / wifi_cloud delay presets (study fig3_9_cloud)")
    names = [k for k in THESIS_CLOUD if k in cloud]
    notes = [f"no run under the {k} preset" for k in THESIS_CLOUD if k not in cloud]
    d = {k: delays(cloud[k]) for k in names}
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    for ax, k in zip(axes, THESIS_CLOUD):
        if k not in cloud:
            ax.set_visible(False)
            continue
        for path, arr, ls, color in (("r2c", d[k][0], "-", "C0"), ("c2r", d[k][1], "--", "C3")):
            _cdf(ax, arr, color=color, lw=1.4, ls=ls, label=f"{path.upper()} (cerebx)")
            ax.plot(THESIS_CLOUD[k][path], (0.5, 0.9, 0.99), "x", color=color, ms=8,
                    label=f"{path.upper()} thesis p50/p90/p99 bounds")
        ax.set(xlabel="one-way delay (ms)", ylabel="CDF", title=k)
    _box(axes[2], [cloud[k].mae for k in names], names)
    axes[2].set_ylabel("SNN position MAE (rad) per trial")
    png = _finish(fig, stem, dict(zip("DEF", axes)), 7)

    table = [HEADER]
    for k in names:
        for i, path in enumerate(("r2c", "c2r")):
            v = d[k][i]
            ours = " / ".join(f"{x:.1f}" for x in np.percentile(v, (50, 90, 99))) if v.size else "–"
            paper = " / ".join(f"{x:g}" for x in THESIS_CLOUD[k][path])
            table.append([f"{k} {path.upper()} p50 / p90 / p99 (ms)", f"below {paper}", ours])
        table.append([f"{k} MAE (rad)", THESIS_CLOUD[k]["mae"], mean_std(cloud[k].mae)])
    if "cloud" in d:
        table.append(["cloud round trip (ms)", "ping RTT 20.0 ± 1.3", mean_std(d["cloud"][0] + d["cloud"][1], 1)])
    caption = ("Fig. 3.9 — SNN on the horizontal circle with the controller in the cloud: (D) Ethernet gateway "
               "(cloud), (E) Wi-Fi + Internet (wifi_cloud): CDFs of the R2C and C2R delays recorded in /control over "
               f"the first {DELAY_TRIALS} trials, crosses at the percentiles the thesis reports as upper bounds; "
               "(F) MAE per trial of each scenario. The delay tables are constructed from those percentiles "
               "(conf/delay/cloud.yaml, wifi_cloud.yaml). "
               f"Runs: {_trials(cloud.values())} per scenario "
               f"({', '.join(sorted({_origin(r) for r in cloud.values()}))}); thesis: 100 trials per scenario.")
    return Figure([png], caption, table, notes)


# ---- Fig. 3.10 ---------------------------------------------------------------------------------------
def _common_grid(ks: list[tuple[np.ndarray, np.ndarray]]) -> tuple[np.ndarray, np.ndarray]:
    """Kernels on one time grid (zero past each one's end); returns (t, kernels as rows)."""
    n = max(k.size for _, k in ks)
    t = ks[int(np.argmax([k.size for _, k in ks]))][0]
    return t, np.array([np.pad(k, (0, n - k.size)) for _, k in ks])


@figure("fig3_10", "Multikernel vs monokernel SNN under constant delays",
        studies=("fig3_10_multikernel", "learn_multikernel", "fig3_4_snn"))
def fig3_10(runs: RunSet, stem: Path) -> Figure:
    multi_all = runs.where(lambda r: _plain_circle(r) and r.controller == "snn" and len(r.kernel_peaks_ms) > 1)
    if not multi_all:
        raise MissingRuns("no multikernel SNN circle runs (studies fig3_10_multikernel, learn_multikernel)")
    (multi, notes_multi), (mono, notes_mono) = _sweep(runs, "snn", multikernel=True), _sweep(runs, "snn")
    notes = notes_multi + notes_mono
    if not multi:
        notes.append("no multikernel runs under constant delays (study fig3_10_multikernel): panel C lacks them")
    if not mono:
        notes.append("no monokernel SNN runs under constant delays (study fig3_4_snn)")
    src = (RunSet(multi.values()) or multi_all).best()
    mk = kernels(src)
    fig, (ax_a, ax_b, ax_c) = plt.subplots(1, 3, figsize=(16, 4.6))
    for i, (name, rule, t, k) in enumerate(mk):
        ax_a.plot(t, k, color=f"C{i}", lw=1.3, label=f"{name}: peak {rule.kernel_peak_ms:g} ms")
    t, rows = _common_grid([(t, k) for _, _, t, k in mk])
    ax_b.plot(t, rows.mean(0), "C2", lw=1.6, label="multikernel mean")
    mono_src = next(iter(mono.values()), None)
    if mono_src is not None:
        for _, rule, t1, k1 in kernels(mono_src):
            ax_b.plot(t1, k1, "C0--", lw=1.4, label=f"monokernel (peak {rule.kernel_peak_ms:g} ms)")
    for ax in (ax_a, ax_b):
        ax.set(xlabel="PF spike before CF spike (ms)", ylabel="LTD kernel k (peak = 1)")
    for sweep, label, color in ((multi, "multikernel", "C2"), (mono, "monokernel", "C0")):
        if sweep:
            s = np.array([_ms(r.mae) for r in sweep.values()])
            ax_c.errorbar(list(sweep), s[:, 0], s[:, 1], marker="o", capsize=3, color=color, label=label)
    ax_c.set(xlabel="constant round-trip delay δT (ms)", ylabel="position MAE (rad), mean ± std")
    png = _finish(fig, stem, {"A": ax_a, "B": ax_b, "C": ax_c})

    table = [HEADER]
    for dt in sorted(set(multi) | set(mono)):
        a = mean_std(multi[dt].mae) if dt in multi else "–"
        b = mean_std(mono[dt].mae) if dt in mono else "–"
        table.append([f"MAE at δT = {dt:g} ms, multikernel / monokernel (rad)",
                      "figure only: multikernel not better", f"{a} / {b}"])

    def rt(rs: Iterable[Run]) -> str:
        v = [r.summary["rt_factor"] for r in rs if r.summary.get("rt_factor")]
        return "–" if not v else f"{np.mean(v):.2f}"
    rt_runs = list(multi.values()) or list(multi_all)
    table.append(["real-time capacity, multikernel / monokernel", "99.263 % / 99.999 % of experiment time",
                  f"rt_factor {rt(rt_runs)} / {rt(mono.values())} (sim s per wall s)"])
    pcs = ", ".join(f"{n} {p.get('size')}" for n, p in (src.get("controller.network.populations") or {}).items()
                    if n.startswith("pc") and isinstance(p, dict))
    where = f"{src.dir.parent.name}/{src.dir.name}"
    mono_text = f"{_trials(mono.values())}, {_origin(next(iter(mono.values())))}" if mono else "none"
    caption = ("Fig. 3.10 — multikernel vs monokernel SNN on the horizontal circle. (A) the LTD kernels of the "
               f"multikernel network ({src.network}; PCs: {pcs}) from the config of {where}; "
               "(B) their mean beside the monokernel kernel; (C) MAE (mean ± std over trials) under constant "
               "round-trip delays. "
               f"Multikernel: {_trials(multi.values()) if multi else 'no delay runs'}"
               f"{', ' + _origin(next(iter(multi.values()))) if multi else ''}; monokernel (fig3_4 SNN runs): "
               f"{mono_text}; thesis: 100 trials per δT. The multikernel "
               f"rt_factor is that of {'its delay runs' if multi else 'its learning run'}; rt_factor is simulated "
               "seconds per wall-clock second over the whole run (≥ 1: faster than real time; it depends on the "
               "machine's load); the thesis reports the share of time EDLUT ran at full real-time capacity, a "
               "different measure.")
    return Figure([png], caption, table, notes)


# ---- Fig. 3.3: convergence -------------------------------------------------------------------------
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
    found = {task: from_scratch(runs, task) for task in CH3_TASKS}
    if not any(found.values()):
        raise MissingRuns("no snn runs learning circle / inclined_circle / circle_eight from scratch "
                          "(studies learn_circle_ch3, learn_inclined_circle, learn_circle_eight)")
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.3))
    table = [["quantity", "paper", "cerebx"]]
    notes, used = [], []
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
        used.append(f"{letter}: {_rel(run)}, {len(mae)} trials of {period:.0f} s")
    fig.tight_layout()
    caption = ("Thesis Fig. 3.3: MAE per trial of the snn controller learning from scratch (thesis: stabilization "
               f"after about 500 trials). Runs: {'; '.join(used)}. Stabilization trial: the first trial where the "
               f"trailing running mean (max(5, n/50) trials) is within {CONVERGENCE_TOL:.0%} of the final level "
               "(mean of the last 10 % of trials).")
    return Figure([save(fig, stem)], caption, table, notes)


# ---- Fig. 3.5: end-effector density under a 50 ms delay ------------------------------------------
def _sample_ee(run: Run, trials: int = FIG3_5_TRIALS) -> tuple[np.ndarray, np.ndarray, int]:
    """ee and ee_des of up to ``trials`` evenly spaced trials (time-windowed reads), and how many."""
    n, period, w = run.trials, run.period_s, min(run.warmup, max(run.trials - 1, 0))
    picks = np.unique(np.linspace(w, n - 1, min(n - w, trials)).round().astype(int))
    ee, des = [], []
    for k in picks:
        c = run.control(["ee", "ee_des"], k * period, (k + 1) * period, every=2)
        if c["ee"].size:
            ee.append(c["ee"])
            des.append(c["ee_des"])
    if not ee:
        return np.zeros((0, 3)), np.zeros((0, 3)), 0
    return np.concatenate(ee), np.concatenate(des), len(picks)


def plane(des: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Origin, 2x3 projection and axis labels: x-y for a flat path, else its two principal axes."""
    if not des.size:
        return np.zeros(3), np.eye(3)[:2], ["x (m)", "y (m)"]
    spread = np.ptp(des, axis=0)
    if spread[2] <= 0.05 * max(spread[0], spread[1]):
        return np.zeros(3), np.eye(3)[:2], ["x (m)", "y (m)"]
    centre = des.mean(0)
    axes = np.linalg.svd(des - centre, full_matrices=False)[2][:2]
    for i in range(2):  # orient: first axis along +x, second along +y
        if axes[i, i] < 0:
            axes[i] *= -1
    labels = [f"{u} (m) along ({a[0]:.2f}, {a[1]:.2f}, {a[2]:.2f})" for u, a in zip("uv", axes, strict=True)]
    return centre, axes, labels


def _limits(des2: np.ndarray, clouds: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Panel limits: the desired path with a 6 cm margin, widened to the 1-99 % range of the densities but at
    most 35 cm from the path's centre."""
    if not des2.size:
        return np.full(2, -0.3), np.full(2, 0.3)
    lo, hi = des2.min(0) - 0.06, des2.max(0) + 0.06
    if clouds:
        pts = np.concatenate(clouds)
        lo, hi = np.minimum(lo, np.percentile(pts, 1, axis=0)), np.maximum(hi, np.percentile(pts, 99, axis=0))
    mid = (des2.min(0) + des2.max(0)) / 2
    return np.maximum(lo, mid - 0.35), np.minimum(hi, mid + 0.35)


def _density_rgba(h: np.ndarray, color: str) -> np.ndarray:
    img = np.zeros((*h.shape, 4))
    img[..., :3] = to_rgb(color)
    img[..., 3] = 0.85 * np.sqrt(h / h.max()) if h.max() > 0 else 0.0
    return img


@figure("fig3_5", "End-effector density under a 50 ms delay: PD vs SNN and ANN vs SNN (Fig. 3.5)",
        studies=("fig3_5_snn_circle", "fig3_5_snn_inclined_circle", "fig3_5_snn_circle_eight", "fig3_5_ann_circle",
                 "fig3_5_ann_inclined_circle", "fig3_5_ann_circle_eight", "fig3_5_pd_circle",
                 "fig3_5_pd_inclined_circle", "fig3_5_pd_circle_eight", "fig3_5_position", "baselines_circle"))
def fig3_5(runs: RunSet, stem: Path) -> Figure:
    delayed = runs.where(lambda r: r.delay == "constant" and r.delay_total_ms == FIG3_5_DELAY_MS and r.trials > 0
                         and (r.controller != "snn" or r.kernel_peaks_ms == [THESIS_KERNEL_MS]))
    slots = {(task, c): delayed.where(task=task, controller=c).best()
             for task in CH3_TASKS for c in ("pd", "ann", "snn")}
    if not any(slots.values()):
        raise MissingRuns(f"no pd / ann / snn runs under a constant {FIG3_5_DELAY_MS:.0f} ms delay "
                          "(studies fig3_5_*)")
    refs = {task: runs.where(lambda r: r.is_factory_position and r.trials > 0, task=task, delay="none").best()
            for task in CH3_TASKS}
    data = {key: _sample_ee(r) for key, r in slots.items() if r is not None}
    colors = {"pd": "C3", "ann": "C1", "snn": "C0"}
    fig, axes = plt.subplots(2, 3, figsize=(15, 9.6))
    notes: list[str] = []
    table = [["quantity", "paper", "cerebx"]]
    claims = {"snn": "figure only (SNN stays accurate)", "ann": "figure only (ANN degrades)",
              "pd": "figure only (PD degrades)"}
    for col, task in enumerate(CH3_TASKS):
        des = next((data[(task, c)][1] for c in ("snn", "ann", "pd") if (task, c) in data), np.zeros((0, 3)))
        ref = refs[task]
        ref_ee = (ref.control(["ee"], (ref.trials - 1) * ref.period_s, ref.trials * ref.period_s)["ee"]
                  if ref is not None else np.zeros((0, 3)))
        if not des.size and ref_ee.size:
            des = ref_ee
        centre, proj, labels = plane(des)
        pd_ = {key: (v[0] - centre) @ proj.T for key, v in data.items() if key[0] == task}
        des2 = (des - centre) @ proj.T if des.size else np.zeros((0, 2))
        lo, hi = _limits(des2, list(pd_.values()))
        for row, other in enumerate(("pd", "ann")):
            ax = axes[row, col]
            handles = []
            for c in (other, "snn"):
                pts = pd_.get((task, c))
                r = slots[(task, c)]
                if pts is None or r is None:
                    continue
                h, xe, ye = np.histogram2d(pts[:, 0], pts[:, 1], bins=120, range=[[lo[0], hi[0]], [lo[1], hi[1]]])
                ax.imshow(_density_rgba(h.T, colors[c]), origin="lower", extent=(xe[0], xe[-1], ye[0], ye[-1]),
                          interpolation="nearest", aspect="equal")
                handles.append(Patch(color=colors[c], label=f"{c.upper()} ({data[(task, c)][2]} trials)"))
            if des2.size:
                handles += ax.plot(des2[:, 0], des2[:, 1], "k--", lw=1, label="desired")
            if ref_ee.size:
                r2 = (ref_ee - centre) @ proj.T
                handles += ax.plot(r2[:, 0], r2[:, 1], color="C2", lw=1.2, label="factory position, no delay")
            ax.set_xlim(lo[0], hi[0])
            ax.set_ylim(lo[1], hi[1])
            ax.set_xlabel(labels[0], fontsize=8)
            ax.set_ylabel(labels[1], fontsize=8)
            ax.set_title(f"{'ABCDEF'[3 * row + col]}  {other.upper()} vs SNN, {TASK_NAMES[task]}", loc="left",
                         fontweight="bold", fontsize=10)
            if handles:
                ax.legend(handles=handles, fontsize=7, loc="upper right")
            else:
                ax.text(0.5, 0.5, "no runs", transform=ax.transAxes, ha="center")
        for c in ("pd", "ann", "snn"):
            r = slots[(task, c)]
            table.append([f"{TASK_NAMES[task]}, {c.upper()} at {FIG3_5_DELAY_MS:.0f} ms: MAE (rad)", claims[c],
                          f"{mean_std(r.mae)} ({r.n_measured} trials)" if r is not None else "not run"])
        missing = [c for c in ("pd", "ann", "snn") if slots[(task, c)] is None]
        if missing:
            notes.append(f"no {' / '.join(missing)} run on {task} at {FIG3_5_DELAY_MS:.0f} ms")
        table.append([f"{TASK_NAMES[task]}, factory position, no delay: MAE (rad)", PAPER_FACTORY_CH3[task],
                      f"{mean_std(ref.mae)} ({ref.n_measured} trials)" if ref is not None else "not run"])
        if ref is None:
            notes.append(f"no factory position run on {task} without delay: no reference path")
    fig.suptitle(f"End-effector density under a constant {FIG3_5_DELAY_MS:.0f} ms round-trip delay", fontsize=11)
    fig.tight_layout()
    counts = sorted({f"{data[k][2]} of {slots[k].trials}" for k in data})
    caption = (f"Thesis Fig. 3.5: end-effector density of PD vs SNN (A–C) and ANN vs SNN (D–F) under a constant "
               f"{FIG3_5_DELAY_MS:.0f} ms round-trip delay (thesis: 100 trials per controller; here the density of "
               f"{', '.join(counts)} trials, evenly spaced, every 2nd control step); dashed: desired path; green: "
               "last trial of the factory position controller without delay. Circle and circle-Lissajous in the xy "
               "plane, the inclined circle in the principal plane of its desired path.")
    return Figure([save(fig, stem)], caption, table, notes)


# ---- Plant realism (issue #11): which plant features the chapter 3 orderings depend on --------------
REALISM_PLANTS = ("baxter", "baxter_sea", "baxter_noise", "baxter_lag5", "baxter_lag10", "baxter_urdf_armature")
REALISM_DELAYS_MS = (0.0, 50.0)


def _plant_preset(run: Run) -> str:
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
    cells = realism_cells(runs)
    if not cells:
        raise MissingRuns("no runs of the plant realism study (studies realism_pd, realism_snn)")
    fig, ax = plt.subplots(figsize=(10, 4))
    width = 0.2
    table = [["quantity", "paper", "cerebx"]]
    notes = []
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
    caption = ("Plant realism study (issue #11, not a thesis figure): MAE on the circle (mean of the "
               "measured trials) of PD (original PD_circle gains) and of the SNN (the chapter 3 learned "
               "circle, 10 more learning trials on each plant, delay-robust default controller) on each "
               "plant variant: the default rigid arm, series elastic actuators, sensor noise (0.5 mrad, "
               "5 mrad/s), a 5 / 10 ms first-order torque lag, and the URDF's armature (none). "
               "Constructed noise and lag levels; 0 and 50 ms constant round trips.")
    return Figure([save(fig, stem)], caption, table, notes)
