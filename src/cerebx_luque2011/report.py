"""Figures of Luque et al. 2011 (the feed-forward corrective cerebellum on a 3-joint LWR): Fig. 7c (the learned
PF-PC weights), Fig. 8 (LTD x LTP estimators), Fig. 9 (delays with the kernel matched), Fig. 10 (kernel
mismatched with the delay) and Fig. 12 (objects of 0.5-2 kg). The MAE of a trial is the sum over the three
joints (paper Section III-A); the estimators are Eq. 8-11 (``cerebx.metrics``)."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np

from cerebx import metrics
from cerebx.report.convergence import Convergence, learning_convergence
from cerebx.report.plot import fmt, panel_letter, save
from cerebx.report.registry import Check, Figure, MissingRuns, figure, studies
from cerebx.report.runs import Run, RunSet
from cerebx.report.studies import study_plateau
from cerebx_luque2011.cerebellum.schema import Luque2011Cerebellum

studies(Path(__file__).with_name("studies.yaml"))

HEADER = ["quantity", "paper", "cerebx"]
N_JOINTS = 3
FINAL_TRIALS = 30  # the paper's final error: the last 30 trials (Eq. 9)
NEARLY_CONSTANT = 1.5  # Fig. 9: "nearly constant" final error, the largest at most this times the smallest
UNSTABLE = 1.05  # Fig. 10: unstable, the final error this much above the lowest it had reached
# Fig. 11 caption: error reduction after 200 / 400 trials, by object mass (kg)
PAPER_IMPROVEMENT = {0.5: (40.4, 49.0), 1.0: (64.6, 64.5), 1.5: (72.5, 74.4), 2.0: (78.6, 79.3)}


def _cer(r: Run, dotted: str):
    """A field of the run's cerebellum part (the composite's part of kind luque2011_cerebellum)."""
    parts = r.get("controller.parts") or []
    node = next((p for p in parts if isinstance(p, dict) and p.get("kind") == "luque2011_cerebellum"), None)
    for key in dotted.split("."):
        if not isinstance(node, dict):
            return None
        node = node.get(key)
    return node


def _luque(runs: RunSet) -> RunSet:
    return runs.where(lambda r: r.task == "luque_eight" and _cer(r, "kind") == "luque2011_cerebellum")


DEFAULT = Luque2011Cerebellum().plasticity


def _default_arm_lag(r: Run) -> bool:
    """The schema's arm lag (runs made before it existed, or with another, are left out)."""
    return _cer(r, "plasticity.arm_lag_ms") == DEFAULT.arm_lag_ms


def _default_plasticity(r: Run) -> bool:
    """LTD, LTP and arm lag at the preset's values (the runs of Fig. 9-12, not the Fig. 8 grid)."""
    return (_cer(r, "plasticity.ltd_nS") == DEFAULT.ltd_nS and _cer(r, "plasticity.ltp_nS") == DEFAULT.ltp_nS
            and _default_arm_lag(r))


def _learnt(runs: RunSet, curves: dict, label, study: str) -> Convergence:
    """The plateau tests of the learning curves of ``curves`` (key -> run), against the full profile's trials of
    ``study`` (the paper's trial count)."""
    return learning_convergence([(label(k), r, study_plateau(study)) for k, r in curves.items()], runs)


def _mae_sum(r: Run) -> np.ndarray:
    """MAE per trial summed over the joints (the summary holds the mean over joints)."""
    return r.mae * N_JOINTS


def _estimators(r: Run) -> dict[str, float]:
    m = list(_mae_sum(r))
    return {"accuracy gain (rad)": metrics.accuracy_gain(m), "final error (rad)": metrics.final_error(m),
            "final error stability (rad)": metrics.final_error_stability(m),
            "convergence (trials)": float(metrics.convergence_speed(m))}


def _finish(fig, stem: Path, axes: list) -> Path:
    for letter, ax in zip("ABCDEF", axes):
        panel_letter(ax, letter)
    fig.tight_layout()
    return save(fig, stem)


def _default_1kg(r: Run) -> bool:
    return (r.get("plant.object_mass_kg") == 1.0 and r.delay_total_ms == 100.0
            and _cer(r, "plasticity.kernel_peak_ms") == 100.0 and _default_arm_lag(r))


# ---- Fig. 8 ----------------------------------------------------------------------------------------------------
@figure("luque2011_fig8", "Luque 2011 Fig. 8: LTD x LTP trade-off", studies=("luque2011_fig8",))
def fig8(runs: RunSet, stem: Path) -> Figure:
    rs = _luque(runs).where(_default_1kg)
    cells = rs.by(lambda r: (_cer(r, "plasticity.ltd_nS"), _cer(r, "plasticity.ltp_nS")))
    if len(cells) < 4:
        raise MissingRuns("fewer than 4 LTD x LTP points of the 1 kg eight (study luque2011_fig8)")
    ltds = sorted({k[0] for k in cells})
    ltps = sorted({k[1] for k in cells})
    names = list(_estimators(next(iter(cells.values()))))
    grids = {n: np.full((len(ltps), len(ltds)), np.nan) for n in names}
    for (ltd, ltp), r in cells.items():
        for n, v in _estimators(r).items():
            grids[n][ltps.index(ltp), ltds.index(ltd)] = v
    fig, axes = plt.subplots(1, 4, figsize=(18, 4.4))
    for ax, n in zip(axes, names):
        im = ax.imshow(grids[n], origin="lower", aspect="auto", cmap="viridis")
        ax.set_xticks(range(len(ltds)), [f"{v:g}" for v in ltds])
        ax.set_yticks(range(len(ltps)), [f"{v:g}" for v in ltps])
        ax.set_xlabel("LTD (nS per IO spike at the kernel peak)")
        ax.set_ylabel("LTP (nS per PF spike)")
        ax.set_title(n, fontsize=10)
        for (i, j), v in np.ndenumerate(grids[n]):
            ax.text(j, i, "" if np.isnan(v) else f"{v:.3g}", ha="center", va="center", fontsize=7, color="w")
        fig.colorbar(im, ax=ax)
    png = _finish(fig, stem, list(axes))
    trials = min(r.trials for r in cells.values())
    best = min(cells, key=lambda k: _estimators(cells[k])["final error (rad)"])
    table = [HEADER, ["balanced point", "LTD 0.075 with LTP < 0.015", f"lowest final error at LTD {best[0]:g}, "
                      f"LTP {best[1]:g}"]]
    checks = [Check("balanced point: the lowest final error at LTD 0.075 with LTP < 0.015",
                    best[0] == 0.075 and best[1] < 0.015, f"lowest at LTD {best[0]:g}, LTP {best[1]:g} "
                    f"({_estimators(cells[best])['final error (rad)']:.3f} rad)")]
    for (ltd, ltp), r in cells.items():
        e = _estimators(r)
        table.append([f"LTD {ltd:g}, LTP {ltp:g}", "–", f"final {e['final error (rad)']:.3f}, std "
                      f"{e['final error stability (rad)']:.4f}, gain {e['accuracy gain (rad)']:.3f}, "
                      f"conv. {e['convergence (trials)']:.0f}"])
    caption = (f"The four estimators (Eq. 8-11, last 30 trials) over the LTD x LTP grid, 1 kg object, {trials} "
               "trials per point. Paper: LTP-dominated points saturate (high, flat error: low stability "
               "estimate), LTD-dominated points reach low error but are unstable; LTD 0.075 needs LTP < 0.015.")
    conv = _learnt(runs, cells, lambda k: f"LTD {k[0]:g}, LTP {k[1]:g}", "luque2011_fig8")
    return Figure([png], caption, table, checks=checks, convergence=conv)


# ---- Fig. 9 / 10 -------------------------------------------------------------------------------------------------
def _curves_and_final(rs: dict, stem: Path, xlabel: str, label) -> tuple[Path, list[list[str]]]:
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(12, 4.4))
    cmap = plt.get_cmap("viridis")
    xs, finals, stds = [], [], []
    for i, (x, r) in enumerate(rs.items()):
        m = _mae_sum(r)
        ax_a.plot(m, color=cmap(i / max(1, len(rs) - 1)), lw=1, label=label(x))
        xs.append(x)
        finals.append(metrics.final_error(list(m)))
        stds.append(metrics.final_error_stability(list(m)))
    ax_a.set_xlabel("trial")
    ax_a.set_ylabel("MAE, sum over joints (rad)")
    ax_a.legend(fontsize=8)
    ax_b.errorbar(xs, finals, stds, marker="o", capsize=3)
    ax_b.set_xlabel(xlabel)
    ax_b.set_ylabel("final error, last 30 trials (rad)")
    ax_b.set_ylim(bottom=0)
    for ax in (ax_a, ax_b):
        ax.grid(alpha=0.3)
    rows = [[label(x), "–", f"{f:.3f} ± {s:.4f}"] for x, f, s in zip(xs, finals, stds)]
    return _finish(fig, stem, [ax_a, ax_b]), rows


@figure("luque2011_fig9", "Luque 2011 Fig. 9: delays with the kernel matched", studies=("luque2011_fig9",))
def fig9(runs: RunSet, stem: Path) -> Figure:
    rs = _luque(runs).where(lambda r: r.get("plant.object_mass_kg") == 1.0 and _default_plasticity(r)
                            and _cer(r, "plasticity.kernel_peak_ms") == r.delay_total_ms)
    by_delay = rs.by(lambda r: r.delay_total_ms)
    if len(by_delay) < 2:
        raise MissingRuns("fewer than 2 delays with a matched kernel (study luque2011_fig9)")
    png, rows = _curves_and_final(by_delay, stem, "sensorimotor delay = kernel peak (ms)",
                                  lambda d: f"delay {d:g} ms")
    finals = [float(r.split()[0]) for _, _, r in rows]
    table = [HEADER, ["final error across delays", "nearly constant", f"{min(finals):.3f} - {max(finals):.3f} rad"],
             *rows]
    checks = [Check(f"final error nearly constant across delays (largest within {NEARLY_CONSTANT:g}× the smallest)",
                    max(finals) <= NEARLY_CONSTANT * min(finals),
                    ", ".join(f"{d:g} ms {f:.3f}" for d, f in zip(by_delay, finals)) + " rad")]
    conv = _learnt(runs, by_delay, lambda d: f"delay {d:g} ms", "luque2011_fig9")
    return Figure([png], "MAE per trial and final error for round-trip delays with the LTD kernel peak at the "
                  f"delay + the arm's own lag ({DEFAULT.arm_lag_ms:g} ms, constructed; 1 kg object). Paper: the "
                  "delay hardly changes the final error.", table, checks=checks, convergence=conv)


@figure("luque2011_fig10", "Luque 2011 Fig. 10: kernel peak vs delay mismatch", studies=("luque2011_fig10",))
def fig10(runs: RunSet, stem: Path) -> Figure:
    rs = _luque(runs).where(lambda r: r.get("plant.object_mass_kg") == 1.0 and r.delay_total_ms == 100.0
                            and _default_plasticity(r))
    by_dev = rs.by(lambda r: _cer(r, "plasticity.kernel_peak_ms") - 100.0)
    if len(by_dev) < 2:
        raise MissingRuns("fewer than 2 kernel peaks at the 100 ms delay (study luque2011_fig10)")
    png, rows = _curves_and_final(by_dev, stem, "kernel peak - delay (ms)", lambda d: f"mismatch {d:+g} ms")
    table = [HEADER, ["mismatch 50-70 ms", "still learns, final error constant", "see rows"],
             ["mismatch > 70 ms", "unstable", "see rows"], *rows]
    checks = _fig10_checks(by_dev)
    conv = _learnt(runs, by_dev, lambda d: f"mismatch {d:+g} ms", "luque2011_fig10")
    return Figure([png], "Kernel peak moved away from the 100 ms teaching delay (1 kg object; the kernel peaks at "
                  f"the setting + the arm's own lag, {DEFAULT.arm_lag_ms:g} ms, constructed). Paper: 50-70 ms of "
                  "mismatch still learn; beyond about 70 ms learning becomes unstable.", table, checks=checks,
                  convergence=conv)


def _fig10_checks(by_dev: dict[float, Run]) -> list[Check]:
    """Fig. 10's shapes: the matched kernel learns best; 50-70 ms of mismatch still learns (the final error below
    half the first trials'); beyond 70 ms learning is unstable (the error rises again after its lowest)."""
    m = {d: _mae_sum(r) for d, r in by_dev.items()}
    final = {d: metrics.final_error(list(v)) for d, v in m.items()}
    checks = [Check("the matched kernel (mismatch 0) gives the lowest final error", min(final, key=final.get) == 0,
                    ", ".join(f"{d:+g} ms {v:.3f}" for d, v in final.items()) + " rad")]
    still = {d: (float(v[:FINAL_TRIALS].mean()), final[d]) for d, v in m.items() if 50 <= abs(d) <= 70}
    if still:
        checks.append(Check("50-70 ms of mismatch still learns (final error below half the first trials')",
                            all(b < 0.5 * a for a, b in still.values()),
                            ", ".join(f"{d:+g} ms {a:.3f} → {b:.3f}" for d, (a, b) in still.items()) + " rad"))
    beyond = {d: (_lowest(v), final[d]) for d, v in m.items() if abs(d) > 70}
    if beyond:
        checks.append(Check(f"beyond 70 ms of mismatch learning is unstable (the final error over {UNSTABLE:g}× the "
                            "lowest running mean)", all(b > UNSTABLE * a for a, b in beyond.values()),
                            ", ".join(f"{d:+g} ms lowest {a:.3f}, final {b:.3f}" for d, (a, b) in beyond.items())
                            + " rad"))
    return checks


def _lowest(mae: np.ndarray) -> float:
    """The lowest mean over FINAL_TRIALS consecutive trials."""
    w = min(FINAL_TRIALS, mae.size)
    return float(np.convolve(mae, np.ones(w) / w, mode="valid").min())


# ---- Fig. 11 / 12 and Fig. 7c ---------------------------------------------------------------------------------------
@figure("luque2011_fig12", "Luque 2011 Fig. 12: objects of 0.5-2 kg", studies=("luque2011_fig12",))
def fig12(runs: RunSet, stem: Path) -> Figure:
    rs = _luque(runs).where(lambda r: r.delay_total_ms == 100.0 and _cer(r, "plasticity.kernel_peak_ms") == 100.0
                            and _default_plasticity(r))
    by_mass = rs.by(lambda r: r.get("plant.object_mass_kg"))
    if len(by_mass) < 2:
        raise MissingRuns("fewer than 2 object masses (study luque2011_fig12)")
    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(12, 4.4))
    table = [HEADER]
    gains = []
    for i, (mass, r) in enumerate(by_mass.items()):
        m = list(_mae_sum(r))
        ax_a.plot(m, lw=1, color=f"C{i}", label=f"{mass:g} kg")
        at = [t for t in (200, 400) if t <= len(m) + r.warmup]  # trials counted from the run's start
        ours = [metrics.improvement_pct(m, min(t, len(m))) for t in at]
        paper = PAPER_IMPROVEMENT.get(float(mass))
        gains.append((mass, metrics.accuracy_gain(m), ours))
        for t, v in zip(at, ours):
            p = "–" if paper is None else f"{paper[0 if t == 200 else 1]:.1f} %"
            table.append([f"{mass:g} kg: error reduction by trial {t}", p, f"{v:.1f} %"])
        table.append([f"{mass:g} kg: first-trial MAE / accuracy gain (rad)", "–",
                      f"{m[0]:.3f} / {metrics.accuracy_gain(m):.3f}"])
    ax_a.set_xlabel("trial")
    ax_a.set_ylabel("MAE, sum over joints (rad)")
    ax_a.legend(fontsize=8)
    width = 0.35
    xs = np.arange(len(gains))
    ax_b.bar(xs - width / 2, [g[2][-1] if g[2] else np.nan for g in gains], width, label="cerebx")
    ax_b.bar(xs + width / 2, [PAPER_IMPROVEMENT.get(float(g[0]), (np.nan, np.nan))[1] for g in gains], width,
             label="paper (400 trials)")
    ax_b.set_xticks(xs, [f"{g[0]:g} kg" for g in gains])
    ax_b.set_ylabel("error reduction at the last trial (%)")
    ax_b.set_ylim(top=118)  # room above the bars (reductions are percentages) for the legend
    ax_b.legend(fontsize=8, loc="upper center", ncols=2)
    for ax in (ax_a, ax_b):
        ax.grid(alpha=0.3)
    png = _finish(fig, stem, [ax_a, ax_b])
    ordered = all(a[1] < b[1] for a, b in zip(gains, gains[1:]))
    table.insert(1, ["accuracy gain grows with the mass", "yes", "yes" if ordered else "no"])
    checks = [Check("accuracy gain grows with the mass", ordered,
                    ", ".join(f"{g[0]:g} kg {g[1]:.3f}" for g in gains) + " rad")]
    conv = _learnt(runs, by_mass, lambda m: f"{m:g} kg", "luque2011_fig12")
    return Figure([png], "MAE per trial with objects of 0.5-2 kg held at the hand; the crude inverse dynamics "
                  "ignores the object. Paper: heavier objects start worse and gain more.", table, checks=checks,
                  convergence=conv)


@figure("luque2011_fig7c", "Luque 2011 Fig. 7c: learned PF-PC weights", studies=("luque2011_fig12",))
def fig7c(runs: RunSet, stem: Path) -> Figure:
    rs = _luque(runs).where(lambda r: _default_1kg(r) and _default_plasticity(r)
                            and (r.dir / "controller_state.part1.npz").exists())
    r = rs.best()
    if r is None:
        raise MissingRuns("no 1 kg run with a saved cerebellum state (study luque2011_fig12)")
    w = np.load(r.dir / "controller_state.part1.npz")["w"]
    fig, ax = plt.subplots(figsize=(9, 4.6))
    im = ax.imshow(w, aspect="auto", cmap="gray", origin="lower", interpolation="nearest")
    n_in = w.shape[1]
    ax.set_xticks(np.arange(6) * n_in // 6 + n_in // 12, ["q1", "q2", "q3", "qd1", "qd2", "qd3"])
    ax.set_yticks(np.arange(6) * 8 + 3.5, ["q1 +", "q1 -", "q2 +", "q2 -", "q3 +", "q3 -"])
    ax.set_xlabel("input cell (PF), by desired signal")
    ax.set_ylabel("Purkinje cell, by output group")
    fig.colorbar(im, ax=ax, label="PF-PC weight (nS)")
    png = _finish(fig, stem, [ax])
    table = [HEADER, ["weights after learning", "six column blocks x six row blocks, dark at the inputs' edges",
                      f"{fmt(float(w.min()), 2)} - {fmt(float(w.max()), 2)} nS after {r.trials} trials"]]
    return Figure([png], f"PF-PC weights after {r.trials} trials (1 kg object; dark = low weight = more DCN "
                  "activity for that output group).", table, convergence=_learnt(runs, {1.0: r}, lambda m: "1 kg",
                                                                                 "luque2011_fig12"))
