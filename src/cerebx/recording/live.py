"""Watch a run while it runs: a Foxglove WebSocket server (foxglove-sdk) fed by the recorder.

Every channel the recorder writes into run.mcap is logged, by the same ``Recorder`` call, to the
server's own context as well; the 3-D scene (``recording/scene.py``) is sent at the display rate.
Nothing here waits for a client: ``log`` only hands a message to the SDK, whose server queues at most
``live.backlog_messages`` messages per client and drops the oldest data of a client that falls behind (a
client whose control messages back up as far is disconnected). With no client subscribed a ``log`` call
is about a microsecond.

Clients connect with Foxglove's WebSocket protocol (subprotocol ``foxglove.sdk.v1``, the same protocol
as ``foxglove.websocket.v1``). The server binds to ``live.host`` (127.0.0.1 unless told otherwise); it
has no authentication, so an address reachable from elsewhere lets anyone there watch the run.
"""

from __future__ import annotations

import logging
import time
from pathlib import Path
from typing import Any

import foxglove
import orjson
from foxglove.websocket import Capability

from cerebx.recording.recorder import channel_schema, message_encoding
from cerebx.recording.scene import PREFIX

log = logging.getLogger("cerebx")

LAYOUT = Path(__file__).with_name("foxglove_layout.json")
"""The Foxglove layout shipped with cerebx (3-D scene, joints, MAE, spike raster, log)."""


class _Paced:
    """A live channel that passes at most one message per ``period_s`` of wall-clock time."""

    __slots__ = ("channel", "period_s", "next_s")

    def __init__(self, channel: foxglove.Channel, period_s: float):
        self.channel, self.period_s, self.next_s = channel, period_s, 0.0

    def log(self, data: bytes, log_time: int) -> None:
        now = time.perf_counter()
        if now >= self.next_s:
            self.next_s = now + self.period_s
            self.channel.log(data, log_time=log_time)


class LiveView:
    """A Foxglove WebSocket server for one run, in a context of its own."""

    def __init__(self, cfg: Any):
        self.ctx = foxglove.Context()
        self.server = foxglove.start_server(
            name="cerebx", host=cfg.host, port=cfg.port, context=self.ctx, capabilities=[Capability.Time],
            message_backlog_size=cfg.backlog_messages)
        self.host, self.port, self.display_hz = cfg.host, self.server.port, cfg.display_hz
        self.signal_period_s = 1.0 / cfg.signal_hz if cfg.signal_hz > 0 else 0.0
        self._channels: dict[str, foxglove.Channel] = {}

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    def channel(self, topic: str, schema: str) -> foxglove.Channel:
        ch = self._channels.get(topic)
        if ch is None:
            ch = foxglove.Channel(topic, message_encoding=message_encoding(schema), context=self.ctx,
                                  schema=channel_schema(schema))
            self._channels[topic] = ch
        return ch

    def twin(self, topic: str, schema: str) -> foxglove.Channel | _Paced | None:
        """The live channel a recorder channel is also logged to, paced by ``live.signal_hz`` (None for the
        scene's, sent by the scene writer at the display rate)."""
        if topic.startswith(PREFIX):
            return None
        ch = self.channel(topic, schema)
        return _Paced(ch, self.signal_period_s) if self.signal_period_s > 0 else ch

    def log(self, topic: str, schema: str, t_s: float, msg: dict) -> None:
        self.channel(topic, schema).log(orjson.dumps(msg, option=orjson.OPT_SERIALIZE_NUMPY),
                                        log_time=int(round(t_s * 1e9)))

    def time(self, t_s: float) -> None:
        """Tell the viewer the run's (simulated) time."""
        self.server.broadcast_time(int(round(t_s * 1e9)))

    def stop(self) -> None:
        self.server.stop()


def start(cfg: Any) -> LiveView | None:
    """The live view ``cfg.live`` asks for, or None (off, or its address cannot be bound: the run goes on
    without it and says so)."""
    if not cfg.live.enabled:
        return None
    try:
        view = LiveView(cfg.live)
    except RuntimeError as err:  # the SDK's FoxgloveError: address in use or not available
        log.error("live view: cannot serve on %s:%s (%s); the run goes on without it", cfg.live.host,
                  cfg.live.port, err)
        return None
    log.info("live view: %s (Foxglove: Open connection > Foxglove WebSocket; layout: %s)", view.url, LAYOUT)
    return view
