"""Learned-state files (``controller_state.npz``) shared by the learning controllers: written
atomically (a crash never leaves a half-written state), read back with a one-line error."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from cerebx.errors import StateMismatchError


def save_state_npz(path: Path, meta: dict[str, Any], **arrays: np.ndarray) -> None:
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    with open(tmp, "wb") as f:
        np.savez_compressed(f, meta=np.array(json.dumps(meta)), **arrays)  # lossless; most weights repeat
    tmp.replace(path)


def load_state_npz(path: Path, what: str) -> tuple[Any, dict[str, Any]]:
    """(the npz mapping, its metadata); any unreadable file gives the same one-line error."""
    try:
        data = np.load(Path(path), allow_pickle=False)
        return data, json.loads(str(data["meta"]))
    except Exception as exc:  # noqa: BLE001
        raise StateMismatchError(f"{path}: not a readable cerebx {what} state ({type(exc).__name__})") from None
