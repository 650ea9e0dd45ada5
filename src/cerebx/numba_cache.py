"""Whether the numba kernels a run will use are compiled already, and about how long compiling them takes.

numba compiles a ``cache=True`` kernel on its first call and keeps it in ``NUMBA_CACHE_DIR``: one folder per
source folder (``<folder name>_<sha1 of its absolute path>``), one index ``<module>.<function>-<line>.pyXY.nbi``
per kernel, valid while the source file is unchanged. A run's kernels are those of the modules it imports: the
closed loop's and those of the builders of its chosen kinds, followed through their imports within cerebx and
its plugins (read from the source, nothing is imported). A module counts as compiled when one of its kernels has
an index newer than its source. A run compiles only the kernels it calls: a module whose kernels no run has
called yet (the checkpoint writer's, in runs shorter than ``checkpoint_every``) stays counted as cold, so less than
``MIN_REPORTED_S`` of compiling is not reported.

The cost is measured, not derived, on a quiet 2-core machine (2026-11-29, an AMD EPYC that LLVM calls znver3):
the first PD run (``+experiment=demo trials=1``), 5 kernels counted cold, took 3.6 s against 2.2 s warm, about
0.3 s per kernel; the first small spiking run (``+task=circle +experiment=small_snn trials=1``), 82 kernels
counted, 118-123 s against 3 s warm. Most of that is the network's step (``cerebx.snn.kernels``): the step kernel
and the three that call it (the chunk, the controller's chunk outputs, those on encoded ticks) each optimise the
whole step again, and the step holds every integrator the schema offers (AdEx, lif_cond with GABA), used by the run
or not. The first Capolei run (``+experiment=capolei2020_arch3 trials=1``), 16 kernels counted, took 41 s against
2.9 s warm: LWPR's kernels, compiled for each model shape (``cerebx.lwpr.kernels``). Hence 0.3 s a kernel, and
:data:`HEAVY_MODULES` on top for those two modules when they are cold. (2026-11-27, before the network vocabulary,
on the development machine: 29 kernels counted, 25.5 s.)
"""

from __future__ import annotations

import ast
import functools
import hashlib
import importlib.util
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cerebx import registry

COMPILE_S_PER_KERNEL = 0.3
HEAVY_MODULES = {"cerebx.snn.kernels": 90.0, "cerebx.lwpr.kernels": 33.0}
"""Seconds that compiling a cold module's kernels takes besides the per-kernel seconds (measured, see above)."""
MIN_REPORTED_S = 5.0
"""Less compiling than this is left out of the estimate (it is within its noise, and partly kernels of modules a
run imports without calling them)."""
LOOP_MODULE = "cerebx.loop.runner"
"""Where the closed loop of every run starts (its imports bring the loop's own kernels)."""


@dataclass(frozen=True)
class ColdKernels:
    """The kernels a run has to compile first: how many, in which modules, and about how long it takes."""

    modules: tuple[str, ...]
    kernels: int
    cache_dir: Path

    @property
    def seconds(self) -> float:
        return self.kernels * COMPILE_S_PER_KERNEL + sum(HEAVY_MODULES.get(m, 0.0) for m in self.modules)

    @property
    def reported(self) -> bool:
        """Enough compiling to tell the user and to count in the estimate."""
        return self.seconds >= MIN_REPORTED_S

    def line(self) -> str:
        return (f"numba: {self.kernels} kernels of this run are not compiled yet (first run since an install or a "
                f"change): compiling them first, ~{self.seconds:.0f} s, once (cached in {self.cache_dir})")


STAMP = "cerebx-sources.sha1"
"""File in the cache folder naming the kernel sources its entries were compiled from."""


def sources_stamp() -> str:
    """A digest of every source file of cerebx and its sibling plugin packages that uses numba. numba keeps a
    cached kernel while the kernel's own file is unchanged, even when a type it was compiled against (a struct
    of another module) has changed or moved: loading it then fails (``Can't get attribute ...``) instead of
    compiling again. So any change to any numba-using file retires the whole cache."""
    import cerebx

    root = Path(cerebx.__file__).resolve().parents[1]
    h = hashlib.sha1()
    for path in sorted(root.glob("cerebx*/**/*.py")):
        text = path.read_bytes()
        if b"numba" in text:
            h.update(str(path.relative_to(root)).encode() + b"\0" + hashlib.sha1(text).digest())
    return h.hexdigest()


def retire_stale(cache_dir: Path) -> bool:
    """Empty ``cache_dir`` of compiled kernels when the numba-using sources changed since they were compiled
    (see :func:`sources_stamp`); True when it did. Cheap when nothing changed (one digest of the sources)."""
    stamp = sources_stamp()
    mark = cache_dir / STAMP
    try:
        if mark.read_text() == stamp:
            return False
    except OSError:
        pass
    removed = False
    if cache_dir.is_dir():
        for f in [*cache_dir.rglob("*.nbi"), *cache_dir.rglob("*.nbc")]:
            try:
                f.unlink()
                removed = True
            except OSError:
                pass
    try:
        cache_dir.mkdir(parents=True, exist_ok=True)
        tmp = mark.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(stamp)
        tmp.replace(mark)
    except OSError:
        pass
    return removed


def cold_kernels(exps: list[Any], cache_dir: Path | None = None) -> ColdKernels:
    """The not yet compiled kernels of the runs of experiments ``exps`` (a sweep's jobs compile each kernel once;
    ``cache_dir``: numba's cache folder, by default ``NUMBA_CACHE_DIR``)."""
    folder = Path(cache_dir or os.environ.get("NUMBA_CACHE_DIR") or ".")
    roots = tuple(sorted(set().union(*(builder_modules(e) for e in exps)))) if exps else ()
    known = _load_facts(folder)
    before = dict(known)  # entries are replaced, never changed in place
    cold = [(m, n) for m in sorted(_closure(roots, known))
            if (n := _facts(m, known)[1]) and not _compiled(m, folder)]
    if known != before:
        _save_facts(folder, known)
    return ColdKernels(tuple(m for m, _ in cold), sum(n for _, n in cold), folder)


def builder_modules(exp: Any) -> set[str]:
    """The closed loop's module and those of the builders of every kind ``exp`` chooses (its components, stages,
    link and, nested in them, e.g. a spiking controller's encoders)."""
    out = {LOOP_MODULE}
    for node in _kinds(exp):
        for reg in registry.GROUPS.values():
            entry = reg._entries.get(node.kind)
            if entry is not None and entry.schema is type(node):
                builder = entry.builder
                out.add(builder.partition(":")[0] if isinstance(builder, str) else builder.__module__)
    return out


def _kinds(node: Any) -> list[Any]:
    """Every config model with a ``kind`` inside ``node`` (itself included)."""
    out = [node] if isinstance(getattr(node, "kind", None), str) else []
    children = node if isinstance(node, (list, tuple)) else (
        [getattr(node, f) for f in type(node).model_fields] if hasattr(type(node), "model_fields") else [])
    for child in children:
        if hasattr(type(child), "model_fields") or isinstance(child, (list, tuple)):
            out += _kinds(child)
    return out


FACTS = "cerebx-modules.json"
"""File in the cache folder keeping what each module's source says (its imports within cerebx and its plugins,
its cached kernels), by file size and modification time: reading the sources' syntax trees took ~0.3 s of
every run's start."""


def _load_facts(folder: Path) -> dict[str, list]:
    try:
        facts = json.loads((folder / FACTS).read_text())
    except (OSError, ValueError):
        return {}
    return facts if isinstance(facts, dict) else {}


def _save_facts(folder: Path, facts: dict[str, list]) -> None:
    """Written whole and renamed into place (runs side by side may write it at once); a folder that cannot be
    written is left as it is."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        tmp = folder / f"{FACTS}.{os.getpid()}.tmp"
        tmp.write_text(json.dumps(facts, sort_keys=True))
        tmp.replace(folder / FACTS)
    except OSError:
        pass


def _facts(name: str, known: dict[str, list]) -> tuple[list[str], int]:
    """(imports, cached kernels) of module ``name``: from ``known`` while its source is the same size and age,
    else read from the source and put in ``known``."""
    src = _source(name)
    assert src is not None
    st = src.stat()
    key = [str(src), st.st_size, st.st_mtime_ns]
    entry = known.get(name)
    if isinstance(entry, list) and len(entry) == 5 and entry[:3] == key:
        return list(entry[3]), int(entry[4])
    imports, kernels = _imports(name), _kernel_count(name)
    known[name] = [*key, imports, kernels]
    return imports, kernels


def _closure(roots: tuple[str, ...], known: dict[str, list]) -> frozenset[str]:
    """``roots`` and every module of cerebx or a plugin they import, directly or not (imports in functions too);
    ``known``: the modules' facts kept in the cache folder (:func:`_facts`)."""
    seen: set[str] = set()
    todo = list(roots)
    while todo:
        name = todo.pop()
        if name in seen or _source(name) is None:
            continue
        seen.add(name)
        todo += _facts(name, known)[0]
    return frozenset(seen)


def _is_ours(name: str) -> bool:
    return name.split(".")[0].startswith("cerebx")


@functools.cache
def _source(name: str) -> Path | None:
    """The source file of module ``name`` of cerebx or a plugin, found without importing it."""
    if not _is_ours(name):
        return None
    top, *rest = name.split(".")
    spec = importlib.util.find_spec(top)
    if spec is None or not spec.submodule_search_locations:
        return None
    base = Path(next(iter(spec.submodule_search_locations))).joinpath(*rest)
    return next((p for p in (base.with_suffix(".py"), base / "__init__.py") if p.is_file()), None)


@functools.cache
def _tree(name: str) -> ast.Module:
    return ast.parse(_source(name).read_text())  # type: ignore[union-attr]


def _imports(name: str) -> list[str]:
    """Modules of cerebx or a plugin that module ``name`` imports (``from a import b`` may name module a.b)."""
    package = name if _source(name).name == "__init__.py" else name.rpartition(".")[0]  # type: ignore[union-attr]
    out = []
    for node in ast.walk(_tree(name)):
        if isinstance(node, ast.Import):
            out += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parent = package.rsplit(".", node.level - 1)[0] if node.level > 1 else package
                base = f"{parent}.{base}" if base else parent
            out += [base, *(f"{base}.{a.name}" for a in node.names)]
    return [m for m in out if _is_ours(m)]


@functools.cache
def _kernel_count(name: str) -> int:
    """The ``cache=True`` kernels defined in module ``name``, with one per ``KernelStruct`` subclass (a class
    given ``fields=``: its compiled constructor)."""
    return sum(1 for node in ast.walk(_tree(name)) if isinstance(node, ast.FunctionDef)
               and any(_caches(d) for d in node.decorator_list)
               or isinstance(node, ast.ClassDef) and any(k.arg == "fields" for k in node.keywords))


def _caches(decorator: ast.expr) -> bool:
    return isinstance(decorator, ast.Call) and any(
        k.arg == "cache" and isinstance(k.value, ast.Constant) and k.value.value is True for k in decorator.keywords)


def _compiled(name: str, cache_dir: Path) -> bool:
    """One kernel of module ``name`` has a cache index newer than its source."""
    src = _source(name)
    assert src is not None
    parent = os.path.dirname(os.path.abspath(src))
    folder = cache_dir / f"{os.path.basename(parent)}_{hashlib.sha1(parent.encode()).hexdigest()}"
    changed = src.stat().st_mtime
    return any(i.stat().st_mtime >= changed for i in folder.glob(f"{src.stem}.*.nbi"))
