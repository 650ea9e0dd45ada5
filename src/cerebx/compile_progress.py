"""Progress of numba compiling a run's kernels, for a run whose kernels are not in the cache yet
(``cerebx.numba_cache``): a line every few seconds, above the run's progress bar."""

from __future__ import annotations

import sys
import time

from numba.core import event
from tqdm import tqdm


class CompileProgress(event.Listener):
    """Counts the cerebx kernels numba compiles (its ``numba:compile`` events; loads from the cache are none)."""

    def __init__(self, expected: int, every_s: float = 5.0):
        self.expected, self.every_s = expected, every_s
        self.done, self.started, self.written = 0, 0.0, 0.0

    def on_start(self, ev: event.Event) -> None:
        if not self.started:
            self.started = self.written = time.perf_counter()

    def on_end(self, ev: event.Event) -> None:
        func = getattr(ev.data.get("dispatcher"), "py_func", None)
        if not (getattr(func, "__module__", None) or "").startswith("cerebx"):
            return  # numba's own helpers, compiled inside a kernel
        self.done += 1
        now = time.perf_counter()
        if now - self.written >= self.every_s:
            self.written = now
            tqdm.write(f"numba: {self.done} of ~{self.expected} kernels compiled ({now - self.started:.0f} s)",
                       file=sys.stderr)


def show_progress(expected: int) -> CompileProgress:
    """Report the compiling of about ``expected`` kernels in this process from now on."""
    listener = CompileProgress(expected)
    event.register("numba:compile", listener)
    return listener
