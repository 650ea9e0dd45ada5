"""Chapter 4, Baxter driven by Ekeberg antagonist muscles (thesis §4.5-4.7): Fig. 4.6, drawn from run logs.

A: position MAE of the SNN with the muscles in the loop, per cocontraction multiplier k, over the
measured trials of the runs evaluated from a learned state. B: the end-effector's vertical sag when
a payload is attached to the arm held only by the muscles' passive component (M_ag = M_at = 0).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from cerebx.report.plot import fmt, mean_std, panel_letter, save  # noqa: E402
from cerebx.report.registry import Check, Figure, MissingRuns, figure  # noqa: E402
from cerebx.report.runs import Run, RunSet  # noqa: E402
from cerebx.schema.muscles import EkebergConfig  # noqa: E402
from cerebx_thesis.report.common import learnt  # noqa: E402

# thesis §4.7 (Fig. 4.6): k -> position MAE (mean, std; rad) and payload sag (cm)
THESIS_MAE = {0: (0.0189, 0.0042), 1: (0.0191, 0.0034), 5: (0.0179, 0.0051), 9: (0.0189, 0.0052),
              10: (0.0240, 0.0052), 12: (0.0508, 0.0075)}
THESIS_SAG_CM = {0: 9.9, 1: 9.6, 5: 5.8, 9: 4.7, 10: 4.4, 12: 3.9}
SETTLED_S = 1.0  # the sag is measured over the run's last second
LEARN_STUDY = "fig4_6a_learn"  # each profile learns from scratch (its full profile: where A's shape appears)
FLAT_UP_TO = 9.0  # A: flat up to this cocontraction, clearly worse at the highest


def _table_4_1(r: Run) -> bool:
    """An Ekeberg run with the Table 4.1 muscle (only the cocontraction multiplier may differ)."""
    m = r.get("muscle") or {}
    if m.get("kind") != "ekeberg":
        return False
    default = EkebergConfig().model_dump(exclude={"cocontraction"})
    return all(list(m.get(k, [])) == list(v) if isinstance(v, tuple) else m.get(k) == v for k, v in default.items())


def _k(r: Run) -> float | None:
    """The run's cocontraction multiplier, None if it has no muscle."""
    k = r.get("muscle.cocontraction")
    return None if k is None else float(k)


def payload_sag_cm(r: Run) -> float | None:
    """End-effector z just before the payload is attached minus its mean z over the run's last second (cm)."""
    at = [e["at_s"] for e in r.events if (e.get("action") or {}).get("kind") == "attach_payload" and e.get("at_s")]
    if not at:
        return None
    c = r.control(["ee"])
    if c["t"].size == 0:
        return None
    t, z = c["t"], c["ee"][:, 2]
    before, settled = z[t < at[0]], z[t >= t[-1] - SETTLED_S]
    if before.size == 0 or settled.size == 0:
        return None
    return float(100.0 * (before[-1] - settled.mean()))


BORROWED = {"controller.error.kpos": "error gains kpos", "controller.error.kvel": "kvel",
            "controller.decoder.spikes_full_scale": "M's full scale (DCN spikes per 2 ms step)"}


def _borrowed(runs: list[Run]) -> str:
    """The values the thesis does not give for chapter 4, as the evaluated runs have them (their sources:
    conf/experiment/fig4_6a_learn.yaml)."""
    shown = []
    for key, label in BORROWED.items():
        values = {str(r.get(key)) for r in runs}
        shown.append(f"{label} {values.pop() if len(values) == 1 else 'differing between runs'}")
    return f"Borrowed (see the preset fig4_6a_learn): {', '.join(shown)}. " if runs else ""


@figure("fig4_6", "Baxter with Ekeberg muscles: MAE and payload sag per cocontraction",
        studies=("fig4_6a", "fig4_6b"))
def fig4_6(runs: RunSet, stem: Path) -> Figure:
    """A: MAE per cocontraction from a learned state; B: payload sag per cocontraction at rest."""
    muscles = runs.where(lambda r: r.completed and _table_4_1(r))
    eight = muscles.where(lambda r: r.controller == "snn" and r.task == "eight")
    learned = eight.where(lambda r: r.learned_from is not None and not r.events and r.n_measured > 0).by(_k)
    learn_trials = sorted({r.trials for r in eight.where(lambda r: r.learned_from is None).by(_k).values()})
    rest = muscles.where(lambda r: r.controller == "muscle_rest" and bool(r.events)).by(_k)
    if not learned and not rest:
        raise MissingRuns("no Ekeberg-muscle runs of the eight from a learned state or with a payload at rest "
                          "(studies fig4_6a, fig4_6b)")
    notes = []
    if not learned:
        notes.append("panel A: no SNN runs of the eight from a learned state with the muscles (study fig4_6a)")
    if not rest:
        notes.append("panel B: no muscle_rest runs with a payload (study fig4_6b)")
    sag = {k: payload_sag_cm(r) for k, r in rest.items()}

    fig, (ax_a, ax_b) = plt.subplots(1, 2, figsize=(12, 4.6))
    ks = sorted(THESIS_MAE)
    ax_a.errorbar(ks, [THESIS_MAE[k][0] for k in ks], [THESIS_MAE[k][1] for k in ks], marker="s", capsize=3,
                  color="0.5", ls="--", label="thesis")
    if learned:
        x = np.array(list(learned))
        stats = np.array([(r.mae.mean(), r.mae.std()) for r in learned.values()])
        ax_a.errorbar(x, stats[:, 0], stats[:, 1], marker="o", capsize=3, color="C0",
                      label=f"cerebx ({min(r.n_measured for r in learned.values())}+ trials each)")
    ax_a.set_xlabel("cocontraction c (multiple of [1.5, 1.5, 1.5, 1.5, 0.5, 0.5])")
    ax_a.set_ylabel("position MAE (rad), mean ± std over trials")
    ax_b.plot(ks, [THESIS_SAG_CM[k] for k in ks], "s--", color="0.5", label="thesis")
    got = {k: v for k, v in sag.items() if v is not None}
    if got:
        ax_b.plot(list(got), list(got.values()), "o-", color="C1", label="cerebx")
    ax_b.set_xlabel("cocontraction c (multiple of the x1 baseline)")
    ax_b.set_ylabel("end-effector sag Δz with 2 kg (cm)")
    for letter, ax in (("A", ax_a), ("B", ax_b)):
        panel_letter(ax, letter)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    fig.tight_layout()
    png = save(fig, stem)

    table = [["quantity", "paper", "cerebx"]]
    checks = _shape_a(learned)
    for k in ks:
        r = learned.get(float(k))
        table.append([f"A: position MAE at c = x{k} (rad)", f"{THESIS_MAE[k][0]:.4f} ± {THESIS_MAE[k][1]:.4f}",
                      "–" if r is None else f"{mean_std(r.mae, 4)} ({r.n_measured} trials)"])
    if learned:
        m = {k: r.mae.mean() for k, r in learned.items()}
        flat = [v for k, v in m.items() if k <= 9]
        table.append(["A: spread of the mean MAE up to x9 (max / min)", f"{0.0191 / 0.0179:.2f}",
                      fmt(max(flat) / min(flat), 2) if flat else "–"])
        if 12.0 in m and flat:
            paper = THESIS_MAE[12][0] / np.mean([THESIS_MAE[k][0] for k in (0, 1, 5, 9)])
            table.append(["A: MAE at x12 / mean MAE up to x9", f"{paper:.2f}", fmt(m[12.0] / float(np.mean(flat)), 2)])
    for k in ks:
        v = sag.get(float(k))
        table.append([f"B: sag Δz with 2 kg at c = x{k} (cm)", f"{THESIS_SAG_CM[k]:.1f}", fmt(v, 1)])
    if len(got) > 1:
        vals = [got[k] for k in sorted(got)]
        falls = all(a > b for a, b in zip(vals, vals[1:]))
        table.append(["B: sag falls monotonically with c", "yes", "yes" if falls else "no"])
        checks.append(Check("B: sag falls monotonically with c", falls,
                            " → ".join(f"x{k:g} {v:.1f}" for k, v in sorted(got.items())) + " cm"))
    caption = ("Fig. 4.6. (A) Position MAE of the cerebellar SNN driving one Ekeberg muscle pair per joint "
               "(Eq. 4.6, Table 4.1) on the eight-like trajectory, each cocontraction profile learnt from scratch "
               "and then evaluated from its learned state"
               + (f" (learning: {', '.join(map(str, learn_trials))} trials per profile, constructed: the thesis "
                  "gives no count)" if learn_trials else "")
               + ". " + _borrowed(list(learned.values())) + "(B) Vertical sag of the end-effector when a 2 kg "
               "payload is attached at the resting pose with no active muscle component (M_ag = M_at = 0), measured "
               f"against the last {SETTLED_S:g} s of the run. The arm's own weight is compensated (plant "
               "baxter_muscles, constructed); the payload is not.")
    conv = learnt(runs, [(f"x{k:g}", r, LEARN_STUDY) for k, r in learned.items()], lambda q: q.startswith("A:"))
    return Figure([png], caption, table, notes, checks, conv if learned else None)


def _shape_a(learned: dict[float, Run]) -> list[Check]:
    """Fig. 4.6 A's shape: the MAE flat up to x9 (the spread of its means smaller than the step up to the highest
    cocontraction), and the highest cocontraction the worst."""
    m = {k: float(r.mae.mean()) for k, r in learned.items()}
    flat = {k: v for k, v in m.items() if k <= FLAT_UP_TO}
    top = max(m, default=None)
    if top is None or top <= FLAT_UP_TO or len(flat) < 2:
        return []
    spread, step = max(flat.values()) - min(flat.values()), m[top] - max(flat.values())
    return [Check(f"A: MAE flat up to x{FLAT_UP_TO:g} (spread of the means below the step to x{top:g})", spread < step,
                  f"spread {spread:.4f}, step {step:.4f} rad"),
            Check(f"A: x{top:g} the least accurate", all(v < m[top] for k, v in m.items() if k != top),
                  ", ".join(f"x{k:g} {v:.4f}" for k, v in sorted(m.items())))]
