"""Writes a run's MCAP file through foxglove-sdk (a Rust MCAP writer, fast enough for every 2 ms
step). The joint channels are ROS 2 ``sensor_msgs/msg/JointState`` messages and the spikes
``cerebx_msgs/msg/Spikes``, both in CDR (``recording/cdr.py``), which Foxglove reads natively; every other
channel is JSON (encoded with orjson) with a JSON Schema. Older runs have JSON joint states (a
``foxglove.JointStates``-shaped schema) and JSON spikes (``cerebx.Spikes``); the readers give both the same shape.

Channels (units SI; time stamps are simulated time):

=========================  =====================  ===============================================
topic                      schema                 content
=========================  =====================  ===============================================
/joint_states/desired      sensor_msgs/JointState desired position (rad) and velocity (rad/s)
/joint_states/actual       sensor_msgs/JointState actual position, velocity, applied torque (N·m)
/control                   cerebx.Control         what the brain side sent (joint.torque as
                                                  tau_controller, other signals by name), what robot
                                                  stages report (tau_supervisor), error, end-effector
                                                  and desired end-effector (m), delays sampled for
                                                  this step's messages (r2c_ms, c2r_ms)
/trial_metrics             cerebx.TrialMetrics    per-trial MAE per joint, velocity MAE, dtau, task variant
/events                    cerebx.PlantEvent      plant events as they happen
/spikes/<population>       cerebx_msgs/Spikes     time (s) and local indices of the cells that fired in the step
/weights                   cerebx.WeightSummary   per-trial plastic-weight statistics
/task/cartesian_path       cerebx.CartesianPath   desired Cartesian path of the first trial
=========================  =====================  ===============================================

With ``recording.scene_every`` or ``live.enabled`` the plant's 3-D scene is recorded too (``/scene/*``,
``/log``: see ``recording/scene.py``). With a live view (``recording/live.py``) every channel is also
logged to its server.

Metadata records ``config`` (the resolved config as JSON) and ``cerebx`` (version, overrides).
The file is finished in ``close`` (called from ``finally``), so an exception or Ctrl-C still
leaves a valid file.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import foxglove
import numpy as np
import orjson
from foxglove.mcap import MCAPCompression, MCAPWriteOptions

from cerebx.recording.cdr import JOINT_STATE, JOINT_STATE_DEFINITION, SPIKES, SPIKES_DEFINITION, JointStateEncoder

_NUMS = {"type": "array", "items": {"type": "number"}}

SCHEMAS: dict[str, dict] = {
    "cerebx.Control": {
        "type": "object",
        "properties": {"t": {"type": "number"}, "trial": {"type": "integer"}, "tau_controller": _NUMS,
                       "tau_supervisor": _NUMS, "error": _NUMS, "ee": _NUMS, "ee_des": _NUMS,
                       "r2c_ms": {"type": "number"}, "c2r_ms": {"type": "number"}},
    },
    "cerebx.TrialMetrics": {
        "type": "object",
        "properties": {"trial": {"type": "integer"}, "mae": {"type": "number"}, "mae_per_joint": _NUMS,
                       "vel_mae": {"type": "number"}, "torque_variability_Nm_per_ms": {"type": "number"},
                       "ee_error_m": {"type": ["number", "null"]}, "label": {"type": "string"}},
    },
    "cerebx.PlantEvent": {"type": "object", "properties": {"t": {"type": "number"}, "kind": {"type": "string"},
                                                           "params": {"type": "object"}}},
    "cerebx.WeightSummary": {"type": "object", "properties": {"trial": {"type": "integer"}}},
    "cerebx.CartesianPath": {"type": "object", "properties": {"x": _NUMS, "y": _NUMS, "z": _NUMS}},
}

_COMPRESSION = {"zstd": MCAPCompression.Zstd, "lz4": MCAPCompression.Lz4, "none": None}
ZSTD_LEVEL = 1
"""zstd's fastest level: a logged message (~0.8 kB of JSON) costs the loop's thread ~2.2 us instead of ~3.4 us at
the default level 3, and the files are no larger (joint states and control compress to ~30 % either way)."""


_NUMPY = orjson.OPT_SERIALIZE_NUMPY

EARLY_CHUNK = 0.6
"""The fraction of a chunk's size (in message bytes) from which :meth:`Recorder.idle` finishes the chunk."""


def to_ns(t_s: float) -> int:
    """A message's log time (ns) at simulated time ``t_s``."""
    return int(round(t_s * 1e9))


def stamps_ns(first_tick: int, n: int, dt_s: float) -> np.ndarray:
    """The log times (int64 ns) of ticks ``first_tick .. first_tick + n - 1`` of ``dt_s`` each: for each tick,
    the ``int(round(tick * dt_s * 1e9))`` of the messages logged at its time ``tick * dt_s``, the same doubles
    rounded the same way (half to even)."""
    ticks = np.arange(first_tick, first_tick + n, dtype=np.int64)
    return np.rint(ticks * dt_s * 1e9).astype(np.int64)


def register_schema(name: str, schema: dict) -> None:
    """Make a JSON Schema available to channels (a module with messages of its own calls this at import);
    a name already registered with another schema is refused."""
    if SCHEMAS.setdefault(name, schema) != schema:
        raise ValueError(f"schema {name!r} is already registered with another definition")


CDR_SCHEMAS: dict[str, str] = {JOINT_STATE: JOINT_STATE_DEFINITION, SPIKES: SPIKES_DEFINITION}
"""Schemas of the channels written in CDR (ROS 2 message definitions)."""


def channel_schema(name: str) -> foxglove.Schema:
    if name in CDR_SCHEMAS:
        return foxglove.Schema(name=name, encoding="ros2msg", data=CDR_SCHEMAS[name].encode())
    return foxglove.Schema(name=name, encoding="jsonschema", data=json.dumps(SCHEMAS[name]).encode())


def message_encoding(schema: str) -> str:
    """How the messages of a channel with ``schema`` are encoded: ``cdr`` or ``json``."""
    return "cdr" if schema in CDR_SCHEMAS else "json"


class _Both:
    """A topic logged into the MCAP file and to a live view."""

    __slots__ = ("file", "live")

    def __init__(self, file: foxglove.Channel, live: Any):
        self.file, self.live = file, live

    def log(self, data: bytes, log_time: int) -> None:
        self.file.base.log(data, log_time)
        self.live.log(data, log_time=log_time)


class Recorder:
    """Owns the MCAP writer for one run. Channels are created lazily on first use."""

    def __init__(self, path: Path, joint_names: tuple[str, ...] = (), chunk_size_kb: int = 256,
                 compression: str = "zstd", live: Any = None):
        self.path = Path(path)
        self._ctx = foxglove.Context()  # one context per recording: nothing leaks between runs
        opts = MCAPWriteOptions(compression=_COMPRESSION[compression], chunk_size=chunk_size_kb * 1024,
                                compression_threads=0, profile="",
                                compression_level=ZSTD_LEVEL if compression == "zstd" else 0)
        self._w = foxglove.open_mcap(self.path, allow_overwrite=True, context=self._ctx, writer_options=opts)
        self._logs: dict[str, Callable[[bytes, int], None]] = {}
        self._early = int(EARLY_CHUNK * chunk_size_kb * 1024) if compression != "none" else 0
        self._pending = 0  # message bytes logged since the last chunk this recorder finished (an estimate)
        self._joint_encoders: dict[str, JointStateEncoder] = {}
        self.joint_names = tuple(joint_names)
        self.live = live  # a LiveView (recording/live.py) whose server also gets every channel, or None
        self.closed = False
        # under recording.trials: the [start, end) log times (ns) of the recorded trials' control steps, which
        # the spikes logged after their tick are held to; None: every step is recorded
        self.held: list[tuple[int, int]] | None = None

    def _channel(self, topic: str, schema: str) -> Callable[[bytes, int], None]:
        """The function that logs ``(data, log_time_ns)`` on ``topic``, creating the channel on first use."""
        log = self._logs.get(topic)
        if log is None:
            ch = foxglove.Channel(topic, message_encoding=message_encoding(schema), context=self._ctx,
                                  schema=channel_schema(schema))
            twin = self.live.twin(topic, schema) if self.live is not None else None
            # the SDK's own channel object under the Python wrapper: the bytes go straight to the writer (the
            # wrapper's checks of the message's type cost about a microsecond a message, four messages a step)
            log = _Both(ch, twin).log if twin is not None else ch.base.log
            self._logs[topic] = log
        return log

    def write(self, topic: str, schema: str, t_s: float, msg: dict[str, Any]) -> None:
        """Log ``msg`` (numpy arrays allowed) on ``topic`` at simulated time ``t_s``."""
        data = orjson.dumps(msg, option=_NUMPY)
        self._pending += len(data)
        self._channel(topic, schema)(data, to_ns(t_s))

    def joint_states(self, topic: str, t_s: float, q: np.ndarray, qd: np.ndarray,
                     effort: np.ndarray | None = None) -> None:
        """A ``sensor_msgs/msg/JointState`` message: the joints named, or the first n of them when fewer
        values are given (as zip would pair them); effort 0 when none is given."""
        n = min(len(self.joint_names), len(q), len(qd), len(q) if effort is None else len(effort))
        ns = to_ns(t_s)
        data = self._joint_encoder(topic, n).encode(ns, q, qd, effort)
        self._pending += len(data)
        self._channel(topic, JOINT_STATE)(data, ns)

    def joint_state_messages(self, topic: str, t_ns: np.ndarray, q: np.ndarray, qd: np.ndarray) -> list[bytes]:
        """The ``sensor_msgs/msg/JointState`` messages :meth:`joint_states` would log on ``topic`` at the times
        ``t_ns`` (int64 ns, see :func:`stamps_ns`) for the rows of ``q`` and ``qd`` (effort 0), encoded at
        once and not logged: :meth:`log_encoded` logs each (a trial's desired states, known from its start)."""
        n = min(len(self.joint_names), q.shape[1], qd.shape[1])
        return self._joint_encoder(topic, n).encode_many(t_ns, q, qd)

    def _joint_encoder(self, topic: str, n: int) -> JointStateEncoder:
        """The encoder of ``topic``'s messages for its first ``n`` joints (made again when ``n`` changes)."""
        enc = self._joint_encoders.get(topic)
        if enc is None or enc.n != n:
            enc = self._joint_encoders[topic] = JointStateEncoder(self.joint_names[:n])
        return enc

    def log_encoded(self, topic: str, schema: str, data: bytes, t_ns: int) -> None:
        """Log a message encoded already (e.g. by :meth:`joint_state_messages`) at ``t_ns``."""
        self._pending += len(data)
        self._channel(topic, schema)(data, t_ns)

    def spike_messages(self, topics: Sequence[str], times_s: Sequence[float], data: bytes,
                       starts: Sequence[int]) -> None:
        """Log a chunk's spikes messages, encoded already (:func:`~cerebx.recording.spike_chunks.chunk_spike_messages`):
        message k = p * len(times_s) + s, ``data[starts[k]:starts[k + 1]]``, is population ``topics[p]``'s
        step s, logged at ``times_s[s]``."""
        stamps = [to_ns(t) for t in times_s]
        self._pending += len(data)
        keep = None if self.held is None else [self.holds_step(ns) for ns in stamps]
        k = 0
        for topic in topics:
            log = self._channel(topic, SPIKES)
            for s, ns in enumerate(stamps):
                if keep is None or keep[s]:
                    log(data[starts[k]:starts[k + 1]], ns)
                k += 1

    def restrict_steps(self, held: tuple[int, int] | None = None) -> None:
        """Record control steps only in the trials given (``recording.trials``): from now on, and also for
        ``held``, the [start, end) log times (ns) of a recorded trial's steps."""
        if self.held is None:
            self.held = []
        if held is not None and held not in self.held:
            self.held.append((int(held[0]), int(held[1])))

    def holds_step(self, t_ns: int) -> bool:
        """Whether a control step logged at ``t_ns`` belongs to a recorded trial (always without a window)."""
        if self.held is None:
            return True
        for start, end in reversed(self.held):
            if start <= t_ns:
                return t_ns < end
        return False

    def idle(self) -> None:
        """The caller is about to wait (the loop's thread, for the network's next chunk): a moment to compress
        the chunk being filled, if it holds at least :data:`EARLY_CHUNK` of a chunk's size. The writer
        compresses a chunk when a message fills it, in the middle of a tick, where the network thread then
        waits for the loop's thread to hand it its next inputs (~0.3 ms a 256 kB chunk with zstd, seven a
        ``make_run`` trial); finishing it here lets the compression run while the loop would wait anyway (the
        network thread's compiled code needs no interpreter lock, which the writer holds most of the time it
        compresses: docs/guide/speed.md). Whether it does depends only on the messages logged, so the
        file stays the same from run to run; its messages are the same either way, only the chunks are
        smaller."""
        if self._early and self._pending >= self._early and not self.closed:
            self._pending = 0
            self._w.flush()

    def flush(self) -> None:
        """Finish the chunk being filled (what was logged is then on the disk: a windowed run logs so little
        between its held trials that a chunk may hold many trials)."""
        if not self.closed:
            self._pending = 0
            self._w.flush()

    def metadata(self, name: str, data: dict[str, str]) -> None:
        self._w.write_metadata(name, {k: str(v) for k, v in data.items()})

    def close(self) -> None:
        if not self.closed:
            self.closed = True
            self._w.close()
