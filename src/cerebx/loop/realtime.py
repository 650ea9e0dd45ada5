"""What the two sides of a wall-clock run share: their extra MCAP channels, the per-tick timing log,
link events, and the errors that end a side.

A wall-clock run is one experiment split at the link (``delay_channel.py`` in simulated time): the robot
side (``robot_side.py``, ``cerebx robot``) steps the plant and everything after the link, paced by the
monotonic clock; the brain side (``brain_side.py``, ``cerebx run ... link=... clock=wall``) steps the
task reference and the brain stages as sensor messages arrive. The phases of ``loop.py`` keep their
order on each side; the link between them is a transport (``cerebx.link``).

Extra channels (times are the tick's simulated time, as in every log):

====================  ==========  ========================================================================
topic                 side        content
====================  ==========  ========================================================================
/timing               robot       per tick: lateness of its start, compute time, time waited for the
                                  command, commands that arrived (late: after their stamp), lost, refused,
                                  dropped (packets dropped during the tick, by reason)
/timing/brain         brain       per tick: lag (finish - tick start), compute time, sensors that
                                  arrived, shedding level, dropped by reason
/delays/r2c           brain       per sensor message: seq, tick sent, tick used, measured delay (ms)
/delays/c2r           robot       per command message: the same
/shedding             brain       each change of the shedding level, with the lead that caused it
/link_events          both        safe stop, pose held, commands or sensors resumed, link lost, ...
/clock_sync           brain       each clock-offset estimate with its uncertainty
====================  ==========  ========================================================================
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from cerebx.link.stats import describe
from cerebx.recording.pair import ROBOT_DIR
from cerebx.recording.recorder import SCHEMAS, Recorder

_NUM = {"type": "number"}
_INT = {"type": "integer"}
SCHEMAS.update({
    "cerebx.RobotTiming": {"type": "object", "properties": {
        "t": _NUM, "tick": _INT, "lateness_ms": _NUM, "compute_ms": _NUM, "wait_ms": _NUM, "commands": _INT,
        "late": _INT, "lost": _INT, "refused": _INT, "dropped": {"type": "object"}, "state": {"type": "string"}}},
    "cerebx.BrainTiming": {"type": "object", "properties": {
        "t": _NUM, "tick": _INT, "lag_ms": _NUM, "compute_ms": _NUM, "sensors": _INT, "lost": _INT,
        "refused": _INT, "dropped": {"type": "object"}, "level": _INT}},
    "cerebx.LinkDelay": {"type": "object", "properties": {
        "seq": _INT, "tick": _INT, "used_tick": _INT, "delay_ms": _NUM}},
    "cerebx.Shedding": {"type": "object", "properties": {
        "t": _NUM, "level": _INT, "name": {"type": "string"}, "lead_ratio": _NUM, "lag_ms": _NUM}},
    "cerebx.LinkEvent": {"type": "object", "properties": {
        "t": _NUM, "side": {"type": "string"}, "event": {"type": "string"}, "detail": {"type": "string"}}},
    "cerebx.ClockSync": {"type": "object", "properties": {
        "t": _NUM, "offset_ms": _NUM, "uncertainty_ms": _NUM, "method": {"type": "string"}, "probes": _INT}},
})

__all__ = ["ROBOT_DIR", "LinkEvents", "TickLog", "side_summary"]


@dataclass
class LinkEvents:
    """Transitions of a side (safe stop, pose held, resumed, lost), logged and kept for the summary."""

    side: str
    rec: Recorder | None
    items: list[dict[str, Any]] = field(default_factory=list)

    def add(self, t_s: float, event: str, detail: str = "") -> None:
        item = {"t": round(t_s, 6), "side": self.side, "event": event, "detail": detail}
        self.items.append(item)
        if self.rec is not None:
            self.rec.write("/link_events", "cerebx.LinkEvent", t_s, item)


class TickLog:
    """Named per-tick series, preallocated for the whole run."""

    def __init__(self, ticks: int, names: tuple[str, ...]):
        self.series = {n: np.full(ticks, np.nan) for n in names}
        self.n = 0

    def put(self, tick: int, **values: float) -> None:
        for name, v in values.items():
            self.series[name][tick] = v
        self.n = max(self.n, tick + 1)

    def totals(self) -> dict[str, Any]:
        return {name: describe(v[:self.n], 3) for name, v in self.series.items()}


def side_summary(cfg: Any, side: str, run_id: bytes, end: Any, timing: dict[str, Any],
                 events: LinkEvents, **extra: Any) -> dict[str, Any]:
    """The ``link`` block a side adds to its summary.json."""
    return {"side": side, "transport": cfg.link.kind, "run_id": run_id.hex(), "clock": cfg.clock,
            "packets": end.counts() if end is not None else {}, "timing": timing, "events": events.items, **extra}
