"""CEREBX_VECTOR_BITS: the width numba's kernels are compiled for (cerebx/vectors.py)."""

from __future__ import annotations

import os
import subprocess
import sys

import llvmlite.binding as ll
import pytest

from cerebx import vectors

ll.initialize_native_target()
HOST = ll.get_host_cpu_features().flatten()
AVX512 = "+avx512f" in HOST.split(",")


def test_256_leaves_numba_alone():
    env = {"CEREBX_VECTOR_BITS": "256"}
    vectors.configure(env)
    assert env == {"CEREBX_VECTOR_BITS": "256"} and vectors.problem(env) is None


@pytest.mark.parametrize("env", [{}, {"CEREBX_VECTOR_BITS": ""}, {"CEREBX_VECTOR_BITS": "512"}])
def test_512_is_the_default_where_the_cpu_has_it(env):
    vectors.configure(env)
    assert vectors.problem(env) is None
    if AVX512:
        assert env["NUMBA_CPU_FEATURES"] == HOST + ",-prefer-256-bit"
    else:
        assert "NUMBA_CPU_FEATURES" not in env


def test_a_bad_width_is_one_line_and_changes_nothing():
    env = {"CEREBX_VECTOR_BITS": "128"}
    vectors.configure(env)
    assert env == {"CEREBX_VECTOR_BITS": "128"}
    assert vectors.problem(env) == "CEREBX_VECTOR_BITS: expected 256 or 512, got '128'"


def test_the_command_line_refuses_a_bad_width():
    p = subprocess.run([sys.executable, "-m", "cerebx", "validate", "+task=circle"], capture_output=True, text=True,
                       env={**os.environ, "CEREBX_VECTOR_BITS": "wide"})
    assert p.returncode == 2
    assert p.stderr.strip() == "CEREBX_VECTOR_BITS: expected 256 or 512, got 'wide'"


@pytest.mark.skipif(not AVX512, reason="this CPU has no AVX-512")
def test_512_hands_numba_the_host_features_with_wide_vectors():
    env = {"CEREBX_VECTOR_BITS": "512"}
    vectors.configure(env)
    assert env["NUMBA_CPU_FEATURES"] == HOST + ",-prefer-256-bit"
    # a job started from that process (maybe on another host) works its own host's out again
    env["NUMBA_CPU_FEATURES"] = "+avx512f,+sse2,-prefer-256-bit"
    vectors.configure(env)
    assert env["NUMBA_CPU_FEATURES"] == HOST + ",-prefer-256-bit"


def test_512_leaves_the_users_own_numba_cpu_settings():
    for key, value in (("NUMBA_CPU_FEATURES", "+sse2"), ("NUMBA_CPU_NAME", "generic")):
        env = {"CEREBX_VECTOR_BITS": "512", key: value}
        vectors.configure(env)
        assert env == {"CEREBX_VECTOR_BITS": "512", key: value}


@pytest.mark.skipif(not AVX512, reason="this CPU has no AVX-512")
def test_a_process_reports_the_width_its_kernels_get():
    out = at_each_width("import cerebx, numba; from cerebx.vectors import vector_bits; print(vector_bits())")
    assert out == {"256": ["256"], "512": ["512"]}, out


def at_each_width(code: str) -> dict[str, list[str]]:
    """The words ``python -c code`` prints with CEREBX_VECTOR_BITS=256 and with 512 (nothing else of the kind
    inherited), by width; a process that fails says why."""
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CPU_FEATURES", "CEREBX_VECTOR_BITS")}
    out = {}
    for bits in ("256", "512"):
        p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                           env={**env, "CEREBX_VECTOR_BITS": bits})
        assert p.returncode == 0, p.stderr
        out[bits] = p.stdout.split()
    return out


@pytest.mark.skipif(not AVX512, reason="this CPU has no AVX-512")
def test_512_compiles_16_lane_loops():
    """A float32 loop like the integration loops: vectorised either way (8 lanes, ymm, by default where LLVM
    prefers 256-bit vectors, as on this Emerald Rapids host), 16 lanes (zmm) with 512."""
    code = ("import cerebx, numpy as np\nfrom numba import njit\n"
            "@njit(fastmath=True)\ndef f(u, g):\n    for i in range(u.shape[0]):\n"
            "        u[i] = u[i] * np.float32(0.9) + g[i]\n"
            "a = np.ones(64, np.float32)\nf(a, a)\nasm = next(iter(f.inspect_asm().values()))\n"
            "print('zmm' in asm, 'ymm' in asm)")
    out = at_each_width(code)
    assert "True" in out["256"], out
    assert out["512"][0] == "True", out


def test_256_kernels_have_their_own_cache_folder(tmp_path):
    """The compile notice reads a cache folder's index files, which do not say for which width: kernels
    compiled with CEREBX_VECTOR_BITS=256 go to a folder of their own (unless the user names one)."""
    from cerebx import jobenv

    env = {"CEREBX_CACHE": str(tmp_path), "CEREBX_VECTOR_BITS": "256"}
    assert jobenv.configure(env)["NUMBA_CACHE_DIR"] == str(tmp_path / "numba-256")
    assert jobenv.numba_cache_dir({"CEREBX_CACHE": str(tmp_path)}) == tmp_path / "numba"
    assert jobenv.numba_cache_dir({"CEREBX_CACHE": str(tmp_path), "CEREBX_VECTOR_BITS": "512"}) == tmp_path / "numba"
    env = {"NUMBA_CACHE_DIR": "/elsewhere", "CEREBX_VECTOR_BITS": "256"}
    jobenv.configure(env)
    assert env["NUMBA_CACHE_DIR"] == "/elsewhere"


@pytest.mark.skipif(not AVX512, reason="this CPU has no AVX-512")
def test_the_dcn_step_gives_the_same_bits_at_either_width():
    """The width is a matter of speed only: the DCN's AMPA+NMDA+GABA step (its Mg block divides) over 50 steps
    of 600 neurons, with 8 and with 16 lanes, to the last bit of every potential."""
    code = ("import hashlib, numpy as np\nfrom cerebx.config import load\nfrom cerebx.snn.network import Network\n"
            "from cerebx.snn import kernels as K\nfrom cerebx.vectors import vector_bits\n"
            "exp, _ = load(['+task=circle', 'network=full'])\n"
            "p = Network(exp.controller.network, parallel=False)._kernel_arrays().populations.pop_par[4]\n"
            "r = np.random.default_rng(1)\nm = 600\n"
            "u, a, n, g = (r.uniform(0, hi, m).astype(np.float32) for hi in (25, 2, 1, 3))\n"
            "ref, flag = np.zeros(m, np.float32), np.zeros(m, np.uint8)\n"
            "for k in range(50):\n    K._lif_full(u, a, n, g, ref, flag, p)\n"
            "    a += np.float32(0.3)\n    n += np.float32(0.1)\n"
            "print(vector_bits(), hashlib.sha256(u.tobytes()).hexdigest(), int(flag.sum()))")
    out = at_each_width(code)
    assert [out["256"][0], out["512"][0]] == ["256", "512"] and out["256"][1:] == out["512"][1:], out
