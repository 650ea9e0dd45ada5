"""The link's shared key, the session keys derived from it, and packet authentication (HMAC-SHA256,
truncated to 16 bytes).

The key never comes from the configuration and is never logged or written to a run folder. It is
read from the file named by ``CEREBX_LINK_KEY_FILE`` (a regular file of at most 4 KiB; one that others
may read gets a warning) or from ``CEREBX_LINK_KEY`` itself (at least 16 bytes either way; ``openssl
rand -hex 32 > link.key`` makes a good one). When ``cerebx run`` starts the robot side itself and no
key is set, it makes a random key for the run and hands it over the child's stdin pipe.

The shared key (the *pairing key*) signs only the handshake (HELLO, WELCOME, REFUSE). Every later
packet is signed with a session key both sides derive from it and from a fresh nonce of each side
(:meth:`Signer.session`, HKDF-SHA256 of RFC 5869), so a recorded session cannot be replayed into
another one.
"""

from __future__ import annotations

import hashlib
import hmac
import os
import secrets
import stat
import sys
from collections.abc import Mapping
from pathlib import Path

from cerebx.errors import CerebxError

KEY_ENV = "CEREBX_LINK_KEY"
KEY_FILE_ENV = "CEREBX_LINK_KEY_FILE"
MIN_KEY_BYTES = 16
MAX_KEY_FILE_BYTES = 4096
TAG_BYTES = 16
NONCE_BYTES = 16
SESSION_INFO = b"cerebx link session v2"


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

    def session(self, brain_nonce: bytes, robot_nonce: bytes, run_id: bytes) -> Signer:
        """The session key of one pairing: HKDF-SHA256 (RFC 5869) with this key as input keying material,
        both sides' nonces as salt and the run id in the info."""
        prk = hmac.new(brain_nonce + robot_nonce, self._key, hashlib.sha256).digest()
        return Signer(hmac.new(prk, SESSION_INFO + run_id + b"\x01", hashlib.sha256).digest())

    def hex(self) -> str:
        """The key as hex text, for the private channel to a child process this run starts."""
        return self._key.hex()

    def __repr__(self) -> str:
        return "Signer(<key hidden>)"


def key_from_env(env: Mapping[str, str] | None = None) -> Signer | None:
    """The key set in the environment (file first), or None when neither variable is set."""
    env = os.environ if env is None else env
    path = env.get(KEY_FILE_ENV, "")
    if path:
        return Signer(_unhex(read_key_file(Path(path))))
    value = env.get(KEY_ENV, "")
    return Signer(_unhex(value.encode())) if value else None


def read_key_file(path: Path) -> bytes:
    """The bytes of a key file: a regular file (not a device, FIFO or folder) of at most
    :data:`MAX_KEY_FILE_BYTES`; a file that others than its owner may read is used with a warning."""
    where = f"{KEY_FILE_ENV}: {path}"
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError as err:
        raise CerebxError(f"{where}: cannot be read ({err.strerror})") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise CerebxError(f"{where}: not a regular file")
        if st.st_size > MAX_KEY_FILE_BYTES:
            raise CerebxError(f"{where}: {st.st_size} bytes; a key file holds at most {MAX_KEY_FILE_BYTES}")
        raw = os.read(fd, MAX_KEY_FILE_BYTES + 1)
    except OSError as err:
        raise CerebxError(f"{where}: cannot be read ({err.strerror})") from None
    finally:
        os.close(fd)
    if len(raw) > MAX_KEY_FILE_BYTES:
        raise CerebxError(f"{where}: more than {MAX_KEY_FILE_BYTES} bytes")
    if st.st_mode & 0o077:
        print(f"warning: {where}: others may read it (mode {stat.S_IMODE(st.st_mode):04o}); chmod 600 it",
              file=sys.stderr)
    return raw.strip()


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


def new_nonce() -> bytes:
    return secrets.token_bytes(NONCE_BYTES)
