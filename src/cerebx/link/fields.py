"""The JSON fields of every control packet kind, checked before any side uses one.

Each kind has a table of its fields: whether one must be there, its type, its range, its length. A
packet whose field breaks its rule is refused (``bad_field``), counted and dropped, like any other
refused packet; fields a kind does not list are dropped unread, so a newer peer may add some. What a
side reads of a packet is then of the type it expects: an ``int`` in range, a finite ``float``, a short
string, a list of finite numbers.

=========  ======  =========================================================================
kind       from    fields
=========  ======  =========================================================================
HELLO      brain   fingerprint, version, nonce (its fresh nonce, hex), controller facts,
                   boot_id, host
WELCOME    robot   fingerprint, nonce (the robot's fresh nonce), answers (the HELLO's nonce),
                   boot_id, host
REFUSE     robot   fingerprint, version, answers
START      both    brain: offset_ns; robot: t0_ns (tick 0 on its clock)
PING       brain   n (probes left in the burst), burst, offset_ns (the current estimate)
PONG       robot   ping (the PING's sequence number), burst, t2 (its arrival here)
TRIAL      robot   the trial's metrics (trial, mae, mae_per_joint, ...) and label
BYE        both    status, reason; the robot side's timing, packet counts and events
=========  ======  =========================================================================
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from typing import Any

from cerebx.link.wire import Kind, WireError

Check = Callable[[Any], Any]

NS_LIMIT = 2**62
_HEX = re.compile(r"^[0-9a-f]*$")


def _bad(what: str) -> WireError:
    return WireError("bad_field", what)


def integer(lo: int, hi: int) -> Check:
    def check(v: Any) -> int:
        if type(v) is not int or not lo <= v <= hi:
            raise _bad(f"an integer in [{lo}, {hi}]")
        return v
    return check


def number(lo: float, hi: float) -> Check:
    def check(v: Any) -> float:
        ok = (type(v) is int and lo <= v <= hi) or (type(v) is float and math.isfinite(v) and lo <= v <= hi)
        if not ok:
            raise _bad(f"a finite number in [{lo}, {hi}]")
        return float(v)
    return check


def text(max_len: int) -> Check:
    def check(v: Any) -> str:
        if not isinstance(v, str) or len(v) > max_len:
            raise _bad(f"a string of at most {max_len} characters")
        return v
    return check


def hex_bytes(n: int) -> Check:
    def check(v: Any) -> bytes:
        if not isinstance(v, str) or len(v) != 2 * n or not _HEX.match(v):
            raise _bad(f"{n} bytes as lower-case hex")
        return bytes.fromhex(v)
    return check


def numbers(max_len: int, lo: float = -1e12, hi: float = 1e12) -> Check:
    item = number(lo, hi)

    def check(v: Any) -> list[float]:
        if not isinstance(v, list) or len(v) > max_len:
            raise _bad(f"a list of at most {max_len} numbers")
        return [item(x) for x in v]
    return check


def optional(inner: Check) -> Check:
    def check(v: Any) -> Any:
        return None if v is None else inner(v)
    return check


def one_of(*values: str) -> Check:
    def check(v: Any) -> str:
        if v not in values:
            raise _bad(f"one of {', '.join(values)}")
        return v
    return check


def json_object(v: Any) -> dict[str, Any]:
    """Any JSON object (its depth is already bounded by the wire format): kept as it came, to be written."""
    if not isinstance(v, dict):
        raise _bad("a JSON object")
    return v


def json_list(max_len: int) -> Check:
    def check(v: Any) -> list[Any]:
        if not isinstance(v, list) or len(v) > max_len:
            raise _bad(f"a list of at most {max_len} items")
        return v
    return check


def controller_facts(v: Any) -> dict[str, Any]:
    if not isinstance(v, dict):
        raise _bad("controller facts: a JSON object")
    bounds = v.get("position_bounds")
    if bounds is None:
        return {}
    if not isinstance(bounds, list) or len(bounds) != 2:
        raise _bad("position_bounds: [lower, upper]")
    lo, hi = (numbers(64, -1e6, 1e6)(b) for b in bounds)
    if len(lo) != len(hi):
        raise _bad("position_bounds: lower and upper of one length")
    return {"position_bounds": [lo, hi]}


STATUSES = ("completed", "interrupted", "diverged", "failed", "killed", "running")
NS = integer(0, NS_LIMIT)
FINGERPRINT = text(64)
HOST = {"boot_id": text(64), "host": text(255)}
METRIC = number(0.0, 1e12)

SPECS: dict[Kind, dict[str, tuple[bool, Check]]] = {
    Kind.HELLO: {"fingerprint": (True, FINGERPRINT), "version": (False, text(64)), "nonce": (True, hex_bytes(16)),
                 "controller": (False, controller_facts), **{k: (False, c) for k, c in HOST.items()}},
    Kind.WELCOME: {"fingerprint": (True, FINGERPRINT), "nonce": (True, hex_bytes(16)),
                   "answers": (True, hex_bytes(16)), **{k: (False, c) for k, c in HOST.items()}},
    Kind.REFUSE: {"fingerprint": (True, FINGERPRINT), "version": (False, text(64)),
                  "answers": (True, hex_bytes(16))},
    Kind.START: {"offset_ns": (False, integer(-NS_LIMIT, NS_LIMIT)), "t0_ns": (False, NS)},
    Kind.PING: {"n": (True, integer(0, 1 << 16)), "burst": (True, integer(0, NS_LIMIT)),
                "offset_ns": (False, integer(-NS_LIMIT, NS_LIMIT))},
    Kind.PONG: {"ping": (True, integer(0, 2**64 - 1)), "burst": (True, integer(0, NS_LIMIT)), "t2": (True, NS)},
    Kind.TRIAL: {"trial": (True, integer(0, 10**7)), "mae": (True, METRIC), "mae_per_joint": (True, numbers(64, 0)),
                 "vel_mae": (True, METRIC), "torque_variability_Nm_per_ms": (True, METRIC),
                 "ee_error_m": (False, optional(METRIC)), "label": (False, optional(text(200)))},
    Kind.BYE: {"status": (True, one_of(*STATUSES)), "reason": (False, optional(text(2000))),
               "trials_completed": (False, integer(0, 10**7)), "wall_seconds": (False, optional(number(0, 1e9))),
               "ticks": (False, integer(0, 2**62)), "timing": (False, optional(json_object)),
               "packets": (False, optional(json_object)), "events": (False, optional(json_list(100)))},
}


def check(kind: Kind, info: dict[str, Any]) -> dict[str, Any]:
    """The fields of ``kind`` that ``info`` holds, each checked (raises ``WireError('bad_field')``)."""
    spec = SPECS.get(kind)
    if spec is None:
        return {}
    out: dict[str, Any] = {}
    for name, (required, rule) in spec.items():
        if name not in info:
            if required:
                raise _bad(f"{kind.name}: {name} missing")
            continue
        try:
            out[name] = rule(info[name])
        except WireError as err:
            raise _bad(f"{kind.name}.{name}: {err}") from None
    return out
