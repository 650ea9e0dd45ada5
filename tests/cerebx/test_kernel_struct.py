"""KernelStruct: a kernel's named tuple as one numba object that shares its arrays, pickles as its tuple and
keeps its compiled constructor in a cache file of its own."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
from typing import NamedTuple

import numpy as np
import pytest
from numba import njit

from cerebx.api import KernelStruct


class Gains(NamedTuple):
    k: float
    n: int


class Toy(NamedTuple):
    x: np.ndarray
    gains: Gains


class ToyState(KernelStruct, fields=Toy):
    """A test struct."""


@njit(cache=False)
def _bump(state):
    state.x[0] += state.gains.k * state.gains.n
    return state.x[0]


def test_the_kernel_reads_fields_by_name_and_writes_the_callers_array():
    x = np.zeros(3)
    state = ToyState.of(Toy(x, Gains(1.5, 2)))
    assert _bump(state) == 3.0
    assert x[0] == 3.0 and state.source.x is x


def test_it_pickles_as_its_tuple():
    state = ToyState.of(Toy(np.arange(3.0), Gains(0.5, 4)))
    again = pickle.loads(pickle.dumps(state))
    assert type(again) is ToyState
    assert _bump(again) == 2.0
    np.testing.assert_array_equal(again.source.x, [2.0, 1.0, 2.0])


def test_a_field_named_like_the_base_s_own_attributes_is_refused():
    class Bad(NamedTuple):
        source: np.ndarray

    with pytest.raises(TypeError, match="source"):
        class BadState(KernelStruct, fields=Bad):
            pass


CORD = """
import sys
import numpy as np
from cerebx.stages.spinal import Cord, CordState, IaLaw, RateNeurons
z = np.zeros(1)
CordState.of(Cord(np.zeros((1, 2)), np.zeros((1, 1)), np.zeros((1, 2, 1)), 1, z, z, IaLaw(1.0, 1.0, 1.0, 1.0, 1.0),
                  RateNeurons(1.0, 1.0, 1.0, 1.0, 1.0), z, z, z))
print(sum(CordState._pack.stats.cache_hits.values()), "cerebx.snn.encoders" in sys.modules)
"""

CODERS = """
import numpy as np
from cerebx.snn.encoders import BoxCoding, Coders, CodersState, ErrorCoding
a, i = np.zeros((1, 4)), np.zeros(3, np.int32)
CodersState.of(Coders(BoxCoding(a, a, a, a, 2, 0, i), ErrorCoding(1, z := np.zeros(1), z, z, 1.0, 0.0, 1.0, 3, 1,
                                                                 np.zeros(2, np.int64), 8, i)))
"""


@pytest.mark.integration
def test_each_struct_has_its_own_constructor_cache(tmp_path):
    """Two structs' compiled constructors are cached in two files, and loading one imports nothing of the
    other's module (a shared index would import every module, a plugin's too, whose struct it lists)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}

    def run(code: str) -> str:
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=600)
        assert done.returncode == 0, done.stderr
        return done.stdout.split()

    run(CODERS)
    assert run(CORD) == ["0", "False"]  # compiled
    names = sorted(p.name.split("-")[0] for p in tmp_path.rglob("kernel_struct.*.nbi"))
    assert names == ["kernel_struct.cerebx.snn.encoders.CodersState.pack",
                     "kernel_struct.cerebx.stages.spinal.CordState.pack"]
    assert run(CORD) == ["1", "False"]  # loaded from its cache
