"""``init_from`` checked at validation: every state file the run would load is opened, read through
(a truncated or corrupt file fails here, not after the run folder exists) and matched to the controller
it starts. An SNN state must carry the structure fingerprint of this experiment's network, computed
from the network config alone (``snn.topology.structure_fingerprint``, no network is built)."""

from __future__ import annotations

import functools
from pathlib import Path
from typing import Any

STATE_FILE = "controller_state.npz"


@functools.lru_cache(maxsize=64)
def _read_meta(path: str, mtime_ns: int, size: int) -> tuple[dict[str, Any] | None, str | None]:
    """(metadata, problem) of a state file; every array is read so a damaged archive shows now."""
    import json

    import numpy as np

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
    from cerebx.stages.controllers import Composite

    state = init_from / STATE_FILE
    if controller.kind == "composite":
        return [(f"controller.parts.{i}", p, part) for i, part in enumerate(controller.parts)
                if (p := Composite.part_path(state, i)).exists()]
    return [("controller", state, controller)]


def _mismatch(meta: dict[str, Any], part: Any, exp: Any) -> str | None:
    if part.kind == "snn":
        from cerebx.snn.topology import structure_fingerprint

        saved, want = meta.get("fingerprint"), structure_fingerprint(exp.network)
        if saved is None:
            return f"is not an SNN state (saved by a {meta.get('kind', 'different')!r} controller)"
        if saved != want:
            return (f"was saved from network {meta.get('network')!r} (fingerprint {saved}), but this run's network "
                    f"{exp.network.name!r} has fingerprint {want}: sizes or connections differ")
    elif part.kind == "ann" and meta.get("kind") != "ann":
        return "is not an ANN state (saved by another controller)"
    elif meta.get("kind") not in (None, part.kind):
        return f"was saved by a {meta['kind']!r} controller"
    return None


def init_from_problems(exp: Any) -> list[str]:
    """One ``init_from: ...`` line per problem of the states this experiment would start from."""
    if exp.init_from is None:
        return []
    root = Path(exp.init_from)
    state = root / STATE_FILE
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
            why = _mismatch(meta, part, exp)
            problem = None if why is None else f"{path} {why} ({where} is {part.kind!r})"
        if problem:
            problems.append(f"init_from: {problem}")
    return problems
