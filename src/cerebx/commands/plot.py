"""``cerebx plot``: a run's learning curve (mean absolute joint error per trial) and its per-joint errors, drawn
from ``summary.json`` into one PNG (by default ``RUN_DIR/learning_curve.png``)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

from cerebx.commands.common import Parser  # noqa: E402
from cerebx.errors import CerebxError  # noqa: E402
from cerebx.recording.summary import read_summary  # noqa: E402

DEFAULT_NAME = "learning_curve.png"


def parser() -> Parser:
    """The command's arguments: a run folder and where the figure goes."""
    ap = Parser("cerebx plot", "a run's learning curve (MAE per trial) and per-joint errors, as a PNG")
    ap.add_argument("run_dir", help="a run folder (holding summary.json)")
    ap.add_argument("--out", help=f"the image file (default: RUN_DIR/{DEFAULT_NAME})")
    return ap


def main(args: list[str]) -> int:
    ns = parser().parse_args(args)
    run_dir = Path(ns.run_dir)
    if not run_dir.is_dir():
        raise CerebxError(f"{run_dir}: no such run folder")
    out = Path(ns.out) if ns.out else run_dir / DEFAULT_NAME
    print(draw(read_summary(run_dir), run_dir, out))
    return 0


def draw(summary: dict[str, Any], run_dir: Path, out: Path) -> Path:
    """Draw the two panels of ``summary`` (of the run in ``run_dir``) into ``out``; returns ``out``."""
    mae = summary.get("mae_per_trial") or []
    if not mae:
        raise CerebxError(f"{run_dir}: no completed trial to plot (status {summary.get('status')})")
    fig, (curve, joints) = plt.subplots(2, 1, figsize=(7, 6), sharex=True, layout="constrained")
    trials = range(1, len(mae) + 1)
    curve.plot(trials, mae, marker="o", ms=3, color="k")
    curve.set_ylabel("MAE (rad)")
    curve.set_title(f"{summary.get('task')} · {summary.get('controller')} · {summary.get('plant')} · "
                    f"delay {summary.get('delay')} · {summary.get('status')}", fontsize=10)
    per_joint = summary.get("mae_per_joint_per_trial") or []
    for j, values in enumerate(zip(*per_joint)):
        joints.plot(range(1, len(values) + 1), values, marker="o", ms=2, label=f"joint {j}")
    joints.set_ylabel("MAE per joint (rad)")
    joints.set_xlabel("trial")
    warmup = summary.get("warmup_trials") or 0
    for ax, values in ((curve, mae), (joints, [v for row in per_joint for v in row])):
        ax.grid(alpha=0.3)
        ax.set_ylim(0, 1.1 * max(values, default=0) or 1)  # from zero: the error's size, not only its changes
        ax.set_xlim(0.5, len(mae) + 0.5)
        ax.xaxis.set_major_locator(MaxNLocator(integer=True, min_n_ticks=1))
        if warmup:
            ax.axvspan(0.5, min(warmup, len(mae)) + 0.5, color="0.9", label="warm-up trials")
    if per_joint:
        joints.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1))
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(out, dpi=110)
    except (OSError, ValueError) as err:
        raise CerebxError(f"{out}: cannot be written ({getattr(err, 'strerror', None) or err})") from None
    finally:
        plt.close(fig)
    return out
