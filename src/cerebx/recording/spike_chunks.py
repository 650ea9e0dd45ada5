"""The spikes messages of a simulated chunk of network steps, encoded in compiled code (``cerebx_msgs/msg/Spikes``
in CDR, the layout in ``recording/cdr.py``).

The spiking controller's network thread calls :func:`chunk_spike_messages` without the interpreter lock, right
after the chunk is simulated; the loop's thread then only logs the messages
(:meth:`~cerebx.recording.recorder.Recorder.spike_messages`). Each message is the same bytes as
:func:`~cerebx.recording.cdr.encode_spikes` gives for it (a test checks that). Kept apart from ``cdr.py`` so that
reading a log does not load numba.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from cerebx.recording.cdr import HEADER_WORD

_HEADER_WORD = np.uint32(HEADER_WORD)


@njit(cache=True, nogil=True, boundscheck=False)
def chunk_spike_messages(local, ends, first, step_s):  # pragma: no cover - numba
    """The messages of populations x steps: ``local`` and ``ends`` as :func:`~cerebx.snn.decoder.chunk_select`
    gives them (population p's step s is ``local[ends[p, s - 1]:ends[p, s]]``), the steps stamped
    ``(first + s) * step_s``. Returns the messages one after the other as 32-bit words (every message is a
    whole number of them), and where message k = p * n_steps + s starts and ends in bytes
    (``starts[k]:starts[k + 1]``)."""
    n_pop, n = ends.shape
    words = np.empty(local.size + 4 * n_pop * n, np.uint32)
    starts = np.empty(n_pop * n + 1, np.int64)
    t = np.empty(n, np.float64)
    for s in range(n):
        t[s] = (first + s) * step_s
    t_words = t.view(np.uint32)  # little endian: the low word of each double first
    m = 0
    k = 0
    begin = 0
    for p in range(n_pop):
        for s in range(n):
            end = ends[p, s]
            starts[k] = 4 * m
            k += 1
            words[m] = _HEADER_WORD
            words[m + 1] = t_words[2 * s]
            words[m + 2] = t_words[2 * s + 1]
            words[m + 3] = end - begin
            m += 4
            for i in range(begin, end):
                words[m] = local[i]
                m += 1
            begin = end
    starts[k] = 4 * m
    return words, starts
