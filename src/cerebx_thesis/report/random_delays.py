"""The SNN under random delays, the links of a robot on a network: thesis Fig. 3.7 (symmetric and
asymmetric gamma delays), Fig. 3.8 (a Wi-Fi gateway at three bandwidth loads) and Fig. 3.9 (the
controller in the cloud). Realised delays are the R2C / C2R delays recorded in /control over a run's first
trials (the delay processes are stationary, so a window is enough and keeps big runs fast)."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from cerebx.report.api import (  # noqa: E402
    DELAY_TRIALS,
    Check,
    Convergence,  # noqa: E402
    Figure,
    MissingRuns,
    Run,
    RunSet,
    delays,
    figure,
    fmt,
    mean_std,
)
from cerebx_thesis.report.common import (  # noqa: E402
    CH3_STUDY,
    HEADER,
    finish,
    learnt,
    origin,
    plain_circle,
    prefer_learned,
    reference_run,
    trial_counts,
)

# thesis §3.3.3: nominal delays of the symmetric (round trip) and asymmetric (R2C, C2R) gamma sets
THESIS_GAMMA = {"gamma15": "15 ± 5", "gamma25": "25 ± 5", "gamma35": "35 ± 5", "gamma45": "45 ± 5",
                "gamma55": "55 ± 5", "gamma65": "65 ± 5", "gamma78": "78 ± 4"}
THESIS_ASYM = {"asym_r2c8_c2r40": ("8 ± 3", "40 ± 3"), "asym_r2c39_c2r9": ("39 ± 2", "9 ± 4")}
# thesis §3.3.4: percentiles (p50, p90, p99) the cloud delays stayed below, and the MAE of each scenario
THESIS_CLOUD = {"cloud": {"r2c": (9, 10, 12), "c2r": (9, 10, 12), "mae": "0.020 ± 0.004"},
                "wifi_cloud": {"r2c": (12, 14, 20), "c2r": (29, 32, 36), "mae": "0.024 ± 0.007"}}


def _delay_label(run: Run) -> str:
    """The delay preset's name, or for a run that recorded none, its delay config in short."""
    if "delay" in (run.summary.get("presets") or {}):
        return run.delay_preset
    cfg = {k: v for k, v in (run.get("delay") or {}).items() if k != "kind"}
    return f"{run.delay} {cfg}"[:40]


def _snn_delay_runs(runs: RunSet, pred: Callable[[Run], bool]) -> dict[str, Run]:
    """Best SNN circle run per delay preset among those ``pred`` accepts."""
    rs = runs.where(lambda r: plain_circle(r) and r.controller == "snn" and pred(r))
    return rs.by(_delay_label, prefer_learned)


def _cdf(ax, v: np.ndarray, **kw) -> None:
    """The empirical CDF of ``v`` (nothing for no values)."""
    q = np.linspace(0.0, 1.0, 401)
    if v.size:
        ax.plot(np.quantile(v, q), q, **kw)


def _ref_lines(ax, runs: RunSet) -> list[Run]:
    """Dashed lines at the no-delay MAE of the PD and factory position controllers, when such runs exist."""
    used = []
    for kind, label, color in (("pd", "PD, no delay", "C3"), ("position", "factory position, no delay", "0.4")):
        r = reference_run(runs, kind)
        if r is not None and r.mae.size:
            ax.axhline(r.mae.mean(), ls="--", lw=1.1, color=color, label=f"{label} ({r.n_measured} trials)")
            used.append(r)
    return used


def _box(ax, data: list[np.ndarray], labels: list[str], color: str = "C0") -> None:
    """Box plots (quartiles, no fliers) of ``data`` with their means as diamonds."""
    pos = np.arange(len(data))
    ax.boxplot(data, positions=pos, widths=0.5, showfliers=False, patch_artist=True,
               boxprops={"facecolor": color, "alpha": 0.35}, medianprops={"color": "k"})
    ax.plot(pos, [np.mean(d) for d in data], "D", color=color, ms=4, label="mean")
    ax.set_xticks(pos, labels, rotation=30, ha="right", fontsize=8)


def _symmetric(r: Run) -> bool:
    """A symmetric gamma preset: one round-trip draw per step, or the same distribution both ways."""
    return bool(r.get("delay.symmetric")) or r.get("delay.r2c") == r.get("delay.c2r")


@figure("fig3_7", "SNN under symmetric and asymmetric gamma delays", studies=("fig3_7_gamma",))
def fig3_7(runs: RunSet, stem: Path) -> Figure:
    """PDF and CDF of the symmetric presets' round trips, CDFs of the asymmetric ones, MAE of each."""
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
    png = finish(fig, stem, dict(zip("ABCDE", (ax_a, ax_b, ax_c, axes_d[0], ax_e))), 7, others=axes_d[1:])

    table = [HEADER]
    for k in sym:
        table.append([f"{k}: round trip (ms)", THESIS_GAMMA.get(k, "–"), mean_std(rt[k], 1)])
        table.append([f"{k}: SNN MAE (rad)", "figure only (below the factory position MAE)", mean_std(gamma[k].mae)])
    for k in asym:
        p = THESIS_ASYM.get(k, ("–", "–"))
        table.append([f"{k}: R2C / C2R (ms)", f"{p[0]} / {p[1]}",
                      f"{mean_std(d[k][0], 1)} / {mean_std(d[k][1], 1)}"])
        table.append([f"{k}: SNN MAE (rad)", "figure only (coped with the delay)", mean_std(gamma[k].mae)])
    pos = reference_run(runs, "position")
    checks = []
    if pos is not None:
        worst = max(gamma[k].mae.mean() for k in gamma)
        table.append(["SNN MAE below the no-delay factory position MAE for every preset",
                      "yes (factory position 0.077 rad)",
                      f"{'yes' if worst < pos.mae.mean() else 'no'} (worst {worst:.3f} vs {pos.mae.mean():.3f})"])
        checks.append(Check("SNN MAE below the no-delay factory position MAE for every preset",
                            bool(worst < pos.mae.mean()), f"worst {worst:.3f} vs {pos.mae.mean():.3f} rad"))
    else:
        notes.append("no factory position controller circle run without delay for the reference")
    caption = ("Fig. 3.7 — SNN on the horizontal circle under random gamma delays. (A) PDF and (B) CDF of the "
               "realised round trip δT = R2C + C2R of the symmetric presets; (C) SNN MAE per trial per preset "
               "(box: quartiles, diamond: mean); (D) CDFs of R2C (solid) and C2R (dashed) of the asymmetric presets; "
               f"(E) their MAE. Delays are the values recorded in /control over the first {DELAY_TRIALS} trials "
               f"(every 2 ms step). Runs: {trial_counts(gamma.values())} per preset "
               f"({', '.join(sorted({origin(r) for r in gamma.values()}))}); thesis: 100 trials per preset. "
               + ("Dashed lines: " + ", ".join(f"{r.controller_preset} without delay ({r.n_measured} trials)"
                                               for r in refs) + "." if refs else ""))
    return Figure([png], caption, table, notes, checks, _snn_learning(runs, gamma))

def _load_mbps(name: str) -> int | None:
    """The bandwidth load of a Wi-Fi delay preset (``wifi54`` -> 54), None for another preset."""
    m = re.fullmatch(r"wifi(\d+)", name)
    return int(m.group(1)) if m else None


@figure("fig3_8", "SNN behind a Wi-Fi gateway", studies=("fig3_8_wifi",))
def fig3_8(runs: RunSet, stem: Path) -> Figure:
    """C: MAE per Wi-Fi load; D: CDFs of its sensor and motor delays."""
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
    png = finish(fig, stem, {"C": ax_c, "D": ax_d}, legend_size=7)

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
               f"Runs: {trial_counts(wifi.values())} per load "
               f"({', '.join(sorted({origin(r) for r in wifi.values()}))}); "
               "thesis: 100 trials per load.")
    return Figure([png], caption, table, notes, _below_factory(runs, wifi, "load"), _snn_learning(runs, wifi))

@figure("fig3_9", "SNN in cloud robotics", studies=("fig3_9_cloud",))
def fig3_9(runs: RunSet, stem: Path) -> Figure:
    """D, E: CDFs of the cloud scenarios' delays beside the thesis's percentiles; F: MAE of each."""
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
    png = finish(fig, stem, dict(zip("DEF", axes)), 7)

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
               f"Runs: {trial_counts(cloud.values())} per scenario "
               f"({', '.join(sorted({origin(r) for r in cloud.values()}))}); thesis: 100 trials per scenario.")
    return Figure([png], caption, table, notes, _below_factory(runs, cloud, "scenario"), _snn_learning(runs, cloud))


def _snn_learning(runs: RunSet, by_delay: dict[str, Run]) -> Convergence:
    """The convergence of the learning behind the SNN runs under random delays (the circle they started from)."""
    return learnt(runs, [("SNN", r, CH3_STUDY["circle"]) for r in by_delay.values()],
                  lambda q: "MAE" in q)


def _below_factory(runs: RunSet, by_delay: dict[str, Run], what: str) -> list[Check]:
    """The SNN under every delay more accurate than the factory position controller without delay."""
    pos = reference_run(runs, "position")
    if pos is None or not pos.mae.size:
        return []
    worst = max(by_delay, key=lambda k: by_delay[k].mae.mean())
    w, p = float(by_delay[worst].mae.mean()), float(pos.mae.mean())
    return [Check(f"SNN MAE below the no-delay factory position MAE at every {what}", w < p,
                  f"worst {worst} {w:.3f} vs {p:.3f} rad")]
