"""Hydra composes, Pydantic validates: compose a config from overrides without running anything,
expand sweeps, and turn Hydra's composition errors into one ``path: message`` line each."""

from __future__ import annotations

import functools
import itertools
import math
import os
import re
import threading
from pathlib import Path
from typing import Any

import yaml
from hydra import compose as hydra_compose
from hydra import initialize_config_module
from hydra.core.global_hydra import GlobalHydra
from hydra.core.override_parser.overrides_parser import OverridesParser
from hydra.errors import HydraException
from omegaconf import DictConfig, OmegaConf, open_dict
from omegaconf.errors import OmegaConfBaseException

from cerebx.errors import ConfigError
from cerebx.estimate import Estimate, estimate, total
from cerebx.guard import check_args, conf_roots
from cerebx.schema.experiment import validate

MAX_SWEEP_JOBS = 1000
"""The largest command-line sweep cerebx accepts (every job is validated before the first starts)."""


def to_plain(cfg: DictConfig) -> dict[str, Any]:
    """The composed config as plain data (interpolations resolved, Hydra's own node dropped)."""
    try:
        data = OmegaConf.to_container(cfg, resolve=True, throw_on_missing=True)
    except OmegaConfBaseException as err:
        key = getattr(err, "full_key", None) or "config"
        raise ConfigError(f"{key}: {str(err).splitlines()[0]}") from None
    assert isinstance(data, dict)
    data.pop("hydra", None)
    return data


def _hydra_lines(err: Exception) -> list[str]:
    text = str(err)
    m = re.search(r"Could not find '([^']+)/([^']+)'", text)
    if m:
        group, option = m.group(1).split("/")[-1], m.group(2)
        avail = re.findall(r"^\t(\S+)$", text, flags=re.M)
        tail = f" (available: {', '.join(avail)})" if avail else ""
        return [f"{group}: unknown option '{option}'{tail}"]
    m = re.search(r"Could not override '([^']+)'", text)
    if m:
        key = m.group(1)
        if "." in key:
            return [f"{key}: not in the composed config (schema defaults are not); set it with +{key}=VALUE"]
        if "No match in the defaults list" in text and _is_group(key):
            return [f"{key}: none of the chosen options takes a {key} (it is chosen inside another option, "
                    f"e.g. network inside controller=snn)"]
        return [f"{key}: '{key}' has no default to override; add it with +{key}=NAME"]
    m = re.search(r"Could not append to config. An item is already at '([^']+)'", text)
    if m:
        return [f"{m.group(1)}: already set; drop the leading '+' to override it"]
    m = re.search(r"Key '([^']+)' is not in struct", text)
    if m:
        return [f"{m.group(1)}: unknown key (add it with +{m.group(1)}=... only if the schema has it)"]
    first = next((ln.strip() for ln in text.splitlines() if ln.strip()), type(err).__name__)
    return [f"overrides: {first}"]


def _is_group(name: str) -> bool:
    """``name`` is a config group of cerebx or of a plugin."""
    return any((root / name).is_dir() for root in conf_roots())


_COMPOSING = threading.RLock()  # Hydra's global state and the lazily built schema: one thread at a time


def compose(overrides: list[str]) -> DictConfig:
    """Compose ``conf/config.yaml`` with command-line style overrides (no output folders)."""
    return compose_with_choices(overrides)[0]


def compose_with_choices(overrides: list[str]) -> tuple[DictConfig, dict[str, str]]:
    """Compose, and return the option chosen in each config group (what ``cerebx run`` records as presets)."""
    problems = check_args(overrides) + _group_lists(overrides)
    if problems:
        raise ConfigError(problems)
    try:
        with _COMPOSING:
            GlobalHydra.instance().clear()
            with initialize_config_module(config_module="cerebx.conf", version_base="1.3"):
                cfg = hydra_compose(config_name="config", overrides=[o for o in overrides if not _is_hydra(o)],
                                    return_hydra_config=True)
    except (HydraException, OmegaConfBaseException, ValueError) as err:
        raise ConfigError(_hydra_lines(err)) from None
    choices = user_choices(cfg.hydra.runtime.choices)
    with open_dict(cfg):
        del cfg["hydra"]
    return cfg, choices


def _group_lists(overrides: list[str]) -> list[str]:
    """A config group given a list takes option names only (Hydra crashes on anything else in it)."""
    problems = []
    parser = OverridesParser.create()
    for text in overrides:
        if _is_hydra(text):
            continue
        try:
            o = parser.parse_override(text)
        except HydraException:
            continue  # Hydra refuses it with its own message
        value = None if o.is_sweep_override() else o.value()
        if isinstance(value, list) and _is_group(o.key_or_group.split("/")[-1]):
            bad = next((v for v in value if not isinstance(v, str)), None)
            if bad is not None:
                problems.append(f"{o.key_or_group}: a config group takes option names, got {bad!r} in the list")
    return problems


def user_choices(choices: Any) -> dict[str, str]:
    """The chosen option of each of cerebx's config groups (Hydra's own groups left out)."""
    return {k: v for k, v in choices.items() if not k.startswith("hydra") and v is not None}


def _is_hydra(override: str) -> bool:
    key = override.lstrip("+~").split("=", 1)[0]
    return key == "hydra" or key.startswith(("hydra.", "hydra/"))


def load(overrides: list[str]) -> tuple[Any, dict[str, Any]]:
    """Compose and validate; returns (validated experiment, plain resolved dict)."""
    with _COMPOSING:  # the report composes jobs in threads
        plain = to_plain(compose(overrides))
        try:
            return validate(plain), plain
        except ConfigError as err:
            raise ConfigError(_with_hints(err.problems, plain)) from None


def _with_hints(problems: list[str], plain: dict[str, Any]) -> list[str]:
    """Point a network/encoder size mismatch to the experiment presets made for that network."""
    ctrl = plain.get("controller")
    net = ctrl.get("network") if isinstance(ctrl, dict) else None
    presets = _presets_for_network(str(net.get("name"))) if isinstance(net, dict) else ()
    if not presets:
        return problems
    choices = " or +experiment=".join(presets)
    hint = f" (network {net.get('name')!r} comes with matching encoders in +experiment={choices})"
    return [p + hint if p.startswith("controller.mf.fibers_per_signal:") else p for p in problems]


@functools.cache
def _presets_for_network(name: str) -> tuple[str, ...]:
    """Experiment presets (of cerebx and its plugins) that choose network ``name`` for a spiking controller
    (``override /network: NAME``)."""
    out = []
    for root in conf_roots():
        for f in sorted((root / "experiment").glob("*.yaml")):
            try:
                doc = yaml.safe_load(f.read_text()) or {}
            except (OSError, yaml.YAMLError):
                continue
            chosen: dict[str, Any] = {}
            for entry in doc.get("defaults") or [] if isinstance(doc, dict) else []:
                if isinstance(entry, dict):
                    chosen.update(entry)
            if chosen.get("override /network") == name:
                out.append(f.stem)
    return tuple(out)


def expand_sweep(overrides: list[str]) -> list[list[str]]:
    """All override combinations of a ``-m`` sweep (``a=1,2 b=x,y`` -> four lists)."""
    try:
        parsed = OverridesParser.create().parse_overrides([o for o in overrides if not _is_hydra(o)])
    except HydraException as err:
        raise ConfigError(_hydra_lines(err)) from None
    choices: list[list[str]] = []
    for o in parsed:
        if o.is_sweep_override():
            key = o.get_key_element()
            choices.append([f"{key}={v}" for v in o.sweep_string_iterator()])
        else:
            choices.append([o.input_line])
    n = math.prod(len(c) for c in choices)
    if n > MAX_SWEEP_JOBS:
        raise ConfigError(f"sweep: {n:,} jobs; at most {MAX_SWEEP_JOBS:,} are run by one command (split the sweep)")
    return [list(c) for c in itertools.product(*choices)]


def check(overrides: list[str], multirun: bool = False, estimates: list | None = None) -> list[str]:
    """Every problem of every job the command would run, one line each (empty when all is well);
    the disk and time estimate of each valid job is appended to ``estimates``."""
    try:
        jobs = expand_sweep(overrides) if multirun else [overrides]
    except ConfigError as err:
        return err.problems
    seen: list[str] = []
    for job in jobs:
        try:
            exp, _ = load(job)
            if estimates is not None:
                estimates.append(estimate(exp))
        except ConfigError as err:
            prefix = f"[{' '.join(job)}] " if multirun and len(jobs) > 1 else ""
            for line in err.problems:
                if prefix + line not in seen:
                    seen.append(prefix + line)
    return seen


def estimate_jobs(jobs: list[list[str]]) -> tuple[Estimate, list[str]]:
    """The summed estimate of runs given by their overrides (``init_from`` left out: the run it names may
    not exist yet, and it changes no size); one line per job that does not validate."""
    parts, problems = [], []
    for overrides in jobs:
        try:
            parts.append(estimate(load([o for o in overrides if not o.lstrip("+").startswith("init_from=")])[0]))
        except ConfigError as err:
            problems.append(f"[{' '.join(overrides)}] {err.problems[0]}")
    return total(parts), problems


RUN_DIR_DEFAULTS = {"run": "runs", "sweep": "runs/multirun"}
"""The literal part of conf/config.yaml's hydra.run.dir / hydra.sweep.dir (before the first ${...})."""


def _literal_prefix(path: str) -> Path:
    parts = Path(path).parts
    keep = list(itertools.takewhile(lambda p: "${" not in p, parts))
    return Path(*keep) if keep else Path(".")


def _can_make(folder: Path) -> str | None:
    """Why ``folder`` cannot be a run folder (None if it can); whatever is created to find out is removed."""
    if folder.exists():
        if not folder.is_dir():
            return "it exists and is not a folder"
        probe = folder / f".cerebx-probe-{os.getpid()}"
        try:
            probe.mkdir()
            probe.rmdir()
        except OSError as err:
            return f"cannot create a folder in it ({err.strerror})"
        return None
    missing = [folder]
    while not missing[-1].parent.exists() and missing[-1].parent != missing[-1]:
        missing.append(missing[-1].parent)
    if missing[-1].parent.exists() and not missing[-1].parent.is_dir():
        return f"{missing[-1].parent} exists and is not a folder"  # an ancestor
    try:
        folder.mkdir(parents=True)
    except FileExistsError:  # made meanwhile by another cerebx started at the same moment (two sweeps)
        return None if folder.is_dir() else "it exists and is not a folder"
    except OSError as err:
        return f"cannot be created ({err.strerror})"
    for d in missing:
        try:
            d.rmdir()
        except OSError:  # another process put its run in it meanwhile (or removed it): left as it is
            break
    return None


def _output_dir(overrides: list[str], multirun: bool) -> tuple[str, str]:
    """(key, value) of the run or sweep folder a ``cerebx run`` command would use."""
    key = "hydra.sweep.dir" if multirun else "hydra.run.dir"
    value = RUN_DIR_DEFAULTS["sweep" if multirun else "run"]
    for o in overrides:
        k, _, v = o.lstrip("+").partition("=")
        if k == key:
            value = v.strip("'\"")
    return key, value


def output_root(overrides: list[str], multirun: bool) -> Path:
    """The literal part of the run or sweep folder (where the disk space is needed)."""
    return _literal_prefix(_output_dir(overrides, multirun)[1])


def check_output_dir(overrides: list[str], multirun: bool) -> list[str]:
    """The run (or sweep) folder of a ``cerebx run`` command can be made; one line if not."""
    key, value = _output_dir(overrides, multirun)
    why = _can_make(_literal_prefix(value))
    return [f"{key}: {value}: {why}"] if why else []
