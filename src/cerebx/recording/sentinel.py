"""A run's sentinel: a small process that outlives a hard-killed run and finishes its files.

SIGKILL or an OOM kill leaves ``run.mcap`` without its summary and footer (the standard seeking MCAP
reader refuses such a file) and ``summary.json`` saying ``running``. The runner starts this process
with a pipe; a run that ends normally says so on the pipe. If the pipe closes without that word, the
run's process is gone: the sentinel cuts ``run.mcap`` after its last complete record, appends a data
end and a footer without summary (every MCAP reader then reads it front to back, up to the last chunk
that reached the disk) and marks the summary ``killed``. Power loss kills the sentinel too; readers
then tell a killed run by its dead process (``summary.is_killed``) and read the log by scanning.

Standard library only, so it starts in a few tens of milliseconds.
"""

from __future__ import annotations

import json
import os
import struct
import subprocess
import sys
from pathlib import Path

from cerebx import runfiles
from cerebx.errors import CerebxError
from cerebx.recording.segments import segments

MAGIC = b"\x89MCAP0\r\n"
_DATA_END = 0x0F
_FOOTER = 0x02
_DONE = b"done\n"


def complete_length(path: Path) -> int | None:
    """Bytes of ``path`` that hold whole records (magic first); None if it is not an MCAP file."""
    size = path.stat().st_size
    with open(path, "rb") as fh:
        if fh.read(len(MAGIC)) != MAGIC:
            return None
        end = len(MAGIC)
        while True:
            head = fh.read(9)
            if len(head) < 9:
                return end
            opcode, length = struct.unpack("<BQ", head)
            if end + 9 + length > size:
                return end
            if opcode == _FOOTER:
                return end  # a footer is the end (what follows is the closing magic)
            fh.seek(length, os.SEEK_CUR)
            end += 9 + length


def ends_cleanly(path: Path) -> bool:
    """Whether the file ends in a footer and the closing magic (closed by its writer or already sealed)."""
    size = path.stat().st_size
    if size < 2 * len(MAGIC) + 9 + 20:
        return False
    with open(path, "rb") as fh:
        fh.seek(size - len(MAGIC) - 29)
        tail = fh.read()
    return tail[-len(MAGIC):] == MAGIC and tail[0] == _FOOTER


def seal(path: Path) -> bool:
    """Finish an MCAP file whose writer died: keep its whole records, add data end + footer + magic.
    Returns whether anything was changed."""
    path = Path(path)
    if not path.exists() or ends_cleanly(path):
        return False
    n = complete_length(path)
    if n is None:
        return False
    data_end = struct.pack("<BQI", _DATA_END, 4, 0)
    footer = struct.pack("<BQQQI", _FOOTER, 20, 0, 0, 0)  # no summary section
    with open(path, "r+b") as fh:
        fh.truncate(n)
        fh.seek(n)
        fh.write(data_end + footer + MAGIC)
    return True


def mark_killed(run_dir: Path) -> None:
    """Set a ``running`` summary to ``killed`` (written atomically, other keys kept)."""
    path = run_dir / runfiles.SUMMARY
    try:
        s = json.loads(path.read_text())
    except (OSError, ValueError):
        return
    if not isinstance(s, dict) or s.get("status") != "running":
        return
    s["status"] = "killed"
    done = s.get("trials_completed") or 0
    s["error"] = f"the process was killed (SIGKILL or OOM kill) after {done} of {s.get('trials')} trials"
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(s, indent=2))
    os.replace(tmp, path)


class Sentinel:
    """Held by the runner while a run is under way; ``done()`` when the run has finished its files."""

    def __init__(self, run_dir: Path):
        self._proc = subprocess.Popen(
            [sys.executable, "-m", "cerebx.recording.sentinel", str(run_dir)], stdin=subprocess.PIPE,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
            env={**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)})

    def done(self) -> None:
        try:
            assert self._proc.stdin is not None
            self._proc.stdin.write(_DONE)
            self._proc.stdin.close()
            self._proc.wait(timeout=10)
        except (OSError, subprocess.TimeoutExpired):
            self._proc.kill()


def _watch(run_dir: Path) -> int:
    word = sys.stdin.buffer.read()  # blocks until the run closes the pipe, by done() or by dying
    if word == _DONE:
        return 0
    try:
        files = [seg.path for seg in segments(run_dir)]  # a resumed run writes into its last segment
    except CerebxError:
        files = [run_dir / runfiles.MCAP]
    for path in files:
        seal(path)
    mark_killed(run_dir)
    return 0


if __name__ == "__main__":
    sys.exit(_watch(Path(sys.argv[1])))
