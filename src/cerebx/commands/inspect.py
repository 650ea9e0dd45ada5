"""``cerebx inspect``: a run's summary and its MCAP channels; a bad summary or log is one line each, the
other still shown."""

from __future__ import annotations

import json
from pathlib import Path

from cerebx import runfiles
from cerebx.commands.common import Parser, fail
from cerebx.errors import CerebxError
from cerebx.recording.console import format_summary
from cerebx.recording.reader import channel_counts, has_summary, read_metadata, read_summary
from cerebx.recording.segments import segments
from cerebx.schema.window import TrialWindow


def parser() -> Parser:
    """The command's one argument: a run folder or an MCAP file."""
    ap = Parser("cerebx inspect", "a run's summary and its MCAP channels")
    ap.add_argument("path", help="a run folder (RUN_DIR) or one of its .mcap files")
    return ap


def recorded_steps(path: Path) -> str | None:
    """Which control steps the log holds (``recording.trials``, ``decimation``, ``joint_states``), from its
    recorded config; None when that cannot be read."""
    try:
        cfg = json.loads(read_metadata(path)["config"]["json"])
        rec = cfg.get("recording") or {}
        value = rec.get("trials")
        window = None if value in (None, "all") else TrialWindow.model_validate({} if value == "none" else value)
    except (CerebxError, KeyError, OSError, ValueError, TypeError):
        return None
    n = int(cfg.get("trials") or 0)
    held = f"every trial ({n})" if window is None else f"trials {window.describe(n)}"
    out = f"control steps recorded (recording.trials): {held}"
    if int(rec.get("decimation") or 1) > 1:
        out += f"; every {rec['decimation']}th step"
    if rec.get("joint_states") is False:
        out += "; no joint states"
    return out


def main(args: list[str]) -> int:
    p = Path(parser().parse_args(args).path)
    if not p.exists():
        return fail([f"{p}: no such file or folder"])
    run_dir = p if p.is_dir() else p.parent
    problems: list[str] = []
    if (run_dir / runfiles.SUMMARY).exists() or p.is_dir():
        try:
            print(format_summary(read_summary(run_dir), run_dir))
        except CerebxError as err:
            problems.append(str(err))
    log = p
    try:
        files = [s.path for s in segments(p)] if p.is_dir() else [p]
        log = files[-1]
        counts = channel_counts(p)
        width = max(map(len, counts), default=10)
        closed = all(has_summary(f) for f in files)
        print("\n" + " + ".join(str(f) for f in files)
              + ("" if closed else "  (no summary section: counted by scanning up to the last "
                                   "complete record; the run was killed or is still going)"))
        for topic, n in counts.items():
            print(f"  {topic:<{width}}  {n:>9,}")
        steps = recorded_steps(p)
        if steps:
            print(steps)
        robot = run_dir / "robot"
        if p.is_dir() and (robot / runfiles.MCAP).exists():  # the robot side of a wall-clock run
            log = robot / runfiles.MCAP
            counts = channel_counts(robot)
            width = max(map(len, counts), default=10)
            print(f"\n{log}  (robot side: {read_summary(robot)['status']})")
            for topic, n in counts.items():
                print(f"  {topic:<{width}}  {n:>9,}")
    except (CerebxError, OSError) as err:
        problems.append(str(err) if isinstance(err, CerebxError) else f"{log}: {err.strerror}")
    return fail(problems) if problems else 0
