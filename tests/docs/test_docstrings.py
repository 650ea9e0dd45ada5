"""The public API's callables say what each parameter is: a numpy-style "Parameters" section (rendered as a
table in the API reference) on every function and class of ``cerebx.api`` and ``cerebx.report.api`` that
takes parameters. Configuration models document their fields with descriptions instead (the options
reference is generated from them), protocols say their call in their text, a dataclass may list its fields
as "Attributes"."""

from __future__ import annotations

import inspect
from typing import Protocol

import pytest
from pydantic import BaseModel

import cerebx.api
import cerebx.report.api

# defined in src/cerebx/snn/ (documented in the how-tos' encoder interface table); RunSet is made like a list
NOT_YET = {"MossyEncoder", "ClimbingEncoder", "ltd_kernel_table", "RunSet"}


def _parameters(obj) -> list[str]:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    return [p for p in sig.parameters if p not in ("self", "cls")]


def _public(module):
    for name in module.__all__:
        obj = getattr(module, name)
        if not (inspect.isfunction(obj) or inspect.isclass(obj)) or name in NOT_YET or not _parameters(obj):
            continue
        if inspect.isclass(obj) and (issubclass(obj, (BaseModel, BaseException)) or Protocol in obj.__mro__):
            continue
        yield f"{module.__name__}.{name}", obj


@pytest.mark.parametrize(("name", "obj"), [*_public(cerebx.api), *_public(cerebx.report.api)],
                         ids=lambda v: v if isinstance(v, str) else "")
def test_a_public_callable_documents_its_parameters(name, obj):
    docs = [inspect.getdoc(obj) or ""] + ([inspect.getdoc(obj.__init__) or ""] if inspect.isclass(obj) else [])
    assert any("Parameters\n----------" in d or "Attributes\n----------" in d for d in docs), \
        f"{name}: no Parameters section"
