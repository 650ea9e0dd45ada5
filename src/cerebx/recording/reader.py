"""Reads run folders and MCAP files back (for `cerebx inspect`, the report and the tests)."""

from __future__ import annotations

import json
import struct
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from mcap.decoder import DecoderFactory
from mcap.reader import make_reader
from mcap.records import Channel, Message, Metadata, Schema
from mcap.stream_reader import StreamReader

from cerebx import runfiles
from cerebx.errors import CerebxError
from cerebx.recording.cdr import JOINT_STATE, SPIKES, decode_joint_state, decode_spikes
from cerebx.recording.pair import merge, robot_log
from cerebx.recording.segments import segments
from cerebx.recording.summary import read_summary

__all__ = ["channel_counts", "mcap_path", "read_messages", "read_metadata", "read_summary"]


def _short(err: Exception) -> str:
    text = str(err).splitlines()[0] if str(err) else ""
    return f"{type(err).__name__}: {text[:100]}" + ("…" if len(text) > 100 else "")


class Decoders(DecoderFactory):
    """JSON channels decode with json.loads (mcap ships no JSON decoder), the joint states' and spikes' CDR
    with ``recording/cdr.py`` into the shape their JSON messages had."""

    def decoder_for(self, message_encoding: str, schema: Any):
        return _decoder(message_encoding, schema.name if schema is not None else None)


def _decoder(message_encoding: str, schema_name: str | None) -> Any:
    if message_encoding == "json":
        return json.loads
    if message_encoding == "cdr" and schema_name == JOINT_STATE:
        return decode_joint_state()
    if message_encoding == "cdr" and schema_name == SPIKES:
        return decode_spikes
    return None


def mcap_path(path: Path | str) -> Path:
    p = Path(path)
    return p / runfiles.MCAP if p.is_dir() else p


def _reader(fh):
    try:
        return make_reader(fh, decoder_factories=[Decoders()])
    except Exception as err:  # mcap raises several types for bad files
        raise CerebxError(f"{fh.name}: not a readable MCAP file ({_short(err)})") from None


def _has_summary(fh) -> bool:
    """Whether the file ends in a footer that points to a summary section (a cleanly closed file)."""
    try:
        return make_reader(fh).get_summary() is not None
    except Exception:
        return False
    finally:
        fh.seek(0)


def _scan(fh) -> Iterator[Any]:
    """Every complete record of a file read front to back, for a file without a summary (a run in
    progress, or one hard-killed): stops quietly at an incomplete tail, raises for a file that is not MCAP."""
    records = StreamReader(fh, skip_magic=False).records
    try:
        first = next(records)
    except Exception as err:
        raise CerebxError(f"{fh.name}: not an MCAP file ({_short(err)})") from None
    yield first
    while True:
        try:
            rec = next(records)
        except StopIteration:
            return
        except Exception:  # the incomplete tail: stop at the last complete record
            return
        yield rec


def _stream_messages(fh, topics: list[str] | None, decode: bool = True) -> Iterator[tuple[str, int, Any]]:
    schemas: dict[int, str] = {}
    channels: dict[int, tuple[str, Any]] = {}  # id -> topic, decoder
    for rec in _scan(fh):
        if isinstance(rec, Schema):
            schemas[rec.id] = rec.name
        elif isinstance(rec, Channel):
            decode = _decoder(rec.message_encoding, schemas.get(rec.schema_id))
            if decode is not None and (topics is None or rec.topic in topics):
                channels[rec.id] = (rec.topic, decode)
        elif isinstance(rec, Message):
            ch = channels.get(rec.channel_id)
            if ch is not None:
                if not decode:
                    yield ch[0], rec.log_time, None
                    continue
                try:
                    yield ch[0], rec.log_time, ch[1](rec.data)
                except (ValueError, struct.error):  # a damaged message: skipped like the incomplete tail
                    continue


def read_messages(path: Path | str, topics: list[str] | None = None, start_ns: int | None = None,
                  end_ns: int | None = None) -> Iterator[tuple[str, int, Any]]:
    """Yield (topic, log_time_ns, decoded message) in log-time order.

    A run folder is read across its segments (a resumed run: ``run.mcap``, ``run.1.mcap`` …) as one
    log. A file without a summary section (a run still going, or one killed with SIGKILL) is read as a
    stream up to its last complete record. The folder of a wall-clock run also holds its robot side's log
    (``robot/run.mcap``): the two are read as one (``recording/pair.py``).

    Parameters
    ----------
    path : Path or str
        A run folder or an MCAP file.
    topics : list of str, optional
        Only these topics (e.g. ``["/trial_metrics"]``); all when None.
    start_ns, end_ns : int, optional
        Only messages logged in [start_ns, end_ns) (simulated time, ns).
    """
    p = Path(path)
    if not p.is_dir():
        yield from _read_file(p, topics, start_ns, end_ns)
        return
    robot = robot_log(p)
    if robot is not None:
        yield from merge(_read_segments(p, topics, start_ns, end_ns), _read_file(robot, topics, start_ns, end_ns))
        return
    yield from _read_segments(p, topics, start_ns, end_ns)


def _read_segments(p: Path, topics: list[str] | None, start_ns: int | None,
                   end_ns: int | None, decode: bool = True) -> Iterator[tuple[str, int, Any]]:
    for seg in segments(p):
        lo = seg.start_ns if start_ns is None else max(start_ns, seg.start_ns)
        hi = seg.end_ns + 1 if seg.end_ns is not None else None  # the boundary itself: see owns()
        if end_ns is not None:
            hi = end_ns if hi is None else min(end_ns, hi)
        if hi is None or lo < hi:
            for topic, t, msg in _read_file(seg.path, topics, lo, hi, decode):
                if seg.owns(topic, t):
                    yield topic, t, msg


def _read_file(p: Path, topics: list[str] | None, start_ns: int | None,
               end_ns: int | None, decode: bool = True) -> Iterator[tuple[str, int, Any]]:
    """(topic, log time, message) of ``p`` in log-time order; ``decode`` False: None for each message (counting
    needs no decoding)."""
    if not p.exists():
        raise CerebxError(f"{p}: no such file")
    with open(p, "rb") as fh:
        if not _has_summary(fh):
            for topic, t, msg in _stream_messages(fh, topics, decode):
                if (start_ns is None or t >= start_ns) and (end_ns is None or t < end_ns):
                    yield topic, t, msg
            return
        reader = _reader(fh)
        try:
            if not decode:
                for _schema, channel, message in reader.iter_messages(
                        topics=topics, starting_at=start_ns, ending_before=end_ns):
                    yield channel.topic, message.log_time, None
                return
            for _schema, channel, message, decoded in reader.iter_decoded_messages(
                    topics=topics, starting_at=start_ns, ending_before=end_ns):
                yield channel.topic, message.log_time, decoded
        except CerebxError:
            raise
        except Exception as err:
            raise CerebxError(f"{p}: damaged MCAP file ({_short(err)})") from None


def channel_counts(path: Path | str) -> dict[str, int]:
    """Message count per topic: from the file's summary section, by scanning a file without one, or (a
    resumed run's folder) counted over its segments as :func:`read_messages` reads them.

    Parameters
    ----------
    path : Path or str
        A run folder or an MCAP file.
    """
    if Path(path).is_dir() and len(segments(path)) > 1:
        per_topic: dict[str, int] = {}
        for topic, _t, _msg in _read_segments(Path(path), None, None, None, decode=False):
            per_topic[topic] = per_topic.get(topic, 0) + 1
        return dict(sorted(per_topic.items()))
    p = mcap_path(path)
    if not p.exists():
        raise CerebxError(f"{p}: no such file")
    with open(p, "rb") as fh:
        if not _has_summary(fh):
            topics: dict[int, str] = {}
            counts: dict[int, int] = {}
            for rec in _scan(fh):
                if isinstance(rec, Channel):
                    topics[rec.id] = rec.topic
                elif isinstance(rec, Message):
                    counts[rec.channel_id] = counts.get(rec.channel_id, 0) + 1
            return {topics[c]: n for c, n in sorted(counts.items()) if c in topics}
        try:
            summary = _reader(fh).get_summary()
        except CerebxError:
            raise
        except Exception as err:
            raise CerebxError(f"{p}: damaged MCAP file ({_short(err)})") from None
        if summary is None or summary.statistics is None:
            raise CerebxError(f"{p}: MCAP summary has no statistics")
        return {summary.channels[cid].topic: n for cid, n in sorted(summary.statistics.channel_message_counts.items())}


def has_summary(path: Path | str) -> bool:
    """Whether the file was closed cleanly (its summary section is there)."""
    with open(mcap_path(path), "rb") as fh:
        return _has_summary(fh)


def read_metadata(path: Path | str) -> dict[str, dict[str, str]]:
    """The metadata records of a file; of a run folder, its last segment's (each segment carries the
    config, and the last one the summary of the whole run); of a wall-clock run's folder, also the robot
    side's records under ``robot.<name>``.

    Parameters
    ----------
    path : Path or str
        A run folder or an MCAP file.
    """
    if Path(path).is_dir() and robot_log(path) is not None:
        both = _metadata(segments(path)[-1].path)
        both.update({f"robot.{k}": v for k, v in _metadata(robot_log(path)).items()})
        return both
    return _metadata(segments(path)[-1].path if Path(path).is_dir() else Path(path))


def _metadata(p: Path) -> dict[str, dict[str, str]]:
    if not p.exists():
        raise CerebxError(f"{p}: no such file")
    with open(p, "rb") as fh:
        if not _has_summary(fh):
            return {r.name: dict(r.metadata) for r in _scan(fh) if isinstance(r, Metadata)}
        try:
            return {m.name: dict(m.metadata) for m in _reader(fh).iter_metadata()}
        except CerebxError:
            raise
        except Exception as err:
            raise CerebxError(f"{p}: damaged MCAP file ({_short(err)})") from None
