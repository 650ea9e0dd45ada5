"""The two logs of a wall-clock run read as one: the brain side's (``RUN_DIR/run.mcap``) and the robot
side's (``RUN_DIR/robot/run.mcap``), written with the same run id and the same tick times.

Messages come in time order; at equal times the brain side's first. The two ``/control`` messages of a
tick (the brain side's output and ``r2c_ms``; the robot side's error, supervisor torque, ``c2r_ms``...)
become one, as a simulated-time run records it.
"""

from __future__ import annotations

import heapq
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from cerebx import runfiles

ROBOT_DIR = runfiles.ROBOT
MERGED = "/control"


def robot_log(run_dir: Path) -> Path | None:
    """The robot side's log inside a brain-side run folder, if there is one."""
    p = Path(run_dir) / ROBOT_DIR / runfiles.MCAP
    return p if p.exists() else None


def merge(brain: Iterator[tuple[str, int, Any]], robot: Iterator[tuple[str, int, Any]]
          ) -> Iterator[tuple[str, int, Any]]:
    """Both sides' (topic, log time, message) streams, each in time order, as one stream."""
    tagged = heapq.merge(((t, 0, topic, msg) for topic, t, msg in brain),
                         ((t, 1, topic, msg) for topic, t, msg in robot), key=lambda r: (r[0], r[1]))
    held: tuple[int, int, Any] | None = None  # a /control waiting for the other side's of the same time
    for t, side, topic, msg in tagged:
        if held is not None and (t > held[0] or (topic == MERGED and side == held[1])):
            yield MERGED, held[0], held[2]
            held = None
        if topic != MERGED:
            yield topic, t, msg
        elif held is None:
            held = (t, side, msg)
        else:
            brain_msg, robot_msg = (held[2], msg) if held[1] == 0 else (msg, held[2])
            yield MERGED, t, {**robot_msg, **brain_msg}
            held = None
    if held is not None:
        yield MERGED, held[0], held[2]
