"""Where a run's time goes, for ``cerebx bench`` (``recording.phase_times=true``; off otherwise, at no cost).
Not to be confused with ``loop/phases.py``, the parts of one tick: this module only times them.

A :class:`PhaseClock` charges the main thread's wall time to the phase it is in. Code switches phase at a
boundary, so every second lands in exactly one phase: phases nest exclusively (the wait for the network
inside the controller's step is ``wait``, not ``brain``). Coarse phases (:meth:`PhaseClock.span`: build,
checkpoint, finish ...) also count the main thread's CPU time. Work done on other threads (the network,
a checkpoint being written) is reported apart, with its CPU time (:meth:`PhaseClock.add_background`).

The clock in use is module state (:func:`activate`), so a part deep in the loop (the spiking controller's
hand-off to its network thread) can charge a phase without being handed the clock; with no clock active
:func:`span` is a shared no-op context.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from contextlib import AbstractContextManager, contextmanager, nullcontext
from typing import Any

_NOTHING = nullcontext()


class PhaseClock:
    """Wall seconds of the main thread per phase (exclusive), CPU seconds of coarse phases, and the
    wall and CPU seconds of background work."""

    def __init__(self, phase: str = "loop"):
        self.wall: dict[str, float] = {}
        self.cpu: dict[str, float] = {}
        self.background: dict[str, dict[str, float]] = {}
        self.phase = phase
        self._t = time.perf_counter()
        self._lock = threading.Lock()

    def switch(self, phase: str) -> str:
        """Charge the time since the last switch to the current phase, enter ``phase``; returns the phase
        left (to switch back to)."""
        t = time.perf_counter()
        prev = self.phase
        self.wall[prev] = self.wall.get(prev, 0.0) + (t - self._t)
        self._t = t
        self.phase = phase
        return prev

    @contextmanager
    def span(self, phase: str) -> Iterator[None]:
        """A coarse phase: its wall time (exclusive) and the main thread's CPU time in it (inclusive)."""
        c0 = time.thread_time()
        prev = self.switch(phase)
        try:
            yield
        finally:
            self.switch(prev)
            self.cpu[phase] = self.cpu.get(phase, 0.0) + (time.thread_time() - c0)

    @contextmanager
    def charge(self, phase: str) -> Iterator[None]:
        """A fine-grained phase: wall time only (a CPU clock read costs a system call)."""
        prev = self.switch(phase)
        try:
            yield
        finally:
            self.switch(prev)

    def add_background(self, name: str, wall_s: float, cpu_s: float) -> None:
        """Work of another thread (any thread may call this)."""
        with self._lock:
            row = self.background.setdefault(name, {"wall_s": 0.0, "cpu_s": 0.0, "count": 0})
            row["wall_s"] += wall_s
            row["cpu_s"] += cpu_s
            row["count"] += 1

    def report(self) -> dict[str, Any]:
        """Seconds per phase so far (the current one included), rounded to microseconds."""
        self.switch(self.phase)
        with self._lock:
            background = {k: {f: round(v, 6) for f, v in row.items()} for k, row in self.background.items()}
        return {"wall_s": {k: round(v, 6) for k, v in sorted(self.wall.items())},
                "cpu_s": {k: round(v, 6) for k, v in sorted(self.cpu.items())},
                "background": background}


_active: PhaseClock | None = None


def activate(clock: PhaseClock | None) -> None:
    """Make ``clock`` the one :func:`span` and :func:`active` use (None: timing off)."""
    global _active
    _active = clock


def active() -> PhaseClock | None:
    return _active


def span(phase: str) -> AbstractContextManager[None]:
    """:meth:`PhaseClock.span` of the active clock, or a no-op."""
    clock = _active
    return _NOTHING if clock is None else clock.span(phase)


def charge(phase: str) -> AbstractContextManager[None]:
    """:meth:`PhaseClock.charge` of the active clock (wall time only), or a no-op."""
    clock = _active
    return _NOTHING if clock is None else clock.charge(phase)
