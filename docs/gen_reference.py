"""Generates the reference pages at build time from the code itself, so they cannot drift: every registered kind
with its schema's fields (types, defaults, bounds, descriptions), every preset of every config group, and the
API pages. Run by mkdocs-gen-files during `mkdocs build`."""

from __future__ import annotations

import typing
from pathlib import Path

import mkdocs_gen_files
from pydantic import BaseModel
from pydantic_core import PydanticUndefined

from cerebx import registry
from cerebx.guard import conf_roots
from cerebx.schema.experiment import experiment_model

GROUP_TEXT = {
    "task": "desired trajectories (`+task=NAME`, or `task.kind`)",
    "plant": "what is controlled (`plant=NAME`)",
    "controller": "brain-side controllers and controller parts (`controller=NAME`)",
    "stage": "stages between the link and the plant (`robot`, `spinal`, `muscle`) or after the controller (`brain`)",
    "delay": "link delay models (`delay=NAME`)",
    "event": "plant events scheduled in `events`",
    "encoder": "cerebellar input encoders (`controller.mf`, `controller.cf`)",
    "connector": "connection rules of a spiking network's projections (`rule` of a projection; "
                 "[connectors](../models.md#connectors))",
    "plasticity": "learning rules of a spiking network's projections (`plasticity` of a projection; "
                  "[plasticity](../models.md#plasticity))",
}


def _type(annotation: typing.Any) -> str:
    text = getattr(annotation, "__name__", None) if isinstance(annotation, type) else None
    if text is None:
        text = str(annotation).replace("typing.", "").replace("NoneType", "None")
    return text.replace("|", "\\|")


def _bounds(field: typing.Any) -> str:
    marks = (("gt", ">"), ("ge", "≥"), ("lt", "<"), ("le", "≤"), ("min_length", "length ≥"), ("max_length", "length ≤"))
    return ", ".join(f"{sym} {getattr(m, attr)}" for m in field.metadata for attr, sym in marks if hasattr(m, attr))


def _default(field: typing.Any) -> str:
    if field.default is PydanticUndefined:
        return "required" if field.default_factory is None else "(computed)"
    value = field.default
    if isinstance(value, BaseModel):
        return "(see its fields)"
    text = repr(value) if not isinstance(value, str) else f"`{value}`"
    return text.replace("|", "\\|") if len(text) < 60 else text[:57].replace("|", "\\|") + "…"


def fields_table(schema: type[BaseModel]) -> list[str]:
    rows = ["| field | type | default | bounds | description |", "|---|---|---|---|---|"]
    for name, field in schema.model_fields.items():
        if name == "kind":
            continue
        desc = (field.description or "").replace("|", "\\|").replace("\n", " ")
        rows.append(f"| `{name}` | {_type(field.annotation)} | {_default(field)} | {_bounds(field)} | {desc} |")
    return rows if len(rows) > 2 else ["(no fields)"]


def summary(schema: type) -> str:
    doc = (schema.__doc__ or "").strip()
    return " ".join(doc.split("\n\n")[0].split())


def preset_comment(path: Path) -> str:
    lines = [ln[1:].strip() for ln in path.read_text().splitlines() if ln.startswith("#") and "@package" not in ln]
    return " ".join(lines[:2])


def neuron_kinds() -> list[str]:
    """The neuron models a network population can use (``populations.NAME.neuron.kind``): the members of the
    network schema's ``Neuron`` union, which is closed (not a registry)."""
    from cerebx.snn.schema import Neuron

    members = typing.get_args(typing.get_args(Neuron)[0])
    out = ["## Kinds: network neuron models", "",
           "`populations.NAME.neuron.kind` of a spiking network (the [model reference](../models.md#neuron-models) "
           "has the equations).", "", "| kind | what it is |", "|---|---|"]
    for m in members:
        kind = m.model_fields["kind"].default
        out.append(f"| [`{kind}`](#network-neuron-{kind}) | {summary(m).replace('|', '/')} |")
    out.append("")
    for m in members:
        kind = m.model_fields["kind"].default
        out += [f"### network neuron: `{kind}` {{#network-neuron-{kind}}}", "", summary(m), "",
                f"Schema `{m.__module__}.{m.__qualname__}`.", "", *fields_table(m), ""]
    return out


def options_page() -> str:
    registry.load_plugins()
    out = ["# Options (generated)", "",
           "Generated from the registries and the Pydantic schemas when the docs are built: every registered kind "
           "with its fields, and every preset of every config group, cerebx's and each installed plugin's. "
           "`cerebx validate +task=NAME ...` prints a composed configuration.", "",
           "## The experiment", "", "Top-level keys of every experiment:", "", *fields_table(experiment_model()), ""]
    for name, field in experiment_model().model_fields.items():  # nested blocks that are not kinds: recording, live
        block = field.annotation
        if isinstance(block, type) and issubclass(block, BaseModel):
            out += [f"### `{name}` {{#experiment-{name}}}", "", summary(block), "", *fields_table(block), ""]
    for group, reg in registry.GROUPS.items():
        out += [f"## Kinds: {group}", "", GROUP_TEXT.get(group, ""), "",
                "| kind | plugin | what it is |", "|---|---|---|"]
        for kind in reg.kinds():
            entry = reg[kind]
            out.append(f"| [`{kind}`](#{group}-{kind}) | {entry.plugin} | {summary(entry.schema).replace('|', '/')} |")
        out.append("")
        for kind in reg.kinds():
            entry = reg[kind]
            out += [f"### {group}: `{kind}` {{#{group}-{kind}}}", "", summary(entry.schema), "",
                    f"Plugin `{entry.plugin}`; schema `{entry.schema.__module__}.{entry.schema.__qualname__}`.", "",
                    *fields_table(entry.schema), ""]
    out += neuron_kinds()
    out += ["## Presets of the config groups", "",
            "Chosen on the command line as `group=NAME` (`+task=NAME`, `+experiment=NAME`).", ""]
    groups: dict[str, list[tuple[str, str, Path]]] = {}
    for root in conf_roots():
        source = "cerebx" if root.parent.name == "cerebx" or (root / "config.yaml").exists() else root.parent.name
        for f in sorted(root.rglob("*.yaml")):
            rel = f.relative_to(root)
            if len(rel.parts) < 2 or rel.parts[0] == "hydra":
                continue
            groups.setdefault("/".join(rel.parts[:-1]), []).append((f.stem, source, f))
    for group in sorted(groups):
        out += [f"### `{group}`", "", "| option | from | what it is |", "|---|---|---|"]
        for name, source, f in sorted(groups[group]):
            out.append(f"| `{name}` | {source} | {preset_comment(f).replace('|', '/')} |")
        out.append("")
    return "\n".join(out) + "\n"


API_MODULES = {
    "The public API (what a plugin imports)": ["cerebx.api", "cerebx.api.schema", "cerebx.report.api"],
    "The platform": ["cerebx.registry", "cerebx.signals", "cerebx.wiring", "cerebx.runfiles", "cerebx.config",
                     "cerebx.builders", "cerebx.build", "cerebx.loop.loop", "cerebx.loop.lifecycle",
                     "cerebx.loop.runner", "cerebx.delay_channel", "cerebx.loop.resume"],
    "Schemas": ["cerebx.schema.base", "cerebx.schema.experiment", "cerebx.schema.controller",
                "cerebx.schema.stages", "cerebx.schema.plant", "cerebx.schema.task", "cerebx.schema.delay",
                "cerebx.schema.events", "cerebx.schema.legacy"],
    "Controllers and stages": ["cerebx.controllers.base", "cerebx.persistence.state", "cerebx.controllers.snn.schema",
                               "cerebx.stages.base", "cerebx.stages.receivers", "cerebx.stages.check"],
    "Plants and tasks": ["cerebx.plants.base", "cerebx.plants.mujoco_arm", "cerebx.plants.check",
                         "cerebx.tasks.base"],
    "The spiking network and LWPR": ["cerebx.snn.schema", "cerebx.snn.network", "cerebx.lwpr.model"],
    "Recording": ["cerebx.recording.recorder", "cerebx.recording.reader", "cerebx.recording.summary"],
    "Report engine": ["cerebx.report.registry", "cerebx.report.runs", "cerebx.report.plot", "cerebx.metrics"],
}


def api_page() -> str:
    out = ["# API (generated)", "",
           "From the docstrings, when the docs are built. A plugin imports only the three modules of the first "
           "section (the [how-tos](../howto/index.md#the-public-api) say which for what); the modules below them "
           "are where those names are defined, and are internal.", ""]
    for section, modules in API_MODULES.items():
        out += [f"## {section}", ""]
        for module in modules:
            out += [f"::: {module}", "    options:", "      heading_level: 3", ""]
    return "\n".join(out) + "\n"


with mkdocs_gen_files.open("reference/options.md", "w") as fh:
    fh.write(options_page())
with mkdocs_gen_files.open("reference/api.md", "w") as fh:
    fh.write(api_page())
