"""``init_from`` checked at validation: every state file the run would load is opened, read through
(a truncated or corrupt file fails here, not after the run folder exists) and matched to the controller
it starts by that controller kind's ``state_problems`` hook (an SNN state, for example, must carry the
structure fingerprint of this experiment's network, computed from the config alone)."""

from __future__ import annotations

import functools
import json
from pathlib import Path
from typing import Any

import numpy as np

from cerebx import runfiles


@functools.lru_cache(maxsize=64)
def _read_meta(path: str, mtime_ns: int, size: int) -> tuple[dict[str, Any] | None, str | None]:
    """(metadata, problem) of a state file; every array is read so a damaged archive shows now."""
    try:
        with np.load(path, allow_pickle=False) as data:
            for name in data.files:
                data[name]
            meta = json.loads(str(data["meta"])) if "meta" in data.files else {}
    except Exception as exc:  # noqa: BLE001 - zip, npy header, CRC, JSON: all mean the same to the user
        return None, f"{path}: not a readable cerebx state ({type(exc).__name__})"
    if not isinstance(meta, dict):
        return None, f"{path}: not a readable cerebx state (metadata is not a mapping)"
    return meta, None


def _files(init_from: Path, controller: Any) -> list[tuple[str, Path, Any]]:
    """(config path, state file, controller part) of every state the run would load."""
    if controller.kind == "composite":
        return [(f"controller.parts.{i}", p, part) for i, part in enumerate(controller.parts)
                if (p := init_from / runfiles.part_state(runfiles.STATE, i)).exists()]
    return [("controller", init_from / runfiles.STATE, controller)]


def init_from_problems(exp: Any) -> list[str]:
    """One ``init_from: ...`` line per problem of the states this experiment would start from."""
    if exp.init_from is None:
        return []
    root = Path(exp.init_from)
    state = root / runfiles.STATE
    if not state.is_file():
        return [f"init_from: {state} does not exist (give a run folder that saved its state)"]
    problems = []
    for where, path, part in _files(root, exp.controller):
        try:
            st = path.stat()
        except OSError as err:
            problems.append(f"init_from: {path}: {err.strerror}")
            continue
        meta, problem = _read_meta(str(path), st.st_mtime_ns, st.st_size)
        if problem is None:
            why = part.state_problems(meta, exp)
            problem = None if why is None else f"{path} {why} ({where} is {part.kind!r})"
        if problem:
            problems.append(f"init_from: {problem}")
    return problems
