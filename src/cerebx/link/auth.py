"""The link's shared key and packet authentication (HMAC-SHA256, truncated to 16 bytes).

The key never comes from the configuration and is never logged or written to a run folder. It is
read from the file named by ``CEREBX_LINK_KEY_FILE`` or from ``CEREBX_LINK_KEY`` itself (at least
16 bytes either way; ``openssl rand -hex 32 > link.key`` makes a good one). When ``cerebx run``
starts the robot side and the relay itself and no key is set, it makes a random key for the run and
hands it to them in their environment.
"""

from __future__ import annotations

import hashlib
import hmac
import os
import secrets
from collections.abc import Mapping
from pathlib import Path

from cerebx.errors import CerebxError

KEY_ENV = "CEREBX_LINK_KEY"
KEY_FILE_ENV = "CEREBX_LINK_KEY_FILE"
MIN_KEY_BYTES = 16
TAG_BYTES = 16


class Signer:
    """Signs and checks packets with one key. Its ``repr`` never shows the key."""

    __slots__ = ("_key",)

    def __init__(self, key: bytes):
        if len(key) < MIN_KEY_BYTES:
            raise CerebxError(f"link key: {len(key)} bytes, at least {MIN_KEY_BYTES} are needed")
        self._key = bytes(key)

    def tag(self, data: bytes) -> bytes:
        return hmac.new(self._key, data, hashlib.sha256).digest()[:TAG_BYTES]

    def verify(self, data: bytes | memoryview, tag: bytes | memoryview) -> bool:
        return hmac.compare_digest(self.tag(bytes(data)), bytes(tag))

    def env(self) -> dict[str, str]:
        """The environment that hands this key to a child process."""
        return {KEY_ENV: self._key.hex(), KEY_FILE_ENV: ""}

    def __repr__(self) -> str:
        return "Signer(<key hidden>)"


def key_from_env(env: Mapping[str, str] | None = None) -> Signer | None:
    """The key set in the environment (file first), or None when neither variable is set."""
    env = os.environ if env is None else env
    path = env.get(KEY_FILE_ENV, "")
    if path:
        try:
            key = Path(path).read_bytes().strip()
        except OSError as err:
            raise CerebxError(f"{KEY_FILE_ENV}: {path}: cannot be read ({err.strerror})") from None
        return Signer(_unhex(key))
    value = env.get(KEY_ENV, "")
    return Signer(_unhex(value.encode())) if value else None


def _unhex(raw: bytes) -> bytes:
    """A key written as hex text (as ``openssl rand -hex``) is used as the bytes it spells."""
    try:
        return bytes.fromhex(raw.decode("ascii")) if len(raw) % 2 == 0 else raw
    except (UnicodeDecodeError, ValueError):
        return raw


def require_key(env: Mapping[str, str] | None = None) -> Signer:
    """The key from the environment, or one line saying how to set it."""
    signer = key_from_env(env)
    if signer is None:
        raise CerebxError(f"link: no key; set {KEY_FILE_ENV}=PATH (a file made with `openssl rand -hex 32`) or "
                          f"{KEY_ENV} on both sides")
    return signer


def new_key() -> Signer:
    """A random key for one run whose sides this process starts itself."""
    return Signer(secrets.token_bytes(32))
