"""A run's MCAP log as one or more segment files.

A run that is resumed (``cerebx run resume=RUN_DIR``, or a requeued SLURM job) keeps what it logged
and writes the continuation into a further file: ``run.mcap``, ``run.1.mcap``, ``run.2.mcap`` …
``segments.json`` lists them with the simulated time each one starts at. A segment holds everything
logged from its start on; where an earlier segment runs past the next one's start (the trials after
the last checkpoint, logged before the run was killed and run again from the checkpoint), the later
segment is the one read. Readers (``recording/reader.py``) present the segments as one log.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path

from cerebx import runfiles
from cerebx.errors import CerebxError

FIRST = runfiles.MCAP
INDEX = runfiles.SEGMENTS
# Written when a trial ends, stamped with the time of the next trial's first tick: at a segment boundary
# (a checkpoint, taken between trials) they belong to the segment before it, every other topic to the one after.
TRIAL_END_TOPICS = frozenset({"/trial_metrics", "/weights"})


@dataclass(frozen=True)
class Segment:
    path: Path
    start_ns: int  # simulated time of its first message
    end_ns: int | None  # where the next segment takes over (None: the last one)

    def owns(self, topic: str, t_ns: int) -> bool:
        """Whether this segment's message on ``topic`` at ``t_ns`` is part of the run (not superseded)."""
        if t_ns == self.start_ns and self.start_ns > 0:
            return topic not in TRIAL_END_TOPICS
        if self.end_ns is not None and t_ns >= self.end_ns:
            return t_ns == self.end_ns and topic in TRIAL_END_TOPICS
        return t_ns >= self.start_ns


def segment_name(i: int) -> str:
    return FIRST if i == 0 else f"run.{i}.mcap"


def segments(run_dir: Path | str) -> list[Segment]:
    """The run's segments in order (just ``run.mcap`` for a run never resumed)."""
    run_dir = Path(run_dir)
    index = run_dir / INDEX
    if not index.exists():
        return [Segment(run_dir / FIRST, 0, None)]
    try:
        entries = json.loads(index.read_text())["segments"]
        starts = [(run_dir / e["file"], int(e["start_ns"])) for e in entries]
    except (OSError, ValueError, KeyError, TypeError) as err:
        raise CerebxError(f"{index}: not a valid segment index ({type(err).__name__}: {err})") from None
    return [Segment(p, s, starts[i + 1][1] if i + 1 < len(starts) else None) for i, (p, s) in enumerate(starts)]


def add_segment(run_dir: Path, start_ns: int) -> Path:
    """Register the next segment file (starting at simulated time ``start_ns``) and return its path."""
    run_dir = Path(run_dir)
    have = segments(run_dir)
    entries = [{"file": s.path.name, "start_ns": s.start_ns} for s in have]
    if len(entries) == 1 and not (run_dir / INDEX).exists() and not have[0].path.exists():
        raise CerebxError(f"{run_dir}: no {FIRST} to continue")
    name = segment_name(len(entries))
    entries.append({"file": name, "start_ns": int(start_ns)})
    tmp = run_dir / (INDEX + ".tmp")
    tmp.write_text(json.dumps({"segments": entries}, indent=2))
    os.replace(tmp, run_dir / INDEX)
    return run_dir / name
