"""Configuration is data: refuse every key that would make Hydra import or execute code, before Hydra acts.

Hydra instantiates ``_target_`` nodes (``hydra.callbacks``, launchers, sweepers), Python's logging
config calls ``()`` factories, ``hydra.searchpath`` pulls in YAML from elsewhere, ``hydra.job.env_set``
sets variables (``LD_PRELOAD``, ``PYTHONPATH``) for every process a run starts, and ``--experimental-rerun``
unpickles a file. All of these are refused in command-line overrides, in cerebx's own presets and in
every YAML file of a ``--config-dir``/``--config-path`` tree, one ``where: problem`` line each.
Launchers and sweepers are chosen by the name of an installed Hydra plugin (``hydra/launcher=joblib``),
which brings its own fixed target, or of a cerebx preset for one (``conf/hydra/launcher/slurm.yaml``: it
sets values of an installed plugin and is checked like every shipped preset); any other name is refused.
"""

from __future__ import annotations

import functools
import importlib.resources
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import yaml
from hydra.core.config_store import ConfigStore
from hydra.core.override_parser.overrides_parser import OverridesParser
from hydra.core.plugins import Plugins
from hydra.errors import HydraException

from cerebx import registry

CODE_KEYS = ("_target_", "()")
"""Keys that name a callable: Hydra's instantiate and logging.config's factory key."""

HYDRA_CODE_PATHS = ("callbacks", "searchpath", "job.env_set", "job.env_copy")
"""Parts of the ``hydra`` node that run code, load other config sources or set the environment."""

PLUGIN_GROUPS = ("launcher", "sweeper")
REFUSED_FLAGS = ("--experimental-rerun",)
CONFIG_DIR_FLAGS = ("--config-dir", "-cd", "--config-path", "-cp")

CONF_ROOT = Path(__file__).resolve().parent / "conf"


@functools.cache
def installed_plugins(group: str) -> tuple[str, ...]:
    """Options of ``hydra/<group>``: those registered by installed Hydra plugins (e.g. basic, joblib) and
    cerebx's own presets for them (``conf/hydra/<group>/*.yaml``, e.g. slurm)."""
    Plugins.instance()  # registers the installed plugins' configs
    repo = ConfigStore.instance().repo.get("hydra", {}).get(group, {})
    shipped = (p.stem for p in (CONF_ROOT / "hydra" / group).glob("*.yaml"))
    return tuple(sorted({*(name.removesuffix(".yaml") for name in repo), *shipped}))


def _why_code(path: str) -> str | None:
    """Why the dotted key ``path`` carries code, or None."""
    parts = path.split(".")
    if any(p in CODE_KEYS for p in parts):
        return "names a Python callable; a configuration can never import or execute code"
    for i, p in enumerate(parts):
        if p == "hydra":
            rest = ".".join(parts[i + 1:])
            for bad in HYDRA_CODE_PATHS:
                if rest == bad or rest.startswith(bad + "."):
                    return f"hydra.{bad} is not accepted (it runs code, adds config sources or sets the " \
                           "environment of every process)"
    return None


def _why_group(group: str, option: Any) -> str | None:
    """Why choosing ``option`` in config group ``group`` (``hydra/launcher``) carries code, or None."""
    g = group.strip("/").removeprefix("override ").strip("/")
    if not g.startswith("hydra/"):
        return None
    sub = g.removeprefix("hydra/")
    if sub == "callbacks":
        return "hydra/callbacks is not accepted (callbacks run code)"
    if sub in PLUGIN_GROUPS and option is not None and str(option) not in installed_plugins(sub):
        return f"unknown {sub} {option!r} (installed: {', '.join(installed_plugins(sub))})"
    return None


@functools.cache
def _parser():
    return OverridesParser.create()


def _walk(node: Any, prefix: str) -> Iterator[str]:
    """Every dotted key path of a nested mapping/list value."""
    if isinstance(node, dict):
        for k, v in node.items():
            path = f"{prefix}.{k}" if prefix else str(k)
            yield path
            yield from _walk(v, path)
    elif isinstance(node, list):
        for v in node:
            yield from _walk(v, prefix)


def check_overrides(overrides: list[str]) -> list[str]:
    """One line per command-line override that carries code (parsed as Hydra parses it)."""
    problems: list[str] = []
    parser = _parser()
    for text in overrides:
        try:
            o = parser.parse_override(text)
        except HydraException:
            # not parseable: Hydra will refuse it with its own message; still never let a callable through
            if any(k in text for k in CODE_KEYS):
                problems.append(f"{text.split('=', 1)[0]}: {_why_code('_target_')}")
            continue
        key = o.key_or_group
        if "/" in key:
            values = list(o.sweep_string_iterator()) if o.is_sweep_override() else [o.value()]
            for v in values:
                why = _why_group(key, v)
                if why:
                    problems.append(f"{key}: {why}")
                    break
        paths = [key, *_walk(o.value(), key)] if not o.is_sweep_override() else [key]
        for path in paths:
            why = _why_code(path)
            if why:
                problems.append(f"{path}: {why}")
                break
    return problems


def check_yaml_file(path: Path, label: str | None = None) -> list[str]:
    """One line per code-bearing key or defaults entry of one YAML file."""
    where = label or str(path)
    try:
        docs = list(yaml.load_all(path.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader)))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as err:
        return [f"{where}: not readable YAML ({str(err).splitlines()[0]})"]
    problems: list[str] = []
    for doc in docs:
        if not isinstance(doc, dict):
            continue
        for entry in doc.get("defaults") or []:
            if isinstance(entry, dict):
                for group, option in entry.items():
                    why = _why_group(str(group), option)
                    if why:
                        problems.append(f"{where}: defaults: {why}")
        for key in _walk({k: v for k, v in doc.items() if k != "defaults"}, ""):
            why = _why_code(key)
            if why:
                problems.append(f"{where}: {key}: {why}")
                break
    return problems


def check_tree(root: Path, label_root: Path | None = None) -> list[str]:
    """Every YAML file under ``root`` (a config tree: cerebx's own or a ``--config-dir``)."""
    if not root.is_dir():
        return [f"{root}: no such config folder"]
    problems: list[str] = []
    for f in sorted([*root.rglob("*.yaml"), *root.rglob("*.yml")]):
        problems += check_yaml_file(f, str(f.relative_to(label_root)) if label_root else str(f))
    return problems


def conf_roots() -> list[Path]:
    """cerebx's own preset tree, then each loaded plugin's (``registry.add_config_source``)."""
    registry.load_plugins()
    return [CONF_ROOT, *(Path(str(importlib.resources.files(s.target))) for s in registry.config_sources)]


@functools.cache
def _package_tree_problems() -> tuple[str, ...]:
    return tuple(line for root in conf_roots() for line in check_tree(root, root.parent))


def _flag_value(args: list[str], i: int) -> tuple[str | None, int]:
    a = args[i]
    if "=" in a:
        return a.split("=", 1)[1], i + 1
    return (args[i + 1] if i + 1 < len(args) else None), i + 2


def check_args(args: list[str]) -> list[str]:
    """Every code-bearing item of a ``cerebx run``/``validate`` command line, its presets and config trees."""
    problems = list(_package_tree_problems())
    overrides: list[str] = []
    i = 0
    while i < len(args):
        a = args[i]
        flag = a.split("=", 1)[0]
        if flag in REFUSED_FLAGS:
            problems.append(f"{flag}: not accepted (it unpickles a file, which can run code)")
            i += 1
        elif flag in CONFIG_DIR_FLAGS:
            value, i = _flag_value(args, i)
            if value is not None:  # a relative --config-path is relative to the app's module, or to here
                tree = next((d for d in (Path(value), CONF_ROOT.parent / value) if d.is_dir()), Path(value))
                problems += check_tree(tree)
        elif a.startswith("-"):
            i += 1
        else:
            overrides.append(a)
            i += 1
    return problems + check_overrides(overrides)
