"""Hydra composes, Pydantic validates: compose a config from overrides without running anything,
expand sweeps, and turn Hydra's composition errors into one ``path: message`` line each."""

from __future__ import annotations

import contextlib
import functools
import itertools
import math
import os
import re
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import yaml
from hydra import initialize_config_module, version
from hydra._internal.config_loader_impl import ConfigLoaderImpl
from hydra._internal.defaults_list import create_defaults_list
from hydra._internal.hydra import Hydra
from hydra._internal.utils import create_automatic_config_search_path
from hydra.core.config_search_path import SearchPathQuery
from hydra.core.global_hydra import GlobalHydra
from hydra.core.override_parser.overrides_parser import OverridesParser
from hydra.errors import HydraException
from hydra.types import RunMode
from omegaconf import DictConfig, OmegaConf, open_dict
from omegaconf.errors import OmegaConfBaseException

from cerebx import runfiles
from cerebx.errors import ConfigError
from cerebx.estimate import estimate
from cerebx.guard import check_args, conf_roots
from cerebx.jobenv import source_checkout
from cerebx.schema.base import closest
from cerebx.schema.experiment import experiment_model, validate

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


def _hydra_lines(err: Exception, overrides: list[str] | None = None, config_dir: str | None = None) -> list[str]:
    text = str(err)
    m = re.search(r"Could not find '([^']+)/([^']+)'", text)
    if m:
        group, option = m.group(1).split("/")[-1], m.group(2)
        avail = re.findall(r"^\t(\S+)$", text, flags=re.M)
        tail = f" (available: {', '.join(avail)})" if avail else ""
        return [f"{group}: unknown option '{option}'{tail}"]
    m = re.search(r"Could not override '([^']+)'", text)
    if m:
        fix = re.search(r"use (\+\S+)", text)
        fix_text = fix.group(1) if fix else f"+{m.group(1)}=VALUE"
        return [_not_overridable(m.group(1), fix_text, overrides or [], config_dir)]
    m = re.search(r"Ambiguous value for argument '([^=']+)=([^']*)'", text)
    if m:
        return [f"{m.group(1)}: several values ({m.group(2)}): add -m to sweep them"]
    m = re.search(r"Could not append to config. An item is already at '([^']+)'", text)
    if m:
        return [f"{m.group(1)}: already set; drop the leading '+' to override it"]
    m = re.search(r"Key '([^']+)' is not in struct", text)
    if m:
        return [f"{m.group(1)}: unknown key (add it with +{m.group(1)}=... only if the schema has it)"]
    first = next((ln.strip() for ln in text.splitlines() if ln.strip()), type(err).__name__)
    return [f"overrides: {first}"]


def _not_overridable(key: str, fix: str, overrides: list[str], config_dir: str | None) -> str:
    """Why ``key=...`` matched nothing in the composed config (``fix``: the same override with a '+')."""
    if "." in key:
        return (_schema_problem(key, overrides, config_dir)
                or f"{key}: not in the composed config (schema defaults are not); set it with {fix}")
    if _is_group(key):
        owners = _group_owners(key)
        if owners:
            return f"{key}: none of the chosen options takes a {key}; it comes with {' or '.join(owners)}"
        return f"{key}: not in the defaults list; add it with {fix}"
    fields = experiment_model().model_fields
    if key in fields:
        return f"{key}: not in the composed config (the schema's default applies); set it with {fix}"
    close = closest(key, dict.fromkeys([*_groups(), *fields]))
    return f"{key}: no config group or key of that name" + (f"; did you mean {' or '.join(close)}?" if close else "")


def _schema_problem(key: str, overrides: list[str], config_dir: str | None) -> str | None:
    """What the schema says of a dotted ``key`` Hydra could not override, found by composing it with a '+': the
    problem at that key or above it (an unknown key names the closest known ones), or None if it is valid."""
    added = [f"+{o}" if o.split("=", 1)[0] == key else o for o in overrides]
    try:
        load(added, config_dir)
    except ConfigError as err:
        return next((p for p in err.problems if (key + ".").startswith(p.split(":", 1)[0] + ".")), None)
    return None


def _override_key(override: str) -> str:
    return override.lstrip("+~").split("=", 1)[0]


def through_references(overrides: list[str], config_dir: str | None, others: list[str] | None = None) -> list[str]:
    """One line per override of ``overrides`` whose key passes through a reference of the composed config, such
    as a population's ``neuron: ${...neurons.gc}``: Hydra cannot set a key inside one (it says "Could not
    override", then with a '+' "already set", and with '++' replaces the reference). The line names the key to
    set instead. ``others``: the whole command line (default ``overrides``)."""
    dotted = [o for o in overrides if not _is_hydra(o) and "." in _override_key(o)]
    if not dotted:
        return []
    base = [o for o in (others or overrides) if not _is_hydra(o) and "." not in _override_key(o)]
    try:
        with _COMPOSING, _hydra(config_dir):
            cfg = _compose_app(base)[0]
    except (HydraException, OmegaConfBaseException, ValueError):
        return []
    lines = []
    for o in dotted:
        parts = _override_key(o).split(".")
        node: Any = cfg
        for i, part in enumerate(parts[:-1]):
            if not isinstance(node, DictConfig) or part not in node:
                break
            if OmegaConf.is_interpolation(node, part):
                lines.append(_reference_line(o, parts, i, str(node._get_node(part)._value())))
                break
            node = node[part]
    return lines


def _reference_line(override: str, parts: list[str], i: int, text: str) -> str:
    """The line for ``override`` whose key passes through the reference ``text`` at ``parts[i]``."""
    key, ref, rest = ".".join(parts), ".".join(parts[: i + 1]), ".".join(parts[i + 1 :])
    m = re.fullmatch(r"\$\{(\.*)([\w.]+)\}", text)
    if m is None:
        return f"{key}: {ref} is computed ({text}); a key inside it cannot be overridden: replace {ref} whole"
    dots, path = len(m.group(1)), m.group(2)
    target = path if dots == 0 else ".".join([*parts[: i - dots + 1], path])
    value = override.split("=", 1)[1] if "=" in override else None
    use = f"~{target}.{rest}" if value is None else f"{target}.{rest}={value}"
    return (f"{key}: {ref} is a reference ({text}), and a key inside one cannot be overridden; use {use} (it "
            f"applies to everything that refers to {target}), or replace {ref} whole")


def _groups() -> list[str]:
    """Config groups of cerebx and its plugins (Hydra's own left out)."""
    return sorted({d.name for root in conf_roots() for d in root.iterdir() if d.is_dir() and d.name[0] not in "_."}
                  - {"hydra"})


@functools.cache
def _group_owners(group: str) -> tuple[str, ...]:
    """The options that choose ``group`` in their own defaults list (``controller=snn`` chooses a network);
    experiment presets, which choose any group, are left out."""
    owners = []
    for root in conf_roots():
        for f in sorted(root.glob("*/*.yaml")):
            if f.parent.name in ("experiment", "hydra"):
                continue
            try:
                doc = yaml.safe_load(f.read_text()) or {}
            except (OSError, yaml.YAMLError):
                continue
            entries = doc.get("defaults") or [] if isinstance(doc, dict) else []
            if any(isinstance(e, dict) and f"/{group}" in e for e in entries):
                owners.append(f"{f.parent.name}={f.stem}")
    return tuple(owners)


def _is_group(name: str) -> bool:
    """``name`` is a config group of cerebx or of a plugin."""
    return any((root / name).is_dir() for root in conf_roots())


_COMPOSING = threading.RLock()  # Hydra's global state and the lazily built schema: one thread at a time


def compose(overrides: list[str], config_dir: str | None = None) -> DictConfig:
    """Compose ``conf/config.yaml`` with command-line style overrides (no output folders)."""
    return compose_with_choices(overrides, config_dir)[0]


def compose_with_choices(overrides: list[str], config_dir: str | None = None) -> tuple[DictConfig, dict[str, str]]:
    """Compose, and return the option chosen in each config group (what ``cerebx run`` records as presets);
    ``config_dir`` is a ``--config-dir`` folder of presets."""
    flags = ["--config-dir", config_dir] if config_dir is not None else []
    problems = check_args([*flags, *overrides]) + _group_lists(overrides)
    if problems:
        raise ConfigError(problems)
    try:
        with _COMPOSING, _hydra(config_dir):
            cfg, chosen = _compose_app([o for o in overrides if not _is_hydra(o)])
    except (HydraException, OmegaConfBaseException, ValueError) as err:
        lines = through_references(overrides, config_dir) or _hydra_lines(err, overrides, config_dir)
        raise ConfigError(lines) from None
    return cfg, user_choices(chosen)


def _compose_app(overrides: list[str], keep_hydra: bool = False) -> tuple[DictConfig, dict[str, str | None]]:
    """Hydra's composition of ``config`` with ``overrides``, without Hydra's own configuration (launcher, sweeper,
    logging, output folders, help: a dozen configs and their schema, half the time of a composition), which
    only a running Hydra app reads; and the option chosen in each config group. The steps of Hydra's
    ``ConfigLoaderImpl.load_configuration`` (hydra-core 1.3) with the defaults list made without Hydra's tree
    (``tests/cerebx/test_config.py`` checks it composes what Hydra's ``compose`` does). The ``hydra`` node the
    primary config and the presets set (e.g. a preset's sweep, ``hydra.sweeper.params``) is dropped unless
    ``keep_hydra``."""
    loader = GlobalHydra.instance().config_loader()
    parsed, repo = loader._parse_overrides_and_create_caching_repo("config", overrides)
    loader.validate_sweep_overrides_legal(overrides=parsed, run_mode=RunMode.RUN, from_shell=False)
    defaults = create_defaults_list(repo=repo, config_name="config", overrides_list=parsed, prepend_hydra=False,
                                    skip_missing=False)
    cfg = loader._compose_config_from_defaults_list(defaults=defaults.defaults, repo=repo)
    OmegaConf.set_struct(cfg, True)
    ConfigLoaderImpl._apply_overrides_to_config(defaults.config_overrides, cfg)
    if not keep_hydra:
        with open_dict(cfg):
            cfg.pop("hydra", None)
    return cfg, dict(defaults.overrides.known_choices)


def preset_sweep_params(overrides: list[str]) -> dict[str, Any]:
    """The sweep the presets ``overrides`` choose declare (``hydra.sweeper.params``, values as written; empty
    when none). Raises Hydra's exception when they do not compose."""
    with _COMPOSING, _hydra(None):
        node = OmegaConf.select(_compose_app(overrides, keep_hydra=True)[0], "hydra.sweeper.params")
    params = OmegaConf.to_container(node, resolve=False) if node else {}
    assert isinstance(params, dict)
    return params


@contextlib.contextmanager
def _hydra(config_dir: str | None) -> Iterator[None]:
    """Hydra set up on cerebx's presets; a ``--config-dir`` folder is searched first, as ``cerebx run`` does."""
    GlobalHydra.instance().clear()
    if config_dir is None:
        with initialize_config_module(config_module="cerebx.conf", version_base="1.3"):
            yield
        return
    version.setbase("1.3")
    path = create_automatic_config_search_path(None, "cerebx.conf.app", None)
    path.prepend(provider="command-line", path=f"file://{os.path.abspath(config_dir)}",
                 anchor=SearchPathQuery(provider="schema"))
    Hydra.create_main_hydra2("app", path)
    try:
        yield
    finally:
        GlobalHydra.instance().clear()


def split_args(args: list[str]) -> tuple[list[str], str | None]:
    """The overrides of a ``cerebx run``/``validate`` command line and its ``--config-dir`` (flags dropped)."""
    overrides: list[str] = []
    config_dir = None
    i = 0
    while i < len(args):
        flag, eq, value = args[i].partition("=")
        if flag in ("--config-dir", "-cd"):
            config_dir, i = (value, i + 1) if eq else (args[i + 1] if i + 1 < len(args) else None, i + 2)
            continue
        if not args[i].startswith("-"):
            overrides.append(args[i])
        i += 1
    return overrides, config_dir


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


def load(overrides: list[str], config_dir: str | None = None) -> tuple[Any, dict[str, Any]]:
    """Compose the configuration of a command line's overrides (Hydra) and validate it (Pydantic).

    Parameters
    ----------
    overrides : list of str
        As on the command line, e.g. ``["+experiment=demo", "trials=3"]``.
    config_dir : str, optional
        A folder of presets used in place of cerebx's own ``conf/``.

    Returns
    -------
    (ExperimentConfig, dict)
        The validated experiment, and the plain resolved configuration it was made from.
    """
    with _COMPOSING:  # the report composes jobs in threads
        plain = to_plain(compose(overrides, config_dir))
        try:
            return validate(plain), plain
        except ConfigError as err:
            added = [o for o in overrides if o.startswith("+") and "." in _override_key(o)]
            raise ConfigError((added and through_references(added, config_dir, overrides))
                              or _with_hints(err.problems, plain)) from None


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


def check(overrides: list[str], multirun: bool = False, estimates: list | None = None,
          config_dir: str | None = None, valid: list | None = None) -> list[str]:
    """Every problem of every job the command would run, one line each (empty when all is well);
    the disk and time estimate of each valid job is appended to ``estimates``, and (its overrides, the
    validated experiment, its plain config) to ``valid``; ``config_dir`` is a ``--config-dir`` folder of presets."""
    try:
        jobs = expand_sweep(overrides) if multirun else [overrides]
    except ConfigError as err:
        return err.problems
    seen: list[str] = []
    for job in jobs:
        try:
            exp, plain = load(job, config_dir)
            if estimates is not None:
                estimates.append(estimate(exp))
            if valid is not None:
                valid.append((job, exp, plain))
        except ConfigError as err:
            prefix = f"[{' '.join(job)}] " if multirun and len(jobs) > 1 else ""
            for line in err.problems:
                if prefix + line not in seen:
                    seen.append(prefix + line)
    return seen


def load_jobs(jobs: list[list[str]]) -> tuple[list[Any | None], list[str | None]]:
    """The validated experiment of each run given by its overrides (``init_from`` left out: the run it names
    may not exist yet, and it changes no size or pace), and beside it None; or None and the line saying why it
    does not validate."""
    exps: list[Any | None] = []
    problems: list[str | None] = []
    for overrides in jobs:
        try:
            exps.append(load([o for o in overrides if not o.lstrip("+").startswith("init_from=")])[0])
            problems.append(None)
        except ConfigError as err:
            exps.append(None)
            problems.append(f"[{' '.join(overrides)}] {err.problems[0]}")
    return exps, problems


RUN_DIR_DEFAULTS = {"run": "runs", "sweep": "runs/multirun"}
"""The literal part of conf/config.yaml's hydra.run.dir / hydra.sweep.dir (before the first ${...})."""


def _literal_prefix(path: str) -> Path:
    parts = Path(path).parts
    keep = list(itertools.takewhile(lambda p: "${" not in p, parts))
    return Path(*keep) if keep else Path(".")


PROBE = ".cerebx-probe-"
"""The name (and the process id) of the folder :func:`_can_make` makes and removes in a folder to see that runs can
go there; another cerebx started at the same moment (a report's sweep in parts) may see it meanwhile."""


def _can_make(folder: Path) -> str | None:
    """Why ``folder`` cannot be a run folder (None if it can); whatever is created to find out is removed."""
    if folder.exists():
        if not folder.is_dir():
            return "it exists and is not a folder"
        probe = folder / f"{PROBE}{os.getpid()}"
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
    """(key, value) of the run or sweep folder a ``cerebx run`` command would use (the default: the literal
    part of conf/config.yaml's, below which each run makes a folder of its own)."""
    key = "hydra.sweep.dir" if multirun else "hydra.run.dir"
    value, given = RUN_DIR_DEFAULTS["sweep" if multirun else "run"], False
    for o in overrides:
        k, _, v = o.lstrip("+").partition("=")
        if k == key:
            value, given = v.strip("'\""), True
    return key, value if given else value + "/${now}"


def output_root(overrides: list[str], multirun: bool) -> Path:
    """The literal part of the run or sweep folder (where the disk space is needed)."""
    return _literal_prefix(_output_dir(overrides, multirun)[1])


def check_output_dir(overrides: list[str], multirun: bool, probe: bool = True) -> list[str]:
    """The run (or sweep) folder of a ``cerebx run`` command is a new folder, or one of runs, and can be made
    (``probe``: try it; ``cerebx validate`` does not); one line if not."""
    key, value = _output_dir(overrides, multirun)
    if not value.isprintable():
        return [f"{key}: {value!r}: not a folder name (it holds control characters)"]
    why = _refused_folder(value) or (_can_make(_literal_prefix(value)) if probe else None)
    return [f"{key}: {value}: {why}" if value.strip() else f"{key}: {why}"] if why else []


RUN_MARKERS = (runfiles.SUMMARY, runfiles.MCAP, runfiles.HYDRA, runfiles.CHECKPOINT, runfiles.ERROR, "multirun.yaml")
"""What marks a folder as a run's or a sweep's: cerebx writes into such a folder again (resume, reuse)."""


def _refused_folder(value: str) -> str | None:
    """Why ``value`` cannot be a run or sweep folder whatever the disk allows: empty, the working directory, the
    source checkout, or an existing folder that holds other things than runs and logs (``src``)."""
    new = "give a new folder, e.g. runs/mine"
    if not value.strip():
        return f"empty; {new}"
    if "${" in value:
        return None  # resolved per run (a time stamp, a chosen option): a folder of its own
    try:
        folder = Path(value).resolve()
        if folder == Path.cwd().resolve():
            return f"is the working directory; {new}"
        if folder == source_checkout():
            return f"is the cerebx source checkout; {new}"
        if folder.is_dir() and not _holds_runs(folder):
            return f"is an existing folder that holds no run; {new} (or an empty one)"
    except (OSError, RuntimeError):  # unreadable, a symlink loop: for the creation probe to say
        return None
    return None


def _holds_runs(folder: Path) -> bool:
    """``folder`` is empty, a run's or a sweep's (its jobs' folders, even of a sweep cut short before it wrote
    multirun.yaml), or holds only logs (the report writes a study's log first). Two sweeps started together
    into one folder (a report's sweep in parts) see each other's half-made entries: the other's creation probe
    and a job folder Hydra has made but not yet written in; empty folders hold nothing a run could spoil."""
    try:
        entries = [e for e in folder.iterdir() if not e.name.startswith(PROBE)]
    except OSError:
        return True  # not readable: whether a run can go there is for the creation probe to say
    return (any(e.name in RUN_MARKERS for e in entries)
            or all((e.is_file() and e.suffix == ".log") or (e.is_dir() and _is_run_or_empty(e)) for e in entries))


def _is_run_or_empty(folder: Path) -> bool:
    try:
        names = [e.name for e in folder.iterdir()]
    except OSError:
        return False
    return not names or any(n in RUN_MARKERS for n in names)
