"""Thesis chapter 2 figures (2.6, 2.7, 2.9, 2.10) and the trajectory figures of chapter 3 (3.3, 3.5).

Runs are chosen by content:

- learning from scratch: snn controller, no delay, no ``init_from``, no plant events, one PF-PC kernel
  peaking at 150 ms (the thesis kernel; this keeps the multikernel and kernel-sweep runs out);
- the factory position controller: ``Run.is_factory_position``;
- the PD baseline: controller preset ``pd`` (the launch gains), no delay.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from cerebx.report.plot import mean_std, panel_letter, save  # noqa: E402
from cerebx.report.registry import Figure, MissingRuns, figure  # noqa: E402
from cerebx.report.runs import Run, RunSet  # noqa: E402
from cerebx_thesis.report import stages  # noqa: E402

THESIS_KERNEL_MS = 150.0  # chapter 3 ([D]) kernel peak
CH2_KERNEL_MS = 100.0  # chapter 2 ([B]) kernel peak
# Tables 2.3 / 2.4: thesis run length, snn windows (start, stop, mean, std), factory position MAE as printed
PAPER_STAGES: dict[str, tuple[int, list[tuple[int, int, float, float]], str]] = {
    "circle": (500, [(0, 100, 0.115, 0.055), (100, 200, 0.036, 0.013), (400, 500, 0.019, 0.003)], "0.077 ± 0.0004"),
    "eight": (500, [(0, 100, 0.111, 0.034), (100, 200, 0.046, 0.013), (400, 500, 0.017, 0.003)], "0.063 ± 0.0003"),
    "reaching": (1000, [(0, 100, 0.155, 0.050), (300, 400, 0.043, 0.024), (900, 1000, 0.019, 0.006)],
                 "0.026 ± 0.006"),
}
# Fig. 2.9: stages at t1 = 160 s, t2 = 600 s, t3 = 2000 s of 1000 trials; density of the last 80 trials
REACH_STAGES = (0.08, 0.3, 1.0)
REACH_DENSITY = 0.08
TASK_NAMES = {"circle": "horizontal circle", "inclined_circle": "inclined circle",
              "circle_eight": "circle-Lissajous sequence", "eight": "eight", "reaching": "reaching"}


# ---- run selection ---------------------------------------------------------------------------------
def from_scratch(runs: RunSet, task: str, kernel_ms: float = THESIS_KERNEL_MS) -> Run | None:
    """The longest snn run learning ``task`` from scratch without delay, with the kernel peaking at
    ``kernel_ms`` (the chapter's network)."""
    return runs.where(lambda r: r.learned_from is None and not r.events and r.trials > 0
                      and r.kernel_peaks_ms == [kernel_ms],
                      task=task, controller="snn", delay="none").best()


def baselines(runs: RunSet, task: str) -> list[tuple[str, Run]]:
    """(label, run) of the PD and factory-position baselines on ``task`` without delay, those present."""
    none = runs.where(lambda r: r.trials > 0 and not r.events, task=task, delay="none")
    found = [("PD", none.where(controller="pd", controller_preset="pd").best()),
             ("factory position", none.where(lambda r: r.is_factory_position).best())]
    return [(name, r) for name, r in found if r is not None]


def _rel(r: Run | str) -> str:
    d = Path(r) if isinstance(r, str) else r.dir
    return f"{d.parent.name}/{d.name}"


def _trials(a: int, b: int) -> str:
    """Trials [a, b) as text."""
    return f"trial {a}" if b - a == 1 else f"trials {a}–{b - 1}"


# ---- Tables 2.3 / 2.4 ------------------------------------------------------------------------------
def scaled_windows(n: int, total: int, windows: list[tuple[int, int, float, float]]) -> list[tuple[int, int]]:
    """The thesis trial windows, scaled by n / total for runs shorter than the thesis's (at least 1 trial)."""
    f = min(1.0, n / total)
    out = []
    for a, b, _, _ in windows:
        lo = min(int(round(a * f)), n - 1)
        out.append((lo, max(lo + 1, int(round(b * f)))))
    return out


def stage_table(run: Run, task: str, base: list[tuple[str, Run]]) -> tuple[list[list[str]], list[tuple[int, int]]]:
    """Rows of Table 2.3 / 2.4 for ``task`` beside ours, and the windows used."""
    total, ref, factory = PAPER_STAGES[task]
    wins = scaled_windows(run.trials, total, ref)
    rows = [["quantity", "paper", "cerebx"]]
    for (a, b, m, s), (lo, hi) in zip(ref, wins, strict=True):
        ours = f"trials {lo}–{hi}" if hi - lo > 1 else f"trial {lo}"
        used = "" if (lo, hi) == (a, b) else f" [cerebx: {ours} of {run.trials}]"
        rows.append([f"SNN MAE (rad), trials {a}–{b}{used}", f"{m:.3f} ± {s:.3f}", mean_std(run.mae[lo:hi])])
    for name, b in base:
        paper = factory if name == "factory position" else "not in the thesis table"
        nd = 4 if name == "factory position" else 3
        rows.append([f"{name} MAE (rad), all trials [cerebx: {b.n_measured} trials]", paper, mean_std(b.mae, nd)])
    if not any(name == "factory position" for name, _ in base):
        rows.append(["factory position MAE (rad), all trials", factory, "not run"])
    return rows, wins


def _baseline_text(base: list[tuple[str, Run]]) -> str:
    if not base:
        return "no baseline run"
    return "dashed: mean MAE of " + ", ".join(f"{name} ({b.n_measured} trials, {_rel(b)})" for name, b in base)


def _trajectory_learning(runs: RunSet, stem: Path, task: str, fig_no: str, study: str) -> Figure:
    run = from_scratch(runs, task, CH2_KERNEL_MS)
    if run is None:
        raise MissingRuns(f"no {task} run of snn learning from scratch (study {study})")
    base = baselines(runs, task)
    table, wins = stage_table(run, task, base)
    files = [stages.stages_figure(run.dir, run.summary, stem.with_name(stem.name + "_stages")),
             stages.mae_per_joint_figure(run.summary, [b.summary for _, b in base],
                                         stem.with_name(stem.name + "_mae"),
                                         labels=[name for name, _ in base], windows=wins)]
    ks = stages.stage_trials(run.trials)
    notes = [] if base else [f"no {task} baseline runs (pd / position_factory without delay): MAE figure without "
                             "baselines"]
    total = PAPER_STAGES[task][0]
    caption = (f"Thesis Fig. {fig_no} ({TASK_NAMES[task]}): the snn controller learning from scratch, run "
               f"{_rel(run)} with {run.n_measured} trials of {run.period_s:.0f} s (thesis: {total}). "
               f"Stage figure (a–f): trials {', '.join(map(str, ks))} (thesis: 18–20 s, 318–320 s, 998–1000 s, "
               "scaled by fraction of the run); end-effector density of the previous 10 trials. "
               "MAE figure (g): MAE per trial of each joint and their mean; shaded: the table windows "
               f"({', '.join(f'{a}–{b}' for a, b in wins)}); {_baseline_text(base)}.")
    return Figure(files, caption, table, notes)


@figure("fig2_6", "Circle learnt from scratch: stages and MAE per joint (Fig. 2.6, Table 2.3)",
        studies=("learn_circle", "baselines_circle"))
def fig2_6(runs: RunSet, stem: Path) -> Figure:
    return _trajectory_learning(runs, stem, "circle", "2.6", "learn_circle")


@figure("fig2_7", "Eight learnt from scratch: stages and MAE per joint (Fig. 2.7, Table 2.3)",
        studies=("learn_eight", "baselines_eight"))
def fig2_7(runs: RunSet, stem: Path) -> Figure:
    return _trajectory_learning(runs, stem, "eight", "2.7", "learn_eight")


@figure("table2_3", "Tables 2.3 / 2.4: MAE per learning stage beside the thesis",
        studies=("learn_circle", "learn_eight", "learn_reaching", "baselines_circle", "baselines_eight",
                 "baselines_reaching"))
def table2_3(runs: RunSet, stem: Path) -> Figure:
    """The thesis's stage windows (mean ± std) beside ours for every task learnt from scratch, as bars."""
    found = {task: from_scratch(runs, task, CH2_KERNEL_MS) for task in PAPER_STAGES}
    found = {t: r for t, r in found.items() if r is not None}
    if not found:
        raise MissingRuns("no run of snn learning circle, eight or reaching from scratch (studies learn_circle, "
                          "learn_eight, learn_reaching)")
    fig, axes = plt.subplots(1, len(found), figsize=(4.6 * len(found), 3.8), squeeze=False)
    table = [["quantity", "paper", "cerebx"]]
    for ax, (task, run) in zip(axes[0], found.items(), strict=True):
        total, ref, factory = PAPER_STAGES[task]
        base = baselines(runs, task)
        rows, wins = stage_table(run, task, base)
        table += [[f"{task}: {q}", p, c] for q, p, c in rows[1:]]
        x = np.arange(len(ref))
        ours = [run.mae[lo:hi] for lo, hi in wins]
        ax.bar(x - 0.2, [m for *_, m, _ in ref], 0.4, yerr=[sd for *_, sd in ref], capsize=3, color="0.6",
               label=f"thesis ({total} trials)")
        ax.bar(x + 0.2, [o.mean() for o in ours], 0.4, yerr=[o.std() for o in ours], capsize=3, color="C0",
               label=f"cerebx ({run.n_measured} trials)")
        ax.axhline(float(factory.split()[0]), color="0.4", ls="--", lw=1, label="factory position, thesis")
        for name, b in base:
            if name == "factory position":
                ax.axhline(b.mae.mean(), color="C2", ls="--", lw=1.2, label="factory position, cerebx")
        ax.set_xticks(x, [f"{a}–{b}\n[{lo}–{hi}]" if (lo, hi) != (a, b) else f"{a}–{b}"
                          for (a, b, *_), (lo, hi) in zip(ref, wins, strict=True)], fontsize=8)
        ax.set_xlabel("trials (thesis) [cerebx window]")
        ax.set_ylabel("position MAE (rad)")
        ax.set_title(TASK_NAMES[task])
        ax.grid(alpha=0.3, axis="y")
        ax.legend(fontsize=7)
    fig.suptitle("Thesis Tables 2.3 / 2.4 beside cerebx: MAE (mean ± std) per learning stage")
    fig.tight_layout()
    caption = ("Thesis Tables 2.3 (circle, eight) and 2.4 (reaching): the cerebellar controller's position MAE "
               "(mean ± std over the trials of each window) at the initial, intermediate and final stage of "
               "learning from scratch, beside the factory position controller. Runs shorter than the thesis's "
               "use the same fractions of their length (the window in brackets). Runs: "
               + ", ".join(f"{t} {_rel(r)}" for t, r in found.items()) + ".")
    notes = [f"{t}: no run learning from scratch" for t in PAPER_STAGES if t not in found]
    return Figure([save(fig, stem)], caption, table, notes)


# ---- Fig. 2.9: reaching ----------------------------------------------------------------------------
def reach_target(ee_des: np.ndarray, n_targets: int) -> int:
    """Target index from the direction of ee_des at its farthest point from the first sample
    (targets at angles pi + 2 pi k / n in the xy plane, as the reaching task lays them out)."""
    d = ee_des[:, :2] - ee_des[0, :2]
    far = d[int(np.argmax(np.hypot(d[:, 0], d[:, 1])))]
    step = 2 * np.pi / n_targets
    return int(round((np.arctan2(far[1], far[0]) - np.pi) / step)) % n_targets


def _label_target(label: str | None) -> int | None:
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
    if len(tr["t"]) < 2:
        return np.zeros(len(tr["t"]))
    return np.linalg.norm(np.gradient(tr[key], tr["t"], axis=0), axis=1)


@figure("fig2_9", "Reaching learnt from scratch: paths, speed profiles and MAE (Fig. 2.9, Table 2.4)",
        studies=("learn_reaching", "baselines_reaching"))
def fig2_9(runs: RunSet, stem: Path) -> Figure:
    run = from_scratch(runs, "reaching", CH2_KERNEL_MS)
    if run is None:
        raise MissingRuns("no reaching run of snn learning from scratch (study learn_reaching)")
    n, n_targets = run.trials, int(run.get("task.targets", 8))
    base = baselines(runs, "reaching")
    table, wins = stage_table(run, "reaching", base)
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
        ax.set_title(f"before t = {t_end:.0f} s (trial {e}); density: {_trials(max(0, e - width), e)}",
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
    caption = (f"Thesis Fig. 2.9 (reaching, {n_targets} targets): run {_rel(run)}, {n} trials of "
               f"{run.period_s:.0f} s (thesis: 1000). (a–c) end-effector paths in the xy plane: the last trial of "
               f"each target before trials {', '.join(map(str, ends))} (thesis t1 = 160 s, t2 = 600 s, t3 = 2000 s, "
               f"scaled by fraction of the run), over the density of the last {width} trials (thesis: 80). "
               f"(d–f) speed profile of the starred target at those stages. (g) MAE per trial of each joint and "
               f"their mean; {_baseline_text(base)}. Targets from /trial_metrics labels, else from the direction "
               "of the farthest desired point.")
    return Figure(files, caption, table, notes)


# ---- Fig. 2.10: unstructured environment ---------------------------------------------------------
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


def _has_events(run: Run, kinds: tuple[str, ...] | dict) -> bool:
    return any(e.get("action", {}).get("kind") in kinds for e in run.events)


def interaction_metrics(run: Run) -> list[dict[str, float | str]]:
    """Per human-interaction event of ``run`` (thesis §2.3.1): the peak interaction force on the hand
    (N: the push's configured peak; the grab spring's k |anchor - hand|, from the logged hand path and
    the event's anchor path), the peak displacement of the hand from where it was at the same phase
    of the trial before the event, during the event and 1 s after (mm), their ratio (mm/N), and that
    displacement averaged over the last 0.5 s of the trial after the event trial (mm), and the position
    MAE (rad) of the trial before the event, the event's trial and the two after (back on the path?)."""
    from cerebx.plants.baxter import grab_anchor, half_sine

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


def _interaction_rows(runs: RunSet) -> tuple[list[list[str]], list[str]]:
    rows, notes = [], []
    inter = runs.where(lambda r: _has_events(r, INTERACTIONS) and r.trials > 0, delay="none")
    found = [("SNN", inter.where(controller="snn").best()),
             ("PD", inter.where(controller="pd", controller_preset="pd").best()),
             ("factory position", inter.where(lambda r: r.is_factory_position).best())]
    for name, run in found:
        if run is None:
            notes.append(f"no {name} run with human-interaction events (studies interaction_*)")
            continue
        for m in interaction_metrics(run):
            what = "finger push" if m["kind"] == "finger_push" else "grab (soft spring)"
            claim = ("yields to a very low force, returns to the path" if name == "SNN"
                     else "figure only")
            rows.append([f"{name}, {what}: peak force (N) / peak hand displacement (mm) / mm per N",
                         claim, f"{m['force_N']:.2f} / {m['displacement_mm']:.1f} / {m['mm_per_N']:.2f}"])
            rows.append([f"{name}, {what}: MAE (rad) trial before / of the event / 1 after / 2 after",
                         "returns to the path" if name == "SNN" else "figure only",
                         " / ".join(f"{v:.3f}" for v in m["mae_trials"])])
    return rows, notes


@figure("fig2_10", "Adaptation to a payload and an elastic band; human interaction (Fig. 2.10)",
        studies=("fig2_10_adaptation", "interaction_snn", "interaction_baselines"))
def fig2_10(runs: RunSet, stem: Path) -> Figure:
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
        table.append([f"MAE (rad), {_trials(a, b)}: {name}", claim, mean_std(seg)])
        if name != "before" and len(seg) >= 2:
            table.append([f"{name}: MAE first {k} → last {k} trials (rad)", "figure only",
                          f"{seg[:k].mean():.3f} → {seg[-k:].mean():.3f}"])
        claim = "figure only"
    notes = [] if events else ["the run's events were neither logged nor configured"]
    rows, more = _interaction_rows(runs)
    table += rows
    notes += more
    origin = _rel(run.learned_from) if run.learned_from else "scratch"
    caption = (f"Thesis Fig. 2.10: the snn controller, learnt state from {origin}, performing "
               f"the {TASK_NAMES.get(run.task, run.task)} while the plant is disturbed (run {_rel(run)}, {len(mae)} "
               f"trials of {period:.0f} s). Shaded: payload / elastic band attached; dotted: events "
               f"({', '.join(f'{k} at trial {x:g}' for x, k in events)}); red: mean MAE of each phase. "
               "Human interaction (iii), in the table: a one-finger push and a grab through a soft spring on the "
               "learned circle (studies interaction_snn / interaction_baselines; constructed forces) for the SNN, "
               "PD and the factory stand-in.")
    return Figure(files, caption, table, notes)
