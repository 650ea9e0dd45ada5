"""Named registries that map a config ``kind`` to its schema and builder, and the plugins that fill them.

Groups: ``task``, ``plant``, ``controller`` (brain-side parts), ``stage`` (brain- or robot-side
stages: torque filters, the supervisor, muscles, ...), ``delay`` (link delay models), ``event``
(plant events), ``encoder`` (cerebellar input codes), ``link`` (transports between the brain side and
the robot side), ``connector`` (spiking-network connection rules) and ``plasticity`` (their learning rules).
Every kind arrives through a plugin: a callable taking no arguments, exposed as a ``cerebx.plugins`` entry
point, that registers its kinds here. The platform's own kinds come the same way (entry point ``core``,
``cerebx.builtin:register``). A plugin may also add a folder of Hydra presets (:func:`add_config_source`)
and a report module with its figures and studies (:func:`add_report`). Configuration only ever names a
``kind``: it cannot import anything.

A config field that holds "any registered kind of group G" is typed ``Plugin("G")``: the kind is
looked up when the config is validated, so a plugin's kinds are accepted everywhere the built-in
ones are.

``CEREBX_PLUGINS`` (comma-separated entry-point names, e.g. ``core``) loads only those plugins; unset,
every installed plugin is loaded.
"""

from __future__ import annotations

import importlib
import os
from collections.abc import Callable
from dataclasses import dataclass
from importlib.metadata import entry_points
from typing import TYPE_CHECKING, Annotated, Any, Generic, TypeVar

from pydantic import BaseModel, WrapValidator

from cerebx.errors import CerebxError

if TYPE_CHECKING:
    from cerebx.builders import (
        ClimbingEncoderBuilder,
        ConnectorBuilder,
        ControllerBuilder,
        DelayBuilder,
        EventBuilder,
        LinkBuilder,
        MossyEncoderBuilder,
        PlantBuilder,
        PlasticityBuilder,
        ReceiverBuilder,
        StageBuilder,
        TaskBuilder,
    )

B = TypeVar("B", bound=Callable[..., Any])
"""A group's builder protocol (``cerebx/builders.py``)."""

ENTRY_POINTS = "cerebx.plugins"
ONLY_ENV = "CEREBX_PLUGINS"


@dataclass(frozen=True)
class Entry(Generic[B]):
    kind: str
    schema: type[BaseModel]
    builder: str | B
    plugin: str

    def resolve(self) -> B:
        """The builder callable; a ``"module:attr"`` string is imported on first use (a plugin's module,
        loaded by name)."""
        if callable(self.builder):
            return self.builder
        module, _, attr = self.builder.partition(":")
        return getattr(importlib.import_module(module), attr)


class Registry(Generic[B]):
    """Variants of one component group (``task``, ``plant``, ``controller``, ``delay`` ...), each built by a
    builder of the group's protocol ``B`` (``cerebx/builders.py``)."""

    def __init__(self, group: str):
        self.group = group
        self._entries: dict[str, Entry[B]] = {}

    def register(self, schema: type[BaseModel], builder: str | B) -> type[BaseModel]:
        """Register ``schema`` (whose ``kind`` field default names the variant) and its builder.

        Parameters
        ----------
        schema : type[BaseModel]
            The kind's config model; the default of its ``kind`` field is the kind's name.
        builder : str or callable
            The builder (of the group's protocol), or ``"module:attr"`` naming it (imported on first use, so
            heavy modules load only when a run uses the kind).
        """
        kind = schema.model_fields["kind"].default
        if not isinstance(kind, str):
            raise TypeError(f"{schema.__name__}: the 'kind' field needs a string default")
        if kind in self._entries and self._entries[kind].schema is not schema:
            raise ValueError(f"{self.group} kind {kind!r} is already registered by plugin "
                             f"{self._entries[kind].plugin!r}")
        self._entries[kind] = Entry(kind, schema, builder, _loading or "<direct>")
        return schema

    def kinds(self) -> list[str]:
        return sorted(self._entries)

    def schemas(self) -> tuple[type[BaseModel], ...]:
        return tuple(self._entries[k].schema for k in self.kinds())

    def __contains__(self, kind: str) -> bool:
        return kind in self._entries

    def __getitem__(self, kind: str) -> Entry[B]:
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


tasks: Registry[TaskBuilder] = Registry("task")
plants: Registry[PlantBuilder] = Registry("plant")
controllers: Registry[ControllerBuilder] = Registry("controller")
stages: Registry[StageBuilder | ReceiverBuilder] = Registry("stage")
delays: Registry[DelayBuilder] = Registry("delay")
events: Registry[EventBuilder] = Registry("event")
encoders: Registry[MossyEncoderBuilder | ClimbingEncoderBuilder] = Registry("encoder")
links: Registry[LinkBuilder] = Registry("link")
connectors: Registry[ConnectorBuilder] = Registry("connector")
plasticity_rules: Registry[PlasticityBuilder] = Registry("plasticity")

GROUPS = {r.group: r for r in (tasks, plants, controllers, stages, delays, events, encoders, links, connectors,
                               plasticity_rules)}


def Plugin(group: str) -> Any:  # noqa: N802 - reads as a type in schemas
    """The type of a config field holding any registered kind of ``group`` (looked up at validation).

    Parameters
    ----------
    group : str
        The registry group (``"controller"``, ``"stage"``, ``"encoder"``, ...).
    """

    def pick(value: Any, handler: Any) -> BaseModel:
        load_plugins()
        return GROUPS[group].parse(value)

    return Annotated[Any, WrapValidator(pick)]


@dataclass(frozen=True)
class Source:
    """Something a plugin adds besides kinds: a folder of presets or a report module."""

    plugin: str
    target: str


config_sources: list[Source] = []
"""Hydra config folders of plugins (``pkg://package.conf``), searched after cerebx's own ``conf/``."""

report_modules: list[Source] = []
"""Modules that register figures and studies (imported by the report engine only)."""

bench_runs: dict[str, tuple[str, ...]] = {}
"""Learning runs ``cerebx bench`` times as users run them (name -> ``cerebx run`` overrides)."""


def add_config_source(package: str) -> None:
    """Add the presets in ``package`` to every composition (after cerebx's own ``conf/``).

    Parameters
    ----------
    package : str
        A Python package holding config-group folders, e.g. ``my_lab.conf`` with ``experiment/``,
        ``controller/`` ...
    """
    config_sources.append(Source(_loading or "<direct>", package))


def add_report(module: str) -> None:
    """Name the module whose import registers this plugin's figures and studies (``cerebx.report``).

    Parameters
    ----------
    module : str
        The module's import name, e.g. ``my_lab.report``.
    """
    report_modules.append(Source(_loading or "<direct>", module))


def add_bench_run(name: str, overrides: list[str]) -> None:
    """Have ``cerebx bench`` time ``cerebx run OVERRIDES`` (recording and checkpoints as configured) under
    ``name``; a name already taken is refused.

    Parameters
    ----------
    name : str
        The run's name in the bench's report.
    overrides : list of str
        The command line's overrides.
    """
    if name in bench_runs:
        raise ValueError(f"bench run {name!r} is already registered")
    bench_runs[name] = tuple(overrides)


_loaded: list[str] = []
_loading: str | None = None
_done = False
_broken: CerebxError | None = None


def _load_order(ep: Any) -> tuple[bool, str]:
    """``core`` first, then the plugins of each distribution (by distribution name) in the order its metadata
    lists them (a stable sort keeps that order), so the order never depends on where packages are installed."""
    dist = getattr(ep, "dist", None)
    return ep.name != "core", (dist.name if dist is not None else "")


def load_plugins() -> None:
    """Call every ``cerebx.plugins`` entry point once (those named in ``CEREBX_PLUGINS`` when it is set), in
    :func:`_load_order`. A plugin whose import or ``register()`` raises is a :class:`CerebxError` naming it and
    its error (one line), raised again by every later call."""
    global _done, _loading, _broken
    if _done:
        if _broken is not None:
            raise _broken
        return
    _done = True
    only = os.environ.get(ONLY_ENV)
    wanted = None if only is None else {n.strip() for n in only.split(",") if n.strip()}
    chosen = [ep for ep in sorted(entry_points(group=ENTRY_POINTS), key=_load_order)
              if wanted is None or ep.name in wanted]
    for ep in chosen:
        _loading = ep.name
        try:
            ep.load()()
        except Exception as err:  # whatever a third party's code raises: the command stops with one line
            _broken = _broken_plugin(ep, err, [e.name for e in chosen if e.name != ep.name])
            raise _broken from err
        finally:
            _loading = None
        _loaded.append(ep.name)


def _broken_plugin(ep: Any, err: Exception, others: list[str]) -> CerebxError:
    """The one line saying which plugin failed to load, why, and how to run without it."""
    first = next(iter(str(err).splitlines()), "")
    return CerebxError(f"plugin {ep.name} ({ep.value}): {type(err).__name__}: {first} (uninstall it, or load "
                       f"only the others: {ONLY_ENV}={','.join(others)})")


def loaded_plugins() -> list[str]:
    """Names of the plugins loaded so far, ``core`` first."""
    load_plugins()
    return list(_loaded)
