"""Copy a profile's run folders as if each study had run with its ``recording.trials`` window (studies.yaml).

    python scripts/window_runs.py SRC_PROFILE_DIR DST_PROFILE_DIR [--profile full] [--skip GLOB ...]

Each study folder of SRC (``<profile>/<study>/<job>``) is copied into DST: every file as it is (times kept, so the
report picks the same runs), but each MCAP segment (``run.mcap``, ``run.1.mcap``, ...) rewritten with the
messages a run with the study's window would have logged: every message of the per-trial channels
(``/trial_metrics``, ``/events``, ``/weights``, ...), and the control-step channels (joint states, ``/control``,
spikes, scene) only in the trials the window holds (a trial spans from the end of the one before to its own
``/trial_metrics``), without joint states where the study sets ``recording.joint_states=false``. The recorded
config says the window. Nothing in SRC is written. Prints each study's size before and after.

It proves ``recording.trials`` settings without running the profile again: ``cerebx report DST`` should draw the
same numbers as the report of SRC."""

from __future__ import annotations

import argparse
import fnmatch
import heapq
import json
import shutil
import sys
import time
from pathlib import Path

from mcap.exceptions import McapError
from mcap.reader import NonSeekingReader, make_reader
from mcap.records import Message, Metadata
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer

from cerebx.recording.reader import read_messages
from cerebx.report.studies import load_studies, study_recording, with_replicas
from cerebx.schema.window import TrialWindow, is_step_topic

CHUNK = 256 * 1024
TRIAL_TOPICS_READ = ["/trial_metrics"]


def windows(profile: str) -> dict[str, tuple[TrialWindow | None, bool]]:
    """Each study's window (None: every trial) and whether it records joint states (seeds included)."""
    return {name: study_recording(spec, profile) for name, spec in with_replicas(load_studies(), profile).items()}


def trial_spans(run_dir: Path) -> list[tuple[int, int, int]]:
    """(trial, start_ns, end_ns) of every completed trial, from the log times of ``/trial_metrics``."""
    spans, start = [], 0
    for _, t, msg in read_messages(run_dir, TRIAL_TOPICS_READ):
        spans.append((int(msg["trial"]), start, t))
        start = t
    return spans


def held_spans(run_dir: Path, window: TrialWindow, n_trials: int) -> list[tuple[int, int]]:
    return [(a, b) for k, a, b in trial_spans(run_dir) if window.holds(k, n_trials)]


def keeps(topic: str, joints: bool) -> str:
    """'all': every message of ``topic``; 'held': those in the held trials; 'none'."""
    if topic.startswith("/joint_states/") and not joints:
        return "none"
    return "held" if is_step_topic(topic) else "all"


def rewrite(src: Path, dst: Path, held: list[tuple[int, int]] | None, joints: bool,
            window: TrialWindow | None) -> None:
    """``src`` (an MCAP file) as ``dst`` with only the messages a windowed run logs."""
    with open(src, "rb") as f_in, open(dst, "wb") as f_out:
        reader = make_reader(f_in)
        try:
            summary = reader.get_summary()
        except McapError:  # no footer (a run killed outright): read as a stream, up to its last whole record
            summary = None
        header = reader.get_header()
        writer = Writer(f_out, chunk_size=CHUNK, compression=CompressionType.ZSTD)
        writer.start(profile=header.profile, library=header.library)
        schema_ids, channel_ids = {}, {}
        channels = summary.channels if summary is not None else {}
        schemas = summary.schemas if summary is not None else {}
        for sid, sch in sorted(schemas.items()):
            schema_ids[sid] = writer.register_schema(sch.name, sch.encoding, sch.data)
        for cid, ch in sorted(channels.items()):
            channel_ids[cid] = writer.register_channel(ch.topic, ch.message_encoding, schema_ids.get(ch.schema_id, 0),
                                                       ch.metadata)
        for meta in _metadata(reader, summary):
            data = dict(meta.metadata)
            if meta.name == "config" and "json" in data:
                cfg = json.loads(data["json"])
                rec = cfg.setdefault("recording", {})
                rec["trials"] = None if window is None else window.model_dump(mode="json")
                rec["joint_states"] = joints and rec.get("joint_states", True)
                data["json"] = json.dumps(cfg)
            writer.add_metadata(meta.name, data)
        if summary is None or not summary.chunk_indexes:  # a file still being written: read it as a stream
            _copy_stream(reader, writer, schema_ids, channel_ids, held, joints)
        else:
            _copy_indexed(reader, writer, channels, channel_ids, held, joints)
        writer.finish()


def _copy_indexed(reader, writer, channels, channel_ids, held, joints) -> None:
    """The per-trial messages and the step messages of each held trial (read by time range: the chunks of other
    trials are not even decompressed), merged by log time, per-trial first at equal times (as the loop logs a
    trial's /trial_metrics before the next trial's first step)."""
    every = [c.topic for c in channels.values() if keeps(c.topic, joints) == "all"]
    step = [c.topic for c in channels.values() if keeps(c.topic, joints) == "held"]

    def trial_level():
        for n, (_, _, m) in enumerate(reader.iter_messages(topics=every) if every else ()):
            yield m.log_time, 0, n, m

    def step_level():
        ranges = [(None, None)] if held is None else held
        n = 0
        for a, b in ranges if step else ():
            for _, _, m in reader.iter_messages(topics=step, starting_at=a, ending_before=b):
                yield m.log_time, 1, n, m
                n += 1

    for _, _, _, m in heapq.merge(trial_level(), step_level()):
        _add(writer, channel_ids[m.channel_id], m)


def _metadata(reader, summary) -> list:
    if summary is not None:
        return list(reader.iter_metadata())
    reader._stream.seek(0)
    out = []
    try:
        for record in StreamReader(reader._stream, skip_magic=False).records:
            if isinstance(record, Metadata):
                out.append(record)
    except McapError:
        pass
    return out


def _copy_stream(reader, writer, schema_ids, channel_ids, held, joints) -> None:
    reader._stream.seek(0)
    try:
        for sch, ch, m in NonSeekingReader(reader._stream).iter_messages(log_time_order=False):
            _copy_one(writer, schema_ids, channel_ids, held, joints, sch, ch, m)
    except McapError:
        pass


def _copy_one(writer, schema_ids, channel_ids, held, joints, sch, ch, m) -> None:
    if ch.id not in channel_ids:
        if sch is not None and sch.id not in schema_ids:
            schema_ids[sch.id] = writer.register_schema(sch.name, sch.encoding, sch.data)
        channel_ids[ch.id] = writer.register_channel(ch.topic, ch.message_encoding, schema_ids.get(ch.schema_id, 0),
                                                     ch.metadata)
    kind = keeps(ch.topic, joints)
    if kind == "none" or kind == "held" and held is not None and not any(a <= m.log_time < b for a, b in held):
        return
    _add(writer, channel_ids[ch.id], m)


def _add(writer: Writer, channel_id: int, m: Message) -> None:
    writer.add_message(channel_id, m.log_time, m.data, m.publish_time, m.sequence)


def copy_run(src: Path, dst: Path, window: TrialWindow | None, joints: bool) -> None:
    dst.mkdir(parents=True, exist_ok=True)
    held = None
    if window is not None:
        n = int(json.loads((src / "summary.json").read_text()).get("trials") or 0)
        held = held_spans(src, window, n)
    for f in sorted(src.iterdir()):
        if f.is_dir():
            shutil.copytree(f, dst / f.name, copy_function=shutil.copy2, dirs_exist_ok=True)
        elif f.suffix == ".mcap" and (window is not None or not joints):
            rewrite(f, dst / f.name, held, joints, window)
            shutil.copystat(f, dst / f.name)
        else:
            shutil.copy2(f, dst / f.name)


def size(path: Path) -> int:
    return sum(f.stat().st_size for f in path.rglob("*") if f.is_file())


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("src", type=Path)
    ap.add_argument("dst", type=Path)
    ap.add_argument("--profile", default="full", choices=("quick", "full"))
    ap.add_argument("--skip", action="append", default=[], help="study folders to leave out (glob)")
    args = ap.parse_args(argv)
    studies = windows(args.profile)
    total_in = total_out = 0
    for study_dir in sorted(p for p in args.src.iterdir() if p.is_dir()):
        if any(fnmatch.fnmatch(study_dir.name, g) for g in args.skip):
            print(f"{study_dir.name}: skipped", flush=True)
            continue
        if study_dir.name not in studies:
            print(f"{study_dir.name}: not a study of the {args.profile} profile, copied as it is", flush=True)
        window, joints = studies.get(study_dir.name, (None, True))
        started = time.monotonic()
        out = args.dst / study_dir.name
        for f in study_dir.iterdir():  # the study's own files (multirun.yaml, study.log, sweep summaries)
            if f.is_file():
                out.mkdir(parents=True, exist_ok=True)
                shutil.copy2(f, out / f.name)
        for summary in sorted(study_dir.rglob("summary.json")):
            run = summary.parent
            copy_run(run, out / run.relative_to(study_dir), window, joints)
        shutil.copystat(study_dir, out)
        a, b = size(study_dir), size(out)
        total_in, total_out = total_in + a, total_out + b
        what = "every trial" if window is None else window.model_dump(exclude_defaults=True)
        print(f"{study_dir.name}: {a / 1e6:.0f} MB -> {b / 1e6:.0f} MB ({what}, joint states {joints}; "
              f"{time.monotonic() - started:.0f} s)", flush=True)
    print(f"total: {total_in / 1e9:.2f} GB -> {total_out / 1e9:.2f} GB", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
