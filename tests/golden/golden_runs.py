"""Golden runs: three fixed-seed experiments (PD, the small SNN, the small SNN with a gamma delay through the
future/past receiver), kept in two tiers.

- **metrics** (portable): every per-trial metric of summary.json and the message count per channel. Compared
  with a tolerance that numerical noise of another CPU, numpy or numba version stays inside
  (``RTOL``/``ATOL``): the physics and the network differ there in the last bits (fastmath kernels, SIMD),
  which moves a spike now and then, not a learning curve.
- **digest** (same platform): the sha256 of every recorded message's canonical JSON. Bit-identical only on
  the platform that made it (``platform`` below: CPU model and library versions); elsewhere it is skipped,
  and there a metrics failure is the one that counts.

Regenerate (only in a commit that changes results on purpose, and say so):
    .venv/bin/python tests/golden/golden_runs.py
"""

from __future__ import annotations

import hashlib
import json
import platform
import sys
from pathlib import Path

import orjson

HERE = Path(__file__).resolve().parent
GOLDEN = HERE / "runs.json"

# name -> overrides; small enough for `make test`, covering PD, the SNN, and the SNN with a gamma
# delay through the future/past filter (stamped torques)
RUNS: dict[str, list[str]] = {
    "pd_circle": ["+task=circle", "controller=pd", "trials=2", "seed=3", "plant.sensor_noise_rad=0.0005"],
    "snn_small_circle": ["+task=circle", "+experiment=small_snn", "trials=2", "seed=5"],
    "snn_small_gamma45_future_past": ["+task=circle", "+experiment=small_snn", "controller=snn_delays",
                                      "controller.mf.fibers_per_signal=5",
                                      "controller.decoder.alpha_Nm_per_spike=[7.5,11.0,3.75,6.3,0.78,0.78]",
                                      "delay=gamma45", "trials=2", "seed=11"],
}

# summary fields that depend on the machine (clock, process), not on the simulation
WALL_CLOCK = {"wall_seconds", "rt_factor", "cpu_seconds", "started_at", "controller_info", "pid", "host"}
# per-trial metrics (lists) compared with a tolerance; every other summary field must be equal
METRICS = ("mae_per_trial", "mae_per_joint_per_trial", "vel_mae_per_trial", "torque_variability_per_trial",
           "ee_error_per_trial", "final_mae")
RTOL, ATOL = 0.05, 1e-4
"""5 % (or 1e-4 absolute) per value: wide enough for a few spikes that move by a substep, narrow enough that a
change of model, gain, delay or seed shows (those move these metrics by tens of percent)."""


def this_platform() -> dict[str, str]:
    """What the exact digests depend on, the CPU that numba compiles for among them (two hosts that both
    call themselves "AMD EPYC" can be different generations: numba's code for one rounds differently)."""
    import llvmlite.binding
    import mujoco
    import numba
    import numpy

    cpu = ""
    try:
        cpu = next((ln.split(":", 1)[1].strip() for ln in Path("/proc/cpuinfo").read_text().splitlines()
                    if ln.startswith("model name")), "")
    except OSError:
        pass
    # not the vector width (cerebx.vectors): the kernels divide exactly, and 256 and 512 give the same bits
    # (tests/cerebx/test_vectors.py)
    return {"machine": platform.machine(), "cpu": cpu or platform.processor(), "python": platform.python_version(),
            "numpy": numpy.__version__, "numba": numba.__version__, "mujoco": mujoco.__version__,
            "llvm_cpu": llvmlite.binding.get_host_cpu_name()}


def digest(run_dir: Path) -> dict:
    """Per-topic message count and sha256 of the canonical JSON of (time, message), plus the summary's
    simulation fields."""
    from cerebx.recording.reader import read_messages

    hashes: dict[str, hashlib._Hash] = {}
    counts: dict[str, int] = {}
    for topic, t, msg in read_messages(run_dir):
        h = hashes.setdefault(topic, hashlib.sha256())
        h.update(orjson.dumps([t, msg], option=orjson.OPT_SORT_KEYS | orjson.OPT_SERIALIZE_NUMPY))
        counts[topic] = counts.get(topic, 0) + 1
    summary = json.loads((run_dir / "summary.json").read_text())
    sim = {k: v for k, v in summary.items() if k not in WALL_CLOCK}
    return {"topics": {k: {"count": counts[k], "sha256": hashes[k].hexdigest()} for k in sorted(hashes)},
            "summary": sim}


def record(name: str, out_dir: Path) -> dict:
    from cerebx.config import load
    from cerebx.loop.runner import run_experiment

    cfg, _ = load(RUNS[name])
    run_experiment(cfg, out_dir)
    return digest(out_dir)


if __name__ == "__main__":
    import tempfile

    data: dict = {"platform": this_platform(), "runs": {}}
    with tempfile.TemporaryDirectory() as tmp:
        for name in RUNS:
            data["runs"][name] = record(name, Path(tmp) / name)
            print(name, data["runs"][name]["summary"]["mae_per_trial"], file=sys.stderr)
    GOLDEN.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    print(f"wrote {GOLDEN}", file=sys.stderr)
