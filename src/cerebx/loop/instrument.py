"""Per-tick phases of a timed run (``recording.phase_times``): the loop's parts behind thin proxies that
switch the :class:`~cerebx.phase_clock.PhaseClock` around each call, so the loop itself is not touched.

========== =====================================================================================
phase      what is charged to it
========== =====================================================================================
plant      sense, actuate, true state, end effector, physics step, divergence check
brain      the brain-side stages' steps (the controller's encoders and hand-off; its wait for the
           network thread is ``wait``)
robot      the receiver and the robot-side stages (supervisor, muscles, ...)
recording  every message logged (``/control``, joint states, spikes, ...)
end_trial  the stages' end-of-trial work (statistics of the learned weights)
loop       what is left: the loop's own bookkeeping, the link, the trial metrics
========== =====================================================================================

Only the loop's references are replaced (the build context the checkpoints pickle keeps the originals);
the recorder's methods are wrapped on the instance, which is never pickled. A wrapped call costs about
half a microsecond, which the timed run's own factor shows; ``cerebx bench`` takes the real-time factor
from untimed runs.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from cerebx.loop.loop import ClosedLoop
from cerebx.phase_clock import PhaseClock

PLANT_CALLS = ("sense", "actuate", "true_state", "end_effector", "step", "is_diverged")
RECORDER_CALLS = ("write", "joint_states", "log_encoded", "spike_messages", "idle")


def _timed(fn: Callable, clock: PhaseClock, phase: str) -> Callable:
    switch = clock.switch

    def call(*args: Any, **kwargs: Any) -> Any:
        prev = switch(phase)
        try:
            return fn(*args, **kwargs)
        finally:
            switch(prev)

    return call


class _Timed:
    """``target`` with the methods of ``calls`` (name -> phase) timed; everything else passes through."""

    def __init__(self, target: Any, clock: PhaseClock, calls: dict[str, str]):
        self._target = target
        for name, phase in calls.items():
            setattr(self, name, _timed(getattr(target, name), clock, phase))

    def __getattr__(self, name: str) -> Any:
        return getattr(self._target, name)


def instrument(loop: ClosedLoop, clock: PhaseClock) -> None:
    """Time ``loop``'s plant, stages and recorder from now on."""
    loop.plant = _Timed(loop.plant, clock, dict.fromkeys(PLANT_CALLS, "plant"))
    loop.brain = [_Timed(st, clock, {"step": "brain", "end_trial": "end_trial"}) for st in loop.brain]
    loop.receiver = _Timed(loop.receiver, clock, {"receive": "robot"})
    loop.robot = [_Timed(st, clock, {"step": "robot", "record": "recording"}) for st in loop.robot]
    rec = loop.rec
    if rec is not None:
        for name in RECORDER_CALLS:
            setattr(rec, name, _timed(getattr(rec, name), clock, "recording"))
