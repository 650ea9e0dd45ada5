"""Disk and time a run will take, printed before it starts, and the limit that refuses absurd sizes.

The rates are measured, not derived (``cerebx run`` of 4 trials on the 2-core development machine, zstd
level 1 chunks of 256 kB, joint states in CDR, every step recorded; 2026-11-24):

===========================================  ======================  ==========================
run                                          run.mcap per sim. s     wall
===========================================  ======================  ==========================
planar2 + PD (``+experiment=demo``)          109 kB                  docs/guide/speed.md
Baxter + PD                                  258 kB                  docs/guide/speed.md
Baxter + SNN ``full``                        303 kB                  docs/guide/speed.md
===========================================  ======================  ==========================

hence about 25 kB/s plus 39 kB/s per joint for the joint and control channels, and 41 kB/s for the
default spike channels of an SNN (in CDR since the evening of 2026-11-24; 32 kB/s as JSON); without joint
states (``recording.joint_states=false``) a third of the
per-joint rate is kept for ``/control`` (*constructed*: one of three per-step channels). The learned SNN
state holds 4 bytes per plastic synapse and ~44 bytes per neuron before compression (``full``:
147.9 MB raw, 0.7 MB of weights once zlib-compressed after 2 trials, because most PF-PC weights stay at
their initial value); it is written compressed. Wall
time uses the real-time factors of runs with their default recording on a quiet machine (Baxter + PD
30x; a ``full``-network learning run 23x, measured 2026-11-24 evening with ``cerebx bench``'s learning runs
(23.1-24.1x), i.e. 0.033 s + 0.30 ns per plastic synapse per simulated second); a shared machine is slower.

A profile's runs share the cores (``cerebx report --jobs``), so its time is set by the CPU its runs need, not
by their quiet wall times: a spiking run keeps two threads busy (the network's and the loop's) and, beside
another run, goes at the pace of one core. Each estimate therefore also carries its CPU seconds, measured
per simulated second on the runs of the quick and full profiles made from empty folders with ``--jobs 2`` on
the 2-core development machine (2026-11-28; ``summary.json``'s ``cpu_seconds``):

===========================================  ==================================================
part of a run                                CPU
===========================================  ==================================================
loop, plant and a non-spiking controller     31 ms per simulated s (PD 31.6, LWPR 30.4, muscles 30.0)
a spiking network                            29 ms + 1.47 ns per plastic synapse per simulated s
                                             (the thesis network, 36 M: 113 ms with the loop's;
                                             chapter 4's, 4 M: 66 ms), and 50 ns per plastic
                                             synapse once (building or loading it: 1.8 s)
a plugin controller's own cost               its config class's ``cpu_per_sim_s`` (the ANN: 50 ms)
every run                                    2 s (the process, imports, composition, the plant)
===========================================  ==================================================

and :func:`total` of runs ``jobs`` at a time on :data:`CORES` cores takes the longer of their summed wall time
shared ``jobs`` ways and their summed CPU shared over the cores. (The quick profile from empty: 18.6 min
measured; 172 runs' CPU 31.0 min over 2 cores is 15.5 min plus 2 s a run.)
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

BYTES_PER_S_BASE = 25e3
BYTES_PER_S_PER_JOINT = 39e3
BYTES_PER_S_SPIKES = 41e3
STATE_BYTES_PER_PLASTIC = 4.0
STATE_BYTES_PER_NEURON = 44.0
WALL_PER_SIM_S = 0.033
WALL_PER_SIM_S_PER_PLASTIC = 0.30e-9
CPU_PER_SIM_S = 0.031
CPU_PER_SIM_S_NETWORK = 0.029
CPU_PER_SIM_S_PER_PLASTIC = 1.47e-9
CPU_PER_PLASTIC_LOAD = 50e-9
CPU_PER_RUN = 2.0
CORES = 2
"""The cores of the machine the times are given for (the development machine's and CI's)."""
DISK_MARGIN = 1.2
"""A run is refused when its estimate times this margin exceeds the free space of its folder's disk."""


@dataclass(frozen=True)
class Estimate:
    sim_s: float
    mcap_bytes: float
    state_bytes: float
    wall_s: float
    compile_s: float = 0.0
    """Of ``wall_s``: compiling numba kernels not in the cache yet (``numba_cache``; once, not per job)."""
    cpu_s: float = 0.0
    """CPU seconds of all the run's threads when it shares the cores with other runs."""
    jobs: int = 1
    """Runs at once (a :func:`total` of runs given ``jobs``)."""

    def line(self) -> str:
        state = f", learned state <= {_size(self.state_bytes)} before compression" if self.state_bytes else ""
        compiling = f" (~{duration(self.compile_s)} of it compiling numba kernels, once)" if self.compile_s else ""
        at_once = f", {self.jobs} runs at a time" if self.jobs > 1 else ""
        return (f"estimate: {self.sim_s:,.0f} s simulated, run.mcap ~{_size(self.mcap_bytes)}{state}, "
                f"~{duration(self.wall_s)} on a quiet {CORES}-core machine{at_once}{compiling}")

    def with_compiling(self, seconds: float) -> Estimate:
        """This estimate with ``seconds`` of compiling added to its wall time."""
        return replace(self, wall_s=self.wall_s + seconds, compile_s=self.compile_s + seconds)


def _size(b: float) -> str:
    for unit, f in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if b >= f:
            return f"{b / f:,.1f} {unit}"
    return f"{b:.0f} B"


def duration(s: float) -> str:
    """A duration in seconds as people read it (days, h, min or s)."""
    if s >= 86400:
        return f"{s / 86400:,.1f} days"
    if s >= 3600:
        return f"{s / 3600:.1f} h"
    if s >= 60:
        return f"{s / 60:.0f} min"
    return f"{s:.0f} s"


def _parts(exp: Any) -> list[Any]:
    """The controller, or the parts of a composite one."""
    c = exp.controller
    return list(c.parts) if c.kind == "composite" else [c]


def _network_parts(exp: Any) -> list[Any]:
    """The controller parts that run a spiking network (a ``network`` field)."""
    return [p for p in _parts(exp) if getattr(p, "network", None) is not None]


def estimate(exp: Any) -> Estimate:
    """The estimate of one validated experiment."""
    sim_s = exp.trials * exp.task.period_s
    n = exp.plant.n_joints
    per_joint = BYTES_PER_S_PER_JOINT if exp.recording.joint_states else BYTES_PER_S_PER_JOINT / 3
    per_s = BYTES_PER_S_BASE + per_joint * n
    per_s /= exp.recording.decimation
    snn = _network_parts(exp)
    plastic = sum(p.network.n_plastic for p in snn)
    if any(getattr(p, "record_spikes", None) for p in snn):
        per_s += BYTES_PER_S_SPIKES
    window = exp.recording.trials
    if window is not None:  # the step channels of the held trials only (the per-trial messages are negligible)
        per_s *= len(window.trials(exp.trials)) / exp.trials
    neurons = sum(p.network.n_neurons for p in snn)
    state = STATE_BYTES_PER_PLASTIC * plastic + STATE_BYTES_PER_NEURON * neurons if exp.recording.save_state else 0.0
    own = sum(float(getattr(type(p), "cpu_per_sim_s", 0.0)) for p in _parts(exp))  # plugin controllers' cost
    cpu = (CPU_PER_RUN + sim_s * (CPU_PER_SIM_S + own + CPU_PER_SIM_S_NETWORK * len(snn)
                                  + CPU_PER_SIM_S_PER_PLASTIC * plastic) + CPU_PER_PLASTIC_LOAD * plastic)
    wall = CPU_PER_RUN + sim_s * (WALL_PER_SIM_S + own + WALL_PER_SIM_S_PER_PLASTIC * plastic)
    return Estimate(sim_s, per_s * sim_s, state, max(wall, cpu / CORES), cpu_s=cpu)


def free_bytes(folder: Path) -> int:
    """Free space of the disk ``folder`` would be on (its nearest existing ancestor)."""
    p = Path(folder).absolute()
    while not p.exists():
        p = p.parent
    return shutil.disk_usage(p).free


def disk_problem(total_bytes: float, folder: Path, what: str) -> str | None:
    """One line when ``total_bytes`` (with a margin) does not fit on ``folder``'s disk."""
    free = free_bytes(folder)
    if total_bytes * DISK_MARGIN > free:
        return (f"{what}: needs ~{_size(total_bytes)} but {folder} has {_size(free)} free; lower trials or "
                "record less (recording.decimation=N, recording.joint_states=false)")
    return None


def total(parts: list[Estimate], jobs: int = 1) -> Estimate:
    """The estimate of ``parts`` run ``jobs`` at a time on a quiet :data:`CORES`-core machine: the longer of
    their wall times shared ``jobs`` ways and their CPU shared over the cores (one at a time: their summed
    wall time, as a sweep's launcher runs them)."""
    jobs = max(1, jobs)
    s = {f: sum(getattr(e, f) for e in parts) for f in ("sim_s", "mcap_bytes", "state_bytes", "wall_s", "cpu_s")}
    wall = max(s["wall_s"] / jobs, s["cpu_s"] / CORES) if jobs > 1 else s["wall_s"]
    return Estimate(s["sim_s"], s["mcap_bytes"], s["state_bytes"], wall, cpu_s=s["cpu_s"], jobs=jobs)
