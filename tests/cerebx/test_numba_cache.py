"""A run whose numba kernels are not in the cache says it compiles them first and counts it in its estimate."""

from __future__ import annotations

import ast
import json
import os

import pytest

from cerebx import numba_cache
from cerebx.cli import main
from cerebx.compile_progress import CompileProgress
from cerebx.estimate import duration
from cerebx.numba_cache import MIN_REPORTED_S, cold_kernels

SNN = ["+task=circle", "+experiment=small_snn", "trials=1"]


def _warm(cache, modules) -> None:
    """Fake compiled kernels: one cache index per module, newer than its source."""
    for name in modules:
        src = numba_cache._source(name)
        parent = os.path.dirname(os.path.abspath(src))
        folder = cache / f"{os.path.basename(parent)}_{numba_cache.hashlib.sha1(parent.encode()).hexdigest()}"
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"{src.stem}.kernel-1.py311.nbi").write_bytes(b"")


def test_a_cold_cache_is_found_and_a_warm_one_is_not(load, tmp_path):
    exp = load(SNN)
    cold = cold_kernels([exp], tmp_path)
    assert {"cerebx.snn.kernels", "cerebx.snn.encoders", "cerebx.loop.phases"} <= set(cold.modules)
    assert cold.kernels >= 30 and cold.reported
    _warm(tmp_path, cold.modules)
    assert cold_kernels([exp], tmp_path).kernels == 0
    edited = numba_cache._source("cerebx.snn.kernels").stat().st_mtime
    for index in tmp_path.glob("snn_*/kernels.*.nbi"):  # compiled before its source last changed: stale
        os.utime(index, (edited - 60, edited - 60))
    assert cold_kernels([exp], tmp_path).modules == ("cerebx.snn.kernels",)


def test_what_the_sources_say_is_kept_until_a_source_changes(load, tmp_path, monkeypatch):
    """The second run's start reads no syntax tree: each module's imports and kernel count are kept in the cache
    folder by its source's size and age, and read again from a source whose size or age changed."""
    exp = load(SNN)
    first = cold_kernels([exp], tmp_path)
    facts = json.loads((tmp_path / numba_cache.FACTS).read_text())
    assert facts["cerebx.snn.kernels"][4] == numba_cache._kernel_count("cerebx.snn.kernels") > 0
    numba_cache._tree.cache_clear()
    numba_cache._kernel_count.cache_clear()
    parsed = []
    monkeypatch.setattr(numba_cache, "_tree", lambda name: parsed.append(name) or ast.parse(""))
    assert cold_kernels([exp], tmp_path) == first and parsed == []
    facts["cerebx.snn.kernels"][2] -= 1  # as if the file had been edited since: read again (here: an empty tree)
    (tmp_path / numba_cache.FACTS).write_text(json.dumps(facts))
    again = cold_kernels([exp], tmp_path)
    assert parsed == ["cerebx.snn.kernels", "cerebx.snn.kernels"] and "cerebx.snn.kernels" not in again.modules
    monkeypatch.undo()
    (tmp_path / numba_cache.FACTS).write_text("not json")  # a damaged file is read as none
    assert cold_kernels([exp], tmp_path).kernels > 0


def test_a_pd_run_has_too_few_kernels_to_report(load, tmp_path):
    assert cold_kernels([load(["+experiment=demo"])], tmp_path).seconds < MIN_REPORTED_S


def test_a_run_with_a_cold_cache_says_it_compiles(in_tmp, monkeypatch, capsys):
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(in_tmp / "cold"))
    started = []
    monkeypatch.setattr("cerebx.commands.run.run_app", lambda: started.append(True))
    monkeypatch.setattr("cerebx.commands.run.show_progress", lambda n: started.append(n))
    assert main(["run", *SNN]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    n = started[0]
    secs = n * 0.3 + 90.0  # the network's step module is cold: its measured 90 s on top (numba_cache's docstring)
    assert err[0] == (f"numba: {n} kernels of this run are not compiled yet (first run since an install or a change): "
                      f"compiling them first, ~{secs:.0f} s, once (cached in {in_tmp / 'cold'})")
    assert err[1].startswith("run: estimate: 2 s simulated") and err[1].endswith(
        f"on a quiet 2-core machine (~{duration(secs)} of it compiling numba kernels, once)")
    assert started == [n, True]


def test_progress_counts_cerebx_kernels_only(capsys):
    from numba.core.event import Event

    from cerebx.loop.phases import all_finite

    class Dispatcher:
        def __init__(self, func):
            self.py_func = func

    progress = CompileProgress(expected=3, every_s=0.0)
    for func in (all_finite.py_func, os.path.join, all_finite.py_func):
        ev = Event("numba:compile", "start", data={"dispatcher": Dispatcher(func)})
        progress.on_start(ev)
        progress.on_end(Event("numba:compile", "end", data=ev.data))
    assert progress.done == 2
    assert capsys.readouterr().err.splitlines()[-1].startswith("numba: 2 of ~3 kernels compiled (")


@pytest.fixture(autouse=True)
def _fresh_parse():
    """Each test reads the sources as they are now."""
    numba_cache._tree.cache_clear()
    numba_cache._kernel_count.cache_clear()


def test_a_cache_compiled_from_other_sources_is_retired(tmp_path):
    """A kernel cached against a struct that has since changed or moved fails to load instead of compiling again
    (numba checks only the kernel's own file): any change to a numba-using source retires the whole cache once."""
    from cerebx.numba_cache import STAMP, retire_stale, sources_stamp

    cache = tmp_path / "numba"
    (cache / "snn_0123").mkdir(parents=True)
    old = [cache / "snn_0123" / "kernels.run_step-10.py311.nbi", cache / "snn_0123" / "kernels.run_step-10.py311.1.nbc"]
    for f in old:
        f.write_bytes(b"compiled elsewhere")
    (cache / STAMP).write_text("sources of another version")
    assert retire_stale(cache)
    assert not any(f.exists() for f in old) and (cache / STAMP).read_text() == sources_stamp()
    old[0].write_bytes(b"compiled from these sources")
    assert not retire_stale(cache) and old[0].exists()
