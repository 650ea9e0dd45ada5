"""A small client of Foxglove's WebSocket protocol (what the Foxglove app speaks to a live server), for
the live-view tests and measurements: it subscribes to topics as the server advertises them and keeps
every message it receives.

Protocol: text frames are JSON (``serverInfo``, ``advertise``, ...; the client sends ``subscribe``),
binary frames start with an opcode: 1 = message data (u32 subscription id, u64 log time in ns, payload),
2 = time (u64 ns), little-endian.
"""

from __future__ import annotations

import asyncio
import json
import struct
import threading
import time

import websockets

SUBPROTOCOLS = ["foxglove.sdk.v1", "foxglove.websocket.v1"]
MESSAGE_DATA, TIME = 1, 2
UNKNOWN = "Unknown channel ID: "


class LiveClient:
    """Connects to ``ws://host:port`` in a thread of its own (retrying until the server is up), subscribes
    to ``topics`` (all when None) and records ``(topic, log_time_ns, payload)`` until the server closes."""

    def __init__(self, port: int, topics: set[str] | None = None, host: str = "127.0.0.1",
                 connect_timeout_s: float = 120.0, read_delay_s: float = 0.0):
        self.url, self.topics = f"ws://{host}:{port}", topics
        self.connect_timeout_s, self.read_delay_s = connect_timeout_s, read_delay_s
        self.messages: list[tuple[str, int, bytes]] = []
        self.times: list[int] = []
        self.advertised: dict[int, dict] = {}
        self.server_info: dict | None = None
        self.subprotocol: str | None = None
        self.connected = threading.Event()
        self.error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, daemon=True)

    def start(self) -> LiveClient:
        self._thread.start()
        return self

    def join(self, timeout_s: float = 60.0) -> None:
        self._thread.join(timeout_s)

    def _run(self) -> None:
        try:
            asyncio.run(self._main())
        except BaseException as err:  # reported to the test through .error
            self.error = err

    async def _connect(self):
        deadline = time.monotonic() + self.connect_timeout_s
        while True:
            try:
                return await websockets.connect(self.url, subprotocols=SUBPROTOCOLS, max_size=None)
            except OSError:
                if time.monotonic() > deadline:
                    raise
                await asyncio.sleep(0.05)

    async def _main(self) -> None:
        ws = await self._connect()
        self.subprotocol = ws.subprotocol
        self.connected.set()
        subs: dict[int, str] = {}
        try:
            async for frame in ws:
                if self.read_delay_s:
                    await asyncio.sleep(self.read_delay_s)
                if isinstance(frame, str):
                    msg = json.loads(frame)
                    if msg.get("op") == "serverInfo":
                        self.server_info = msg
                    elif msg.get("op") == "advertise":
                        new = []
                        for ch in msg["channels"]:
                            self.advertised[ch["id"]] = ch
                            if self.topics is None or ch["topic"] in self.topics:
                                subs[ch["id"]] = ch["topic"]  # subscription id = channel id
                                new.append({"id": ch["id"], "channelId": ch["id"]})
                        if new:
                            await ws.send(json.dumps({"op": "subscribe", "subscriptions": new}))
                    elif msg.get("op") == "status" and msg.get("message", "").startswith(UNKNOWN):
                        # foxglove-sdk 0.30 sends an advertisement before it records the channel as
                        # advertised: a subscription that quick is refused, so ask again
                        cid = int(msg["message"][len(UNKNOWN):])
                        await asyncio.sleep(0.01)
                        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": cid, "channelId": cid}]}))
                elif frame[0] == MESSAGE_DATA:
                    sub, log_time = struct.unpack_from("<IQ", frame, 1)
                    self.messages.append((subs[sub], log_time, bytes(frame[13:])))
                elif frame[0] == TIME:
                    self.times.append(struct.unpack_from("<Q", frame, 1)[0])
        except websockets.ConnectionClosed:
            pass
        finally:
            await ws.close()
