"""The link between the brain side and the robot side: one delay channel each way.

A message sent at tick k with sampled delay d is released at the first tick whose time is at
least stamp + d; a later message is never released before an earlier one (docs/models.md#delays). The link is
simulated on the tick grid; a real transport would offer the same four calls.
"""

from __future__ import annotations

import math
from collections import deque
from typing import Any, Protocol

from cerebx.schema.base import CONTROL_DT_MS


class DelaySampler(Protocol):
    def next_ms(self) -> float:
        """The delay (ms) for the next message on this path."""


class DelayChannel:
    """FIFO of in-flight messages on the tick grid; releases in order, never overtaking."""

    def __init__(self, sampler: DelaySampler, step_ms: float = CONTROL_DT_MS):
        self.sampler = sampler
        self.step_ms = step_ms
        self._queue: deque[tuple[int, Any]] = deque()
        self._last_release = -1
        self.last_delay_ms = 0.0

    def send(self, msg: Any, tick: int) -> None:
        d = self.sampler.next_ms()
        self.last_delay_ms = d
        release = tick + math.ceil(d / self.step_ms - 1e-9)
        release = max(release, self._last_release)
        self._last_release = release
        self._queue.append((release, msg))

    def receive(self, tick: int) -> list[Any]:
        out = []
        q = self._queue
        while q and q[0][0] <= tick:
            out.append(q.popleft()[1])
        return out


class Link:
    """Robot-to-controller (sensor) and controller-to-robot (command) channels of one run."""

    def __init__(self, r2c: DelaySampler, c2r: DelaySampler, step_ms: float = CONTROL_DT_MS):
        self.r2c = DelayChannel(r2c, step_ms)
        self.c2r = DelayChannel(c2r, step_ms)
