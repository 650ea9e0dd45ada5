"""The one-screen summary printed at the end of a run and by ``cerebx inspect``."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

from cerebx.metrics import final_mae, window_stats


def format_summary(s: dict[str, Any], run_dir: Path | None = None) -> str:
    lines = []
    if run_dir is not None:
        lines.append(f"run       {run_dir}")
    lines.append(f"status    {s['status']}" + (f"  ({s['error']})" if s.get("error") else ""))
    chosen = {**{k: s[k] for k in ("controller", "plant", "delay")}, **(s.get("presets") or {})}  # delay=gamma45
    network = f" network={s['network']}" if s.get("network") else ""
    lines.append(f"setup     task={s['task']} controller={chosen['controller']} plant={chosen['plant']} "
                 f"delay={chosen['delay']}{network} seed={s['seed']}")
    mae = s.get("mae_per_trial") or []
    lines.append(f"trials    {s.get('trials_completed', len(mae))}/{s['trials']}")
    if mae:
        # a summary edited by hand may lack final_mae: it is the mean of the last 10 % of the trials listed
        final = s.get("final_mae")
        final = final_mae(mae) if final is None else final
        lines.append(f"MAE       first {mae[0]:.4f} rad   final {final:.4f} rad (mean of last 10 %)")
        n = len(mae)
        cuts = sorted({0, n // 5, n // 2, n})
        parts = []
        for a, b in zip(cuts, cuts[1:]):
            st = window_stats(mae, a, b)
            if st:
                parts.append(f"[{a}-{b}) {st[0]:.4f}±{st[1]:.4f}")
        lines.append("windows   " + "   ".join(parts))
        pj = (s.get("mae_per_joint_per_trial") or [[]])[-1]
        if pj:
            lines.append("per joint " + " ".join(f"{v:.4f}" for v in pj) + "  (last trial)")
    rt = s.get("rt_factor")
    lines.append(f"time      {s['sim_seconds']:.1f} s simulated in {s['wall_seconds']:.1f} s wall"
                 + (f"  ({rt:.1f}x real time)" if rt else ""))
    return "\n".join(lines)


def print_summary(s: dict[str, Any], run_dir: Path | None = None) -> None:
    print(format_summary(s, run_dir), file=sys.stderr if s["status"] == "failed" else sys.stdout)
