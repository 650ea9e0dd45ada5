"""Adaptation and human interaction in an unstructured environment: thesis Fig. 2.10 (MAE per trial while
a payload and an elastic band are attached and removed) with the table rows of §2.3.1's one-finger push
and grab through a soft spring, for the SNN, PD and the factory position controller."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from cerebx.api import grab_anchor, half_sine  # noqa: E402
from cerebx.report.api import Check, Figure, MissingRuns, Run, RunSet, figure, mean_std, save  # noqa: E402
from cerebx_thesis.report.common import LEARN_STUDY, TASK_NAMES, learnt, short_path, trial_range  # noqa: E402

# event kind -> (condition, switched on)
CONDITIONS = {"attach_payload": ("payload", True), "detach_payload": ("payload", False),
              "elastic_band": ("elastic band", True), "remove_band": ("elastic band", False)}


def run_events(run: Run) -> list[tuple[float, str]]:
    """(trial position, kind) of each plant event: from /events, else from the configured events."""
    period = run.period_s
    logged = [(t / period, msg["kind"]) for _, t, msg in run.messages(["/events"])]
    if logged:
        return logged
    out = []
    for e in run.events:
        at = e.get("at_trial")
        out.append((float(at) if at is not None else float(e.get("at_s", 0.0)) / period, e["action"]["kind"]))
    return sorted(out)


def phases(events: list[tuple[float, str]], n: int) -> list[tuple[int, int, str]]:
    """Trial ranges [a, b) between events, named by the conditions on (or 'before' / 'after ...')."""
    cuts = sorted({min(n, int(np.ceil(x - 1e-9))) for x, _ in events} | {0, n})
    out, active, last_off = [], set(), ""
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        for x, kind in events:
            if int(np.ceil(x - 1e-9)) == a and kind in CONDITIONS:
                cond, on = CONDITIONS[kind]
                (active.add if on else active.discard)(cond)
                last_off = last_off if on else cond
        name = " + ".join(sorted(active)) if active else (f"after {last_off}" if last_off else "before")
        out.append((a, b, name))
    return out


INTERACTIONS = ("finger_push", "grab")
RETURNED = 1.25  # back on the path: the MAE two trials after an event within this factor of the trial before


def _has_events(run: Run, kinds: tuple[str, ...] | dict) -> bool:
    """Whether the run has a configured event of one of ``kinds``."""
    return any(e.get("action", {}).get("kind") in kinds for e in run.events)


def interaction_metrics(run: Run) -> list[dict[str, float | str]]:
    """Per human-interaction event of ``run`` (thesis §2.3.1): the peak interaction force on the hand
    (N: the push's configured peak; the grab spring's k |anchor - hand|, from the logged hand path and
    the event's anchor path), the peak displacement of the hand from where it was at the same phase
    of the trial before the event, during the event and 1 s after (mm), their ratio (mm/N), and that
    displacement averaged over the last 0.5 s of the trial after the event trial (mm), and the position
    MAE (rad) of the trial before the event, the event's trial and the two after (back on the path?)."""
    period, out = run.period_s, []
    mae = list(run.summary.get("mae_per_trial") or [])
    for e in run.events:
        act = e.get("action", {})
        if act.get("kind") not in INTERACTIONS or e.get("at_trial") is None:
            continue
        t0 = float(e["at_trial"]) * period
        if act["kind"] == "finger_push":
            dur = float(act.get("duration_ms", 500.0)) / 1000.0
        else:
            dur = (float(act.get("drag_ms", 1000.0)) + float(act.get("hold_ms", 1000.0))) / 1000.0
        c = run.control(["ee"], t0 - period, t0 + 2 * period)
        t, ee = c["t"], np.asarray(c["ee"])
        ref = t < t0
        if ref.sum() < 2 or (~ref).sum() < 2:
            continue
        # the undisturbed hand path: the trial before the event, by phase
        phase = np.mod(t - t0, period)
        base = np.stack([np.interp(phase, np.mod(t[ref] - t0, period), ee[ref, k], period=period) for k in range(3)], 1)
        dist = np.linalg.norm(ee - base, axis=1) * 1000.0
        if act["kind"] == "finger_push":
            force = np.linalg.norm(act.get("force_N", (0, 0, 0))) * half_sine(t - t0, dur)
        else:
            start = ee[np.argmin(np.abs(t - t0))]
            anchor = grab_anchor(t - t0, start, np.asarray(act["displacement_m"], float),
                                 float(act.get("drag_ms", 1000.0)) / 1000.0)
            force = float(act["stiffness_N_per_m"]) * np.linalg.norm(anchor - ee, axis=1)
            force[(t < t0) | (t > t0 + dur)] = 0.0
        during = (t >= t0) & (t <= t0 + dur + 1.0)
        end = t >= t0 + 2 * period - 0.5
        f_peak, d_peak = float(force.max()), float(dist[during].max())
        out.append({"kind": act["kind"], "force_N": f_peak, "displacement_mm": d_peak,
                    "mm_per_N": d_peak / f_peak if f_peak > 0 else float("nan"),
                    "end_mm": float(dist[end].mean()) if end.any() else float("nan"),
                    "mae_trials": [float(mae[k]) for k in range(int(e["at_trial"]) - 1, int(e["at_trial"]) + 3)
                                   if 0 <= k < len(mae)]})
    return out


def _interaction_runs(runs: RunSet) -> list[tuple[str, Run | None]]:
    """(controller, its run with human-interaction events) for the SNN, PD and the factory stand-in."""
    inter = runs.where(lambda r: _has_events(r, INTERACTIONS) and r.trials > 0, delay="none")
    return [("SNN", inter.where(controller="snn").best()),
            ("PD", inter.where(controller="pd", controller_preset="pd").best()),
            ("factory position", inter.where(lambda r: r.is_factory_position).best())]


def _interaction_rows(runs: RunSet) -> tuple[list[list[str]], list[str], list[Check]]:
    """Table rows of the push and grab for the SNN, PD and factory position runs, notes on those missing, and
    the thesis's shapes: the SNN yields to a low force (more displacement per newton than PD) and returns to
    its path."""
    rows, notes = [], []
    measured = {}
    for name, run in _interaction_runs(runs):
        if run is None:
            notes.append(f"no {name} run with human-interaction events (studies interaction_*)")
            continue
        measured[name] = interaction_metrics(run)
        for m in measured[name]:
            what = "finger push" if m["kind"] == "finger_push" else "grab (soft spring)"
            claim = ("yields to a very low force, returns to the path" if name == "SNN"
                     else "figure only")
            rows.append([f"{name}, {what}: peak force (N) / peak hand displacement (mm) / mm per N",
                         claim, f"{m['force_N']:.2f} / {m['displacement_mm']:.1f} / {m['mm_per_N']:.2f}"])
            rows.append([f"{name}, {what}: MAE (rad) trial before / of the event / 1 after / 2 after",
                         "returns to the path" if name == "SNN" else "figure only",
                         " / ".join(f"{v:.3f}" for v in m["mae_trials"])])
    return rows, notes, _interaction_checks(measured)


def _interaction_checks(measured: dict[str, list[dict]]) -> list[Check]:
    checks = []
    pd = {m["kind"]: m for m in measured.get("PD", [])}
    for m in measured.get("SNN", []):
        what = m["kind"].replace("_", " ")
        if m["kind"] in pd:
            ours, theirs = m["mm_per_N"], pd[m["kind"]]["mm_per_N"]
            checks.append(Check(f"{what}: the SNN arm yields more per newton than PD", ours > theirs,
                                f"{ours:.1f} vs {theirs:.1f} mm/N"))
        mae = m["mae_trials"]
        if len(mae) >= 4:
            checks.append(Check(f"{what}: the SNN returns to its path (MAE 2 trials after within {RETURNED}× the "
                                "trial before)", mae[3] <= RETURNED * mae[0], f"{mae[0]:.3f} → {mae[3]:.3f} rad"))
    return checks


@figure("fig2_10", "Adaptation to a payload and an elastic band; human interaction (Fig. 2.10)",
        studies=("fig2_10_adaptation", "interaction_snn", "interaction_baselines"))
def fig2_10(runs: RunSet, stem: Path) -> Figure:
    """MAE per trial of the snn run with plant events, its phases shaded, and the interaction rows."""
    run = runs.where(lambda r: _has_events(r, CONDITIONS) and r.trials > 0, controller="snn").best()
    if run is None:
        raise MissingRuns("no snn run with plant events (study fig2_10_adaptation)")
    events, mae, period = run_events(run), run.mae, run.period_s
    parts = phases(events, len(mae))
    fig, ax = plt.subplots(figsize=(9, 4.2))
    shade = {"payload": "C1", "elastic band": "C2"}
    for cond, color in shade.items():
        on = None
        for x, kind in events:
            c, is_on = CONDITIONS.get(kind, (None, None))
            if c == cond and is_on and on is None:
                on = x
            elif c == cond and not is_on and on is not None:
                ax.axvspan(on - 0.5, x - 0.5, color=color, alpha=0.18, lw=0, label=f"{cond} on")
                on = None
        if on is not None:
            ax.axvspan(on - 0.5, len(mae) - 0.5, color=color, alpha=0.18, lw=0, label=f"{cond} on")
    for x, kind in events:
        ax.axvline(x - 0.5, color="0.4", ls=":", lw=0.8)
        ax.annotate(kind.replace("_", " "), (x - 0.5, 1.0), xycoords=("data", "axes fraction"), rotation=90,
                    fontsize=7, va="top", ha="right", color="0.3")
    ax.plot(np.arange(len(mae)), mae, "k.-", lw=1, ms=4, label="MAE per trial")
    for i, (a, b, _) in enumerate(parts):
        ax.hlines(mae[a:b].mean(), a - 0.5, b - 0.5, color="C3", lw=2, label="phase mean" if i == 0 else None)
    ax.set_xlabel("trial")
    ax.set_ylabel("position MAE (rad)")
    ax.secondary_xaxis("top", functions=(lambda x: x * period, lambda s: s / period)).set_xlabel("time (s)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    files = [save(fig, stem)]
    claim = "figure only (MAE rises with the disturbance, then recovers: the cerebellum adapts)"
    table = [["quantity", "paper", "cerebx"]]
    for a, b, name in parts:
        seg = mae[a:b]
        k = max(1, min(3, len(seg) // 3))
        table.append([f"MAE (rad), {trial_range(a, b)}: {name}", claim, mean_std(seg)])
        if name != "before" and len(seg) >= 2:
            table.append([f"{name}: MAE first {k} → last {k} trials (rad)", "figure only",
                          f"{seg[:k].mean():.3f} → {seg[-k:].mean():.3f}"])
        claim = "figure only"
    notes = [] if events else ["the run's events were neither logged nor configured"]
    rows, more, checks = _interaction_rows(runs)
    table += rows
    notes += more
    for a, b, name in parts:
        seg, k = mae[a:b], max(1, min(3, (b - a) // 3))
        if name != "before" and not name.startswith("after") and len(seg) >= 2:
            checks.insert(0, Check(f"adapts to the {name}: MAE of its last {k} trials below its first {k}",
                                   bool(seg[-k:].mean() < seg[:k].mean()),
                                   f"{seg[:k].mean():.3f} → {seg[-k:].mean():.3f} rad"))
    snn_inter = dict(_interaction_runs(runs))["SNN"]
    conv = learnt(runs, [("circle, SNN", r, LEARN_STUDY["circle"]) for r in (run, snn_inter)],
                  lambda q: not q.startswith(("PD,", "factory position,")))
    origin = short_path(run.learned_from) if run.learned_from else "scratch"
    caption = (f"Thesis Fig. 2.10: the snn controller, learnt state from {origin}, performing "
               f"the {TASK_NAMES.get(run.task, run.task)} while the plant is disturbed (run {short_path(run)}, "
               f"{len(mae)} trials of {period:.0f} s). Shaded: payload / elastic band attached; dotted: events "
               f"({', '.join(f'{k} at trial {x:g}' for x, k in events)}); red: mean MAE of each phase. "
               "Human interaction (iii), in the table: a one-finger push and a grab through a soft spring on the "
               "learned circle (studies interaction_snn / interaction_baselines; constructed forces) for the SNN, "
               "PD and the factory stand-in.")
    return Figure(files, caption, table, notes, checks, conv)
