"""Time for the two sides of a wall-clock run: the monotonic clock, pacing onto tick deadlines, and the
offset between the two sides' clocks.

On one host both sides read the same ``CLOCK_MONOTONIC`` (one kernel boot: the same ``boot_id``, network
namespaces included), so a message's one-way delay is its arrival time minus its send time. Across hosts
the brain side estimates the offset (robot clock - brain clock) by a ping exchange: for each probe sent
at t1 (brain), received at t2 and answered at t3 (robot), back at t4 (brain), offset = ((t2 - t1) +
(t3 - t4)) / 2 and the round trip = (t4 - t1) - (t3 - t2); of a burst the probe with the shortest round
trip wins, and half its round trip bounds the error (the uncertainty recorded with each estimate).
"""

from __future__ import annotations

import ctypes
import os
import socket
import struct
import sys
import time
from dataclasses import dataclass
from pathlib import Path

now_ns = time.monotonic_ns


def host_identity() -> dict[str, str]:
    """What tells whether two processes share one monotonic clock: the kernel's boot id (and the host name)."""
    try:
        boot = Path("/proc/sys/kernel/random/boot_id").read_text().strip()
    except OSError:
        boot = ""
    return {"boot_id": boot, "host": socket.gethostname()}


def pace(deadline_ns: int, spin_ns: int) -> int:
    """Sleep until ``spin_ns`` before ``deadline_ns``, then spin to it; returns the time it woke (ns)."""
    t = now_ns()
    rest = deadline_ns - t - spin_ns
    if rest > 0:
        time.sleep(rest / 1e9)
    t = now_ns()
    while t < deadline_ns:
        time.sleep(0)  # lets the transport's threads take the interpreter lock while we spin
        t = now_ns()
    return t


SWITCH_INTERVAL_S = 1e-4


RANK = {"robot": 0, "relay": 1, "brain": 2}
"""Real-time priority below ``link.rt_priority`` per process: the paced robot side first, then the relay
(whose wake-ups add to the delays), then the brain side (which has the pathway delay's slack)."""


def host_steal_ms() -> float:
    """CPU time the hypervisor took from this machine since boot, ms (0 where the kernel does not say)."""
    try:
        fields = Path("/proc/stat").read_text().split("\n", 1)[0].split()
        return float(fields[8]) * 1000.0 / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return 0.0


SHORT_SLICE_NS = 100_000
"""The time slice the robot side and the relay ask the fair scheduler for (its shortest)."""
_SCHED_SETATTR = {"x86_64": 314, "aarch64": 274}  # syscall numbers
_SCHED_ATTR = struct.Struct("<IIQiIQQQII")  # size, policy, flags, nice, priority, runtime, deadline, period, util


def short_slices(slice_ns: int = SHORT_SLICE_NS) -> bool:
    """Ask the kernel's fair scheduler for time slices of ``slice_ns`` for this thread and the threads it starts
    later (``sched_setattr`` with ``sched_runtime``: EEVDF's slice request, Linux 6.12 on; normal policy, same
    nice, no privilege). A thread with a shorter slice than the one running preempts it when it wakes, where it
    would otherwise wait in the run queue for that slice to end (1.4 ms on two cores); its share of the CPU is
    unchanged. False where the kernel refuses it (older kernels accept and ignore it)."""
    nr = _SCHED_SETATTR.get(os.uname().machine) if sys.platform == "linux" else None
    if nr is None:
        return False
    try:
        attr = _SCHED_ATTR.pack(_SCHED_ATTR.size, os.SCHED_OTHER, 0, os.getpriority(os.PRIO_PROCESS, 0), 0, slice_ns,
                                0, 0, 0, 0)
        return ctypes.CDLL(None, use_errno=True).syscall(nr, 0, ctypes.create_string_buffer(attr), 0) == 0
    except (OSError, AttributeError):
        return False


def realtime_process(priority: int, role: str = "robot") -> str | None:
    """Prepare this process for a paced loop: threads take turns at the interpreter lock every 0.1 ms (not
    5 ms), so the transport's threads that receive packets do not wait for a tick to finish; with
    ``priority`` > 0 the process (and the threads it starts later) runs under the kernel's real-time
    ``SCHED_FIFO`` policy at that priority less its ``role``'s :data:`RANK`; under the normal policy (no
    priority asked, or not granted) the robot side and the relay ask for short time slices
    (:func:`short_slices`), so that a wake-up on time is not held in the run queue by other jobs. Returns why
    the priority could not be had, or None."""
    sys.setswitchinterval(SWITCH_INTERVAL_S)
    why = None
    if priority > 0:
        priority = max(1, priority - RANK[role])
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
            return None
        except (AttributeError, OSError) as err:
            why = (f"real-time priority {priority} not granted ({getattr(err, 'strerror', None) or err}); running "
                   "with normal scheduling")
    if role != "brain":
        short_slices()
    return why


@dataclass(frozen=True)
class OffsetEstimate:
    """Robot clock minus brain clock (ns), with its error bound and when it was made (brain clock)."""

    offset_ns: int
    uncertainty_ns: int
    at_ns: int
    probes: int
    method: str  # "shared" | "ping"


def estimate(probes: list[tuple[int, int, int, int]], at_ns: int) -> OffsetEstimate | None:
    """The offset from probes (t1, t2, t3, t4); None without any probe."""
    best = None
    for t1, t2, t3, t4 in probes:
        rtt = (t4 - t1) - (t3 - t2)
        if rtt < 0:
            continue
        if best is None or rtt < best[0]:
            best = (rtt, ((t2 - t1) + (t3 - t4)) // 2)
    if best is None:
        return None
    return OffsetEstimate(best[1], best[0] // 2 + 1, at_ns, len(probes), "ping")


def shared(at_ns: int) -> OffsetEstimate:
    return OffsetEstimate(0, 0, at_ns, 0, "shared")
