"""The live view (``live.*``): a Foxglove WebSocket server that shows a running experiment."""

from __future__ import annotations

from pydantic import Field

from cerebx.schema.base import Strict


class LiveConfig(Strict):
    """Serve the run to Foxglove while it runs: every channel of run.mcap plus a 3-D scene of the plant.

    Off by default; with it off a run is exactly what it was without it. The server listens on
    ``host:port`` (localhost unless told otherwise: anyone who reaches the port sees the run)."""

    enabled: bool = Field(False, description="serve the run live over Foxglove's WebSocket protocol")
    host: str = Field("127.0.0.1", description="address to bind; 0.0.0.0 exposes the run to the whole network")
    port: int = Field(8765, ge=0, le=65535, description="TCP port; 0: any free port (logged at start)")
    display_hz: float = Field(
        30.0, gt=0, le=500, description="at most this many 3-D scene frames per wall-clock second go to the viewer "
        "(the recorded scene has its own rate, recording.scene_every)")
    signal_hz: float = Field(
        0.0, ge=0, description="at most this many messages per wall-clock second per recorded channel go to the "
        "viewer (the file keeps them all); 0: every message. Thins a fast run's stream (spike rasters too)")
    backlog_messages: int = Field(
        1024, ge=16, description="messages queued per client; a client that falls further behind loses the oldest")
