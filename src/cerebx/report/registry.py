"""The figure registry: each figure of a reproduction is one function of the runs, declared with the
studies (experiment presets run once or as a sweep) whose runs it needs.

Figures and studies come from plugins: a plugin names its report module (``registry.add_report``), whose
import registers figures with :func:`figure` and its studies file with :func:`studies`. A figure function
takes the run set and an output stem (``reports/figures/<name>``), draws from the logs, saves PNG + SVG
(``report.plot.save``) and returns a :class:`Figure` with its caption, a table of the paper's numbers
beside cerebx's, the paper's shapes tested on the runs (:class:`Check`) and the convergence of the learning
behind it (``report.convergence``). When no run it needs is there it raises :class:`MissingRuns`.

A headline number learned from several independent seeds is given as an :class:`~cerebx.report.stats.Interval`
(``Figure.intervals``, keyed by its table row's quantity): ``paper_vs_cerebx.csv`` then carries its 95 %
interval and whether the paper's number falls inside. A check that fails in a profile and whose cause is
written up is linked to that page by the plugin's explanations file (:func:`explanations`): the report
sets its ``explained_at``.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from cerebx import registry
from cerebx.report.convergence import Convergence
from cerebx.report.runs import RunSet
from cerebx.report.stats import Interval


class MissingRuns(Exception):
    """The runs a figure needs are not in the run set (the message says which)."""


@dataclass(frozen=True)
class Check:
    """One shape of the paper tested on the runs (an ordering, a trend): the claim in the paper's terms,
    whether it holds in these runs (None: they cannot tell) and the numbers it was decided on.

    Parameters
    ----------
    claim : str
        The claim, in the paper's terms.
    holds : bool or None
        Whether it holds in these runs (None: they cannot tell).
    numbers : str
        The numbers it was decided on.
    explained_at : str, optional
        Where a failing check's cause is shown (a docs page and anchor; set from the plugin's explanations file).
    """

    claim: str
    holds: bool | None
    numbers: str = ""
    # where a failing check's cause is shown (a docs page and anchor, from the plugin's explanations file)
    explained_at: str | None = None

    def __post_init__(self) -> None:
        # a comparison of numpy values gives numpy.bool_, which figures.json would write as the string "True"
        if self.holds is not None:
            object.__setattr__(self, "holds", bool(self.holds))


@dataclass
class Figure:
    """What a figure function returns: its files, caption, the paper-vs-cerebx table and the checks.

    Parameters
    ----------
    files : list of Path
        The images written (:func:`save` returns each PNG).
    caption : str
        The caption.
    table : list of list of str
        Header row and rows, typically [quantity, paper, cerebx].
    notes : list of str
        Notes under the table.
    checks : list of Check
        The paper's shapes tested on the runs.
    convergence : Convergence, optional
        The plateau tests of the learning behind the figure; None: nothing learns in its runs.
    intervals : dict of str to Interval
        Headline quantities over independently learned seeds, keyed by the quantity of their table row.
    """
    files: list[Path]
    caption: str
    # header row + rows, typically [quantity, paper, cerebx]
    table: list[list[str]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    checks: list[Check] = field(default_factory=list)
    # the plateau tests of the learning behind the figure; None: nothing learns in its runs
    convergence: Convergence | None = None
    # headline quantities over independently learned seeds, keyed by the quantity of their table row
    intervals: dict[str, Interval] = field(default_factory=dict)

    @property
    def shape_holds(self) -> bool | None:
        """Whether every shape check holds (None: no check could tell)."""
        told = [c.holds for c in self.checks if c.holds is not None]
        return all(told) if told else None


@dataclass(frozen=True)
class FigureSpec:
    name: str
    title: str
    studies: tuple[str, ...]
    draw: Callable[[RunSet, Path], Figure]
    optional: tuple[str, ...] = ()
    """Of ``studies``: those the figure reads when their runs exist and is drawn without (sensitivity rows)."""

    def needs(self, study: str) -> bool:
        """Whether the figure cannot stand for the paper's without ``study``'s runs."""
        return study in self.studies and study not in self.optional


FIGURES: dict[str, FigureSpec] = {}
STUDY_FILES: list[Path] = []
EXPLANATION_FILES: list[Path] = []


def figure(name: str, title: str, studies: tuple[str, ...], optional: tuple[str, ...] = ()) -> Callable:
    """Register a figure function under ``name`` (unique across plugins); a decorator.

    The decorated function takes the runs and a file stem and returns a :class:`Figure`
    (``(runs: RunSet, stem: Path) -> Figure``); it raises :class:`MissingRuns` when its runs are absent.

    Parameters
    ----------
    name : str
        The figure's name (``cerebx report --figures NAME``), e.g. ``fig3_4``.
    title : str
        The title on the figure's page.
    studies : tuple of str
        The studies (from the plugin's studies file) whose runs the figure draws.
    optional : tuple of str
        Of ``studies``, those it is drawn without when their runs are missing (e.g. a sensitivity study a quick
        report borrows from the full profile); a report leaves out a figure missing any other of its studies.
    """
    def deco(fn: Callable[[RunSet, Path], Figure]) -> Callable[[RunSet, Path], Figure]:
        if name in FIGURES:
            raise ValueError(f"figure {name!r} registered twice")
        unknown = [o for o in optional if o not in studies]
        if unknown:
            raise ValueError(f"figure {name!r}: optional studies {unknown} are not among its studies")
        FIGURES[name] = FigureSpec(name, title, tuple(studies), fn, tuple(optional))
        return fn
    return deco


def studies(path: Path) -> None:
    """Register a studies file (YAML, ``report/studies.py``) whose runs the plugin's figures need.

    Parameters
    ----------
    path : Path
        The YAML file, usually beside the plugin's report module.
    """
    path = Path(path).resolve()
    if path not in STUDY_FILES:
        STUDY_FILES.append(path)


def explanations(path: Path) -> None:
    """Register an explanations file (YAML, ``report/explain.py``): for checks that fail, the docs page that
    shows why, with the runs that show the cause.

    Parameters
    ----------
    path : Path
        The YAML file, usually beside the plugin's report module.
    """
    path = Path(path).resolve()
    if path not in EXPLANATION_FILES:
        EXPLANATION_FILES.append(path)


def load_reports() -> None:
    """Import the report module of every loaded plugin (their imports register figures and studies)."""
    registry.load_plugins()
    for source in registry.report_modules:
        importlib.import_module(source.target)


def all_figures() -> dict[str, FigureSpec]:
    """Every registered figure, in :func:`figure_order`."""
    load_reports()
    return {k: FIGURES[k] for k in sorted(FIGURES, key=figure_order)}


def figure_order(name: str) -> tuple:
    """Sort key of a figure name: the numbers of its figure part (``x3_4`` -> (3, 4); ``fig`` and ``table``
    prefixes dropped); a part that is not a number counts 0 (so a name with a paper prefix reads as zeros); at
    equal numbers a name without any digit (a study that is no paper's figure) comes first, then
    the registration order (plugins load in ``registry.load_plugins``'s order)."""
    parts = name.replace("fig", "").replace("table", "").split("_")
    return tuple(int(p) if p.isdigit() else 0 for p in parts), any(c.isdigit() for c in name)
