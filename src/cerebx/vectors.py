"""The width of the SIMD vectors numba compiles cerebx's kernels for: ``CEREBX_VECTOR_BITS``.

On a CPU with AVX-512, LLVM still prefers 256-bit vectors for most CPU models, and numba compiles for the host
CPU as LLVM describes it, so the vectorised loops (every population's integration, the dense deliveries, the
weight updates) would run 8 float32 lanes wide. cerebx lets them use the 16 lanes of AVX-512 (the host's LLVM
features with ``-prefer-256-bit``, handed to numba as ``NUMBA_CPU_FEATURES``): by default on such a CPU, or
with ``CEREBX_VECTOR_BITS=512``; ``CEREBX_VECTOR_BITS=256`` leaves numba's choice.

Measured on the 2-core development machine (Emerald Rapids, 2026-11-29; docs/guide/speed.md#wide-vectors):
the Golgi network's fused granule step 110-120 -> 71-81 us a call, its closed loop 3.1 -> 4.7x real time
(medians); the thesis network's closed loop does not gain (its loop's thread sets the pace). The results do not
depend on the width: the DCN's step divides exactly (``cerebx.snn.kernels.FAST``), and the golden runs and a
thesis-network run give the same bits at 256 and 512. A run records its width (``controller_info.vector_bits``).

It must be chosen before numba compiles or loads its first kernel: :func:`configure` runs when ``cerebx`` is
imported (in a process that imported numba and compiled with it before, the width stays numba's). A
``NUMBA_CPU_FEATURES`` or ``NUMBA_CPU_NAME`` set by the user wins (then nothing is changed here).
"""

from __future__ import annotations

import os
import sys

ENV = "CEREBX_VECTOR_BITS"
WIDE = "-prefer-256-bit"


def problem(environ: dict[str, str] | None = None) -> str | None:
    """A one-line error for a ``CEREBX_VECTOR_BITS`` other than 256 or 512 (the command line refuses it; an
    import of cerebx leaves the width as numba picks it)."""
    bits = (os.environ if environ is None else environ).get(ENV, "").strip()
    return None if bits in ("", "256", "512") else f"{ENV}: expected 256 or 512, got {bits!r}"


def asked(environ: dict[str, str] | None = None) -> bool:
    """Whether 512-bit vectors are wanted where the CPU has them: by default and with ``CEREBX_VECTOR_BITS=512``
    (not with 256, nor with a value :func:`problem` refuses)."""
    return (os.environ if environ is None else environ).get(ENV, "").strip() in ("", "512")


def configure(environ: dict[str, str] | None = None) -> None:
    """On a CPU with AVX-512, unless ``CEREBX_VECTOR_BITS=256`` (and with neither ``NUMBA_CPU_FEATURES`` nor
    ``NUMBA_CPU_NAME`` set), give numba the host's CPU features with 512-bit vectors preferred."""
    env = os.environ if environ is None else environ
    if env.get("NUMBA_CPU_FEATURES", "").endswith("," + WIDE):  # set by cerebx, maybe on another host: again
        del env["NUMBA_CPU_FEATURES"]
    if not asked(env) or env.get("NUMBA_CPU_FEATURES") or env.get("NUMBA_CPU_NAME") or not _may_have_avx512():
        return
    import llvmlite.binding as ll  # ~0.1 s, which a run's numba would spend anyway

    ll.initialize_native_target()
    features = ll.get_host_cpu_features().flatten()
    if "+avx512f" in features.split(","):  # else no 512-bit vectors on this CPU
        # in the environment (numba reads it again whenever a NUMBA_ variable changes), where a job started from
        # this process finds it and works out its own host's
        env["NUMBA_CPU_FEATURES"] = f"{features},{WIDE}"


def _may_have_avx512() -> bool:
    """False when Linux's CPU flags say there is no AVX-512 (then llvmlite need not be asked); else True."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("flags"):
                    return " avx512f" in line
    except OSError:
        pass
    return True


def vector_bits() -> int:
    """512 when this process's kernels are compiled with 256-bit vectors no longer preferred on an AVX-512 CPU,
    else 256: numba's default, which is 256-bit vectors on most AVX-512 CPUs (and narrower without AVX2)."""
    features = os.environ.get("NUMBA_CPU_FEATURES", "")
    numba = sys.modules.get("numba")
    if numba is not None:
        from numba.core import config

        features = config.CPU_FEATURES or features
    flags = features.split(",")
    return 512 if WIDE in flags and "+avx512f" in flags else 256
