"""Named registries that map a config ``kind`` to its schema and builder.

Groups: ``task``, ``plant``, ``controller`` (brain-side parts), ``stage`` (brain- or robot-side
stages: torque filters, the supervisor, muscles, ...), ``delay`` (link delay models), ``event``
(plant events), ``encoder`` (cerebellar input codes) and ``link`` (transports between the brain side
and the robot side). Built-in variants register in
``schema/builtin.py``; third-party packages register through the ``cerebx.plugins`` entry-point
group (each entry point is a callable taking no arguments that registers its variants).
Configuration only ever names a ``kind``: it cannot import anything.

A config field that holds "any registered kind of group G" is typed ``Plugin("G")``: the kind is
looked up when the config is validated, so a plugin's kinds are accepted everywhere the built-in
ones are.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from importlib.metadata import entry_points
from typing import Annotated, Any

from pydantic import BaseModel, WrapValidator


@dataclass(frozen=True)
class Entry:
    kind: str
    schema: type[BaseModel]
    builder: str | Callable[..., Any]

    def resolve(self) -> Callable[..., Any]:
        """The builder callable; a ``"module:attr"`` string is imported on first use."""
        if callable(self.builder):
            return self.builder
        module, _, attr = self.builder.partition(":")
        return getattr(importlib.import_module(module), attr)


class Registry:
    """Variants of one component group (``task``, ``plant``, ``controller``, ``delay``)."""

    def __init__(self, group: str):
        self.group = group
        self._entries: dict[str, Entry] = {}

    def register(self, schema: type[BaseModel], builder: str | Callable[..., Any]) -> type[BaseModel]:
        """Register ``schema`` (whose ``kind`` field default names the variant) and its builder."""
        kind = schema.model_fields["kind"].default
        if not isinstance(kind, str):
            raise TypeError(f"{schema.__name__}: the 'kind' field needs a string default")
        if kind in self._entries and self._entries[kind].schema is not schema:
            raise ValueError(f"{self.group} kind {kind!r} is already registered")
        self._entries[kind] = Entry(kind, schema, builder)
        return schema

    def kinds(self) -> list[str]:
        return sorted(self._entries)

    def schemas(self) -> tuple[type[BaseModel], ...]:
        return tuple(self._entries[k].schema for k in self.kinds())

    def __contains__(self, kind: str) -> bool:
        return kind in self._entries

    def __getitem__(self, kind: str) -> Entry:
        try:
            return self._entries[kind]
        except KeyError:
            raise KeyError(f"unknown {self.group} kind {kind!r}; known: {', '.join(self.kinds())}") from None

    def build(self, cfg: BaseModel, *args: Any, **kwargs: Any) -> Any:
        return self[cfg.kind].resolve()(cfg, *args, **kwargs)  # type: ignore[attr-defined]

    def parse(self, value: Any) -> BaseModel:
        """Validate a mapping ``{kind: ..., ...}`` with the schema its ``kind`` names."""
        if isinstance(value, BaseModel):
            value = value.model_dump()
        if not isinstance(value, dict):
            raise ValueError(f"expected a mapping with a 'kind' ({self.group} kinds: {', '.join(self.kinds())})")
        kind = value.get("kind")
        if kind not in self._entries:
            raise ValueError(f"unknown {self.group} kind {kind!r} (known: {', '.join(self.kinds())})")
        return self._entries[kind].schema.model_validate(value)


tasks = Registry("task")
plants = Registry("plant")
controllers = Registry("controller")
stages = Registry("stage")
delays = Registry("delay")
events = Registry("event")
encoders = Registry("encoder")
links = Registry("link")

GROUPS = {r.group: r for r in (tasks, plants, controllers, stages, delays, events, encoders, links)}


def Plugin(group: str) -> Any:  # noqa: N802 - reads as a type in schemas
    """The type of a config field holding any registered kind of ``group`` (looked up at validation)."""

    def pick(value: Any, handler: Any) -> BaseModel:
        load_plugins()
        return GROUPS[group].parse(value)

    return Annotated[Any, WrapValidator(pick)]

_plugins_loaded = False


def load_plugins() -> None:
    """Import the built-in variants, then every ``cerebx.plugins`` entry point (once)."""
    global _plugins_loaded
    if _plugins_loaded:
        return
    _plugins_loaded = True
    importlib.import_module("cerebx.schema.builtin")
    for ep in entry_points(group="cerebx.plugins"):
        ep.load()()
