"""The import contracts of ``make lint`` hold, and they catch a violation planted in a copy of the tree."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.integration

ROOT = Path(__file__).resolve().parents[2]
LINT = Path(sys.executable).with_name("lint-imports")


EXAMPLES = [ROOT / "examples" / "my_lab", ROOT / "examples" / "my_cerebellum"]  # root packages of the contracts too


def _lint(src: Path, cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(map(str, [src, *EXAMPLES]))}
    return subprocess.run([str(LINT), "--no-cache", "--config", str(ROOT / "pyproject.toml")], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=300)


def test_the_tree_keeps_every_contract(tmp_path):
    done = _lint(ROOT / "src", tmp_path)
    assert done.returncode == 0, done.stdout[-3000:]
    assert "0 broken" in done.stdout


@pytest.mark.parametrize(("where", "line", "contract"), [
    ("cerebx/loop/planted.py", "import cerebx_thesis.ann.schema", "The platform imports no paper package"),
    ("cerebx/schema/planted.py", "import cerebx.loop.runner", "The schema layer imports no runtime module"),
    ("cerebx/controllers/schema.py", "import cerebx.loop.runner", "The schema layer imports no runtime module"),
    ("cerebx/stages/planted.py", "import cerebx.report.build", "import no report"),
    ("cerebx_luque2011/planted.py", "import cerebx_capolei2020.task", "The papers are independent"),
    ("cerebx_thesis/planted.py", "from cerebx.loop.runner import run_experiment", "import only cerebx's public API"),
])
def test_a_planted_violation_breaks_its_contract(tmp_path, where, line, contract):
    src = tmp_path / "src"
    shutil.copytree(ROOT / "src", src, ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    (src / where).write_text(f'"""A planted violation."""\n\n{line}\n')
    done = _lint(src, tmp_path)
    assert done.returncode != 0
    assert contract in done.stdout and "BROKEN" in done.stdout


def test_no_two_folders_of_cerebx_import_each_other():
    """Each top-level module or folder of cerebx depends on another one way only (the import graph, direct
    imports, any depth of nesting below the folder)."""
    import grimp

    graph = grimp.build_graph("cerebx", include_external_packages=False)

    def top(module: str) -> str:
        return ".".join(module.split(".")[:2])

    edges = {(top(m), top(i)) for m in graph.modules for i in graph.find_modules_directly_imported_by(m)
             if top(m) != top(i)}
    ties = sorted({tuple(sorted(e)) for e in edges if (e[1], e[0]) in edges})
    assert not ties, f"folders importing each other: {ties}"


def test_few_functions_take_more_than_ten_parameters():
    """Kernels take their parameters named or grouped (a structref, a tuple): of the package's functions, numba
    kernels included, one takes more than ten (the SNN controller's _run_chunk_outputs; the issue's goal: <= 3)."""
    import ast

    many = []
    for path in (ROOT / "src").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                a = node.args
                n = (len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None)
                     + (a.kwarg is not None))
                n -= bool(a.args) and a.args[0].arg in ("self", "cls")
                if n > 10:
                    many.append(f"{path.relative_to(ROOT)}:{node.lineno} {node.name} ({n})")
    assert len(many) <= 1, "\n".join(many)


def test_every_schema_lives_in_a_module_named_schema():
    """The one home convention (docs/index.md#where-the-code-lives): each configuration model (a ``Strict``
    subclass) of cerebx and of the paper plugins is defined in a module named ``schema`` (a package's
    ``schema.py``, or a module of the ``cerebx.schema`` package), the modules the schema-layer contract covers."""
    import importlib
    import pkgutil

    from cerebx.schema.base import Strict

    for package in ("cerebx", "cerebx_thesis", "cerebx_luque2011", "cerebx_capolei2020"):
        root = importlib.import_module(package)
        for info in pkgutil.walk_packages(root.__path__, f"{package}."):
            if not info.name.endswith("__main__"):
                importlib.import_module(info.name)

    def subclasses(cls: type) -> set[type]:
        return {c for s in cls.__subclasses__() for c in (s, *subclasses(s))}

    found = {c for c in subclasses(Strict) if c.__module__.split(".")[0] in
             ("cerebx", "cerebx_thesis", "cerebx_luque2011", "cerebx_capolei2020")}
    elsewhere = sorted(f"{c.__module__}.{c.__qualname__}" for c in found
                       if "schema" not in c.__module__.split(".")[1:])
    assert len(found) > 100
    assert not elsewhere, f"schemas outside a schema module: {elsewhere}"
