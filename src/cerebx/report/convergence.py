"""Whether the learning behind a figure has levelled off, decided from the runs: the plateau test.

A learning curve (the MAE per trial of a run that learns) has levelled off when the mean of its last window
of trials is at most a tolerance below the mean of the window before (relative to the last). The window is a
fraction of the trials the paper's shape needs (at least a few trials), so the test asks the same question of
a short and a long run: did the error still fall over the last tenth of the learning the paper needed? A run
shorter than two windows has not levelled off. A curve that rises is level (no longer learning; whether it is
stable is a shape of its own).

The rule is data: each study that learns carries its :class:`PlateauRule` (the trials of its full profile,
where the paper's shape appears, and its ``plateau`` settings in the plugin's studies file, defaults below;
``report.studies.study_plateau``).

A figure is converged when every learning curve behind it has levelled off. When it is not, the report puts
a badge on its images ("not converged: N of M learning trials; run --profile full"), the same words in its
caption, and "no" in the ``converged`` column of its paper-vs-cerebx rows.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cerebx.report.runs import Run, RunSet
from cerebx.report.schema import MIN_WINDOW, TOLERANCE, WINDOW_FRACTION

FULL_PROFILE = "run --profile full"


@dataclass(frozen=True)
class PlateauRule:
    """How one learning curve is tested: ``needed`` trials make the paper's shape (the full profile's count);
    the window is ``window_fraction`` of them, at least ``min_window``; the last window may fall at most
    ``tolerance`` (relative) below the one before."""

    needed: int
    window_fraction: float = WINDOW_FRACTION
    tolerance: float = TOLERANCE
    min_window: int = MIN_WINDOW

    @property
    def window(self) -> int:
        return max(self.min_window, int(round(self.window_fraction * self.needed)))


@dataclass(frozen=True)
class Plateau:
    """The plateau test of one learning curve."""

    label: str
    trials: int  # trials of the run (as a study counts them: warm-up trials included)
    needed: int  # trials at which the paper's shape appears (the full profile's count)
    window: int
    before: float | None = None  # mean MAE of the window before the last (None: fewer than two windows)
    last: float | None = None  # mean MAE of the last window
    tol: float = TOLERANCE

    @property
    def level(self) -> bool:
        """Whether the curve no longer falls by more than ``tol`` from one window to the next."""
        if self.before is None or self.last is None:
            return False
        return self.before - self.last <= self.tol * abs(self.last)

    def numbers(self) -> str:
        """The numbers behind the verdict, in words."""
        if self.before is None or self.last is None:
            return (f"{self.trials} trials, fewer than two windows of {self.window} (of the {self.needed} trials "
                    "the shape needs)")
        fall = (self.before - self.last) / abs(self.last) if self.last else float("inf")
        verdict = "level" if self.level else "still falling"
        return (f"last two windows of {self.window} trials {self.before:.4f} → {self.last:.4f} rad "
                f"({fall:+.0%} fall, tolerance {self.tol:.0%}): {verdict} after {self.trials} of {self.needed} trials")

    def describe(self) -> str:
        return f"{self.label}: {self.numbers()}"


def plateau(mae: Sequence[float] | np.ndarray, rule: PlateauRule | int, label: str = "",
            trials: int | None = None) -> Plateau:
    """The plateau test of ``mae`` (MAE per measured learning trial) by ``rule``.

    Parameters
    ----------
    mae : sequence of float
        The MAE of each measured learning trial, rad.
    rule : PlateauRule or int
        The test; an int: the trials the paper's shape needs, with the default window and tolerance.
    label : str
        The curve's name in the figure's table.
    trials : int, optional
        The run's trial count (default: the curve's length).
    """
    rule = rule if isinstance(rule, PlateauRule) else PlateauRule(int(rule))
    m = np.asarray(mae, dtype=float)
    n = int(m.size if trials is None else trials)
    w, tol = rule.window, rule.tolerance
    if m.size < 2 * w or not np.isfinite(m[-2 * w:]).all():
        return Plateau(label, n, rule.needed, w, tol=tol)
    return Plateau(label, n, rule.needed, w, float(m[-2 * w:-w].mean()), float(m[-w:].mean()), tol)


@dataclass(frozen=True)
class Convergence:
    """The plateau tests of every learning curve behind a figure.

    Parameters
    ----------
    curves : tuple of Plateau
        One test per learning curve.
    rows : callable, optional
        Which paper-vs-cerebx rows (by their quantity) the learning concerns (every row when None); the
        others (a baseline, a measurement without learning) get "–" in the ``converged`` column.
    """

    curves: tuple[Plateau, ...]
    rows: Callable[[str], bool] | None = None

    @property
    def converged(self) -> bool:
        """Every learning curve levelled off (True also when none was found: see ``known``)."""
        return all(c.level for c in self.curves)

    @property
    def known(self) -> bool:
        """Whether any learning curve behind the figure was found (its runs may start from runs not given)."""
        return bool(self.curves)

    @property
    def short(self) -> tuple[Plateau, ...]:
        """The curves that have not levelled off."""
        return tuple(c for c in self.curves if not c.level)

    @property
    def badge(self) -> str | None:
        """The badge of an unconverged figure (None when converged), from its least converged curve: how many
        learning trials of how many the shape needs, or, at that count, that it still falls."""
        short = self.short
        if not short:
            return None
        worst = min(short, key=lambda c: c.trials / c.needed)
        if worst.trials >= worst.needed:
            return f"not converged: MAE still falling after {worst.trials} learning trials"
        return f"not converged: {worst.trials} of {worst.needed} learning trials; {FULL_PROFILE}"

    def flag(self, quantity: str) -> str:
        """The ``converged`` cell of one paper-vs-cerebx row."""
        if self.rows is not None and not self.rows(quantity):
            return "–"
        if not self.known:
            return "unknown"
        return "yes" if self.converged else f"no ({self.badge.removeprefix('not converged: ')})"

    def describe(self) -> list[str]:
        return [c.describe() for c in self.curves]

    def as_json(self) -> dict:
        """The verdict, its badge and every plateau test, for figures.json."""
        return {"converged": self.converged if self.known else None, "badge": self.badge,
                "curves": [{"label": c.label, "trials": c.trials, "needed": c.needed, "window": c.window,
                            "before": c.before, "last": c.last, "tolerance": c.tol, "level": c.level}
                           for c in self.curves]}


def learning_convergence(curves: Iterable[tuple[str, Run, PlateauRule | int]], runs: RunSet | None = None,
                         rows: Callable[[str], bool] | None = None, own: bool = False) -> Convergence:
    """The convergence of the learning behind ``curves``: the MAE per measured trial of the run that
    learned each run's state from scratch (its origin: the run itself, or the one it started from).

    A run whose origin cannot be found is left out; an origin behind several runs is tested once, under the
    first run's label.

    Parameters
    ----------
    curves : iterable of (str, Run, PlateauRule or int)
        Each curve's label, its run and its study's rule.
    runs : RunSet, optional
        Where origins are looked up first (else on disk).
    rows : callable, optional
        Which paper-vs-cerebx rows (by their quantity) the learning concerns (default: every row).
    own : bool
        Test each run's own curve (runs whose learning from a state is the experiment).
    """
    seen: dict[Path, Plateau] = {}
    for label, run, rule in curves:
        origin = run if own else (runs if runs is not None else RunSet()).origin(run)
        if origin is None:
            continue
        key = origin.dir.absolute()
        if key not in seen:
            name = label if origin is run else f"{label} (learnt in {origin.dir.parent.name}/{origin.dir.name})"
            seen[key] = plateau(origin.mae, rule, name, trials=origin.trials)
    return Convergence(tuple(seen.values()), rows)


def combined(*parts: Convergence) -> Convergence:
    """The plateau tests of several convergences together (the first one's rows).

    Parameters
    ----------
    *parts : Convergence
        The convergences to join, in the order their tests are listed.
    """
    return Convergence(tuple(c for p in parts for c in p.curves), parts[0].rows if parts else None)
