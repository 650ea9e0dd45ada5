"""The phases one tick shares between the closed loop in simulated time (``loop/loop.py``) and the two
sides of a real link (``loop/robot_side.py``, ``loop/brain_side.py``): the brain stages on what the brain
side sees, the robot stages on what arrived, the ``/control`` message, and the divergence checks. Each side
adds only what is its own (pacing, the link, the safe stop)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numba
import numpy as np

from cerebx.errors import Diverged
from cerebx.signals import Frame, Message

# the plant is checked for divergence every this many ticks, and at the end of every trial
DIVERGENCE_CHECK_TICKS = 50


@numba.njit(cache=True)
def all_finite(v):  # pragma: no cover - numba
    """``np.isfinite(v).all()`` in one compiled call (a command is checked every tick)."""
    for x in v.ravel():
        if not np.isfinite(x):
            return False
    return True


def brain_phase(stages: Sequence[Any], tick: int, t: float, q_des: np.ndarray, qd_des: np.ndarray,
                extra: dict[str, np.ndarray] | None, sensed: Message | None) -> tuple[Frame, dict[str, Any]]:
    """The brain stages in order on the reference and the newest sensor message; returns the frame and its
    signals (each stage's outputs written into them)."""
    signals: dict[str, Any] = {"ref.q": q_des, "ref.qd": qd_des}
    if extra:
        signals.update(extra)
    if sensed is not None:
        signals.update(sensed.values)
    frame = Frame(tick, t, signals, sensed)
    for st in stages:
        st.step(frame)
    return frame, signals


def robot_phase(stages: Sequence[Any], tick: int, t: float, robot: dict[str, Any], commands: Sequence[str],
                trial: int, adjust: Callable[[dict[str, Any]], None] | None = None) -> dict[str, np.ndarray]:
    """The robot stages in order on what the receiver gave and the plant's readings (``robot``, written in
    place), then ``adjust`` (e.g. a supervisor holding the pose), then the plant's command signals; a
    non-finite command ends the run as diverged."""
    rframe = Frame(tick, t, robot)
    for st in stages:
        st.step(rframe)
    if adjust is not None:
        adjust(robot)
    command = {name: robot[name] for name in commands}
    for name, v in command.items():
        if not all_finite(np.asarray(v)):
            raise Diverged(f"trial {trial}, t = {t:.3f} s: non-finite {name} command {v.tolist()}")
    return command


def control_message(head: dict[str, Any], stages: Sequence[Any], ee: np.ndarray | None,
                    ee_des: np.ndarray | None) -> dict[str, Any]:
    """One ``/control`` message: ``head`` (time, trial, the side's own fields), then what each robot stage
    records, then the actual and desired end-effector when the plant has one."""
    for st in stages:
        head.update(st.record())
    if ee is not None:
        head["ee"] = ee
    if ee_des is not None:
        head["ee_des"] = ee_des
    return head


def check_diverged(plant: Any, trial: int, t: float | None = None) -> None:
    """Ends the run as diverged when the plant left its physical envelope (``t`` names the tick, if any)."""
    why = plant.is_diverged()
    if why:
        raise Diverged(f"trial {trial}, t = {t:.3f} s: {why}" if t is not None else f"trial {trial}: {why}")
