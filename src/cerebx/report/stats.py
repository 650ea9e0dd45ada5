"""Uncertainty over independently learned seeds: a headline number as the mean of its seeds' values with a
95 % confidence interval (Student's t, two-sided), and whether the paper's number falls inside it.

With n seeds the interval is mean ± t(0.975, n − 1) · s / √n (s: the sample standard deviation). Three seeds
give t = 4.303: a wide interval, which is the honest answer to "could this 10 % difference be noise?".
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

# two-sided 95 % quantiles of Student's t, t(0.975, df) for df = 1 .. 30 (beyond: the normal's 1.960)
_T975 = (12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145, 2.131,
         2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042)


def t975(df: int) -> float:
    """The two-sided 95 % quantile of Student's t with ``df`` degrees of freedom (df ≥ 1)."""
    if df < 1:
        raise ValueError(f"degrees of freedom must be at least 1, got {df}")
    return _T975[df - 1] if df <= len(_T975) else 1.960


@dataclass(frozen=True)
class Interval:
    """One headline quantity over seeds: the mean of ``n`` per-seed values and its 95 % interval
    (``low`` = ``high`` = the value when n = 1), with the paper's number or range when it gives one.

    Parameters
    ----------
    mean, low, high : float
        The mean and the interval's ends.
    n : int
        Seeds.
    values : tuple of float
        The per-seed values.
    paper : (float, float), optional
        The paper's value (low == high) or range, in the same unit.
    """

    mean: float
    low: float
    high: float
    n: int
    values: tuple[float, ...] = ()
    paper: tuple[float, float] | None = None  # the paper's value (lo == hi) or range, in the same unit

    @property
    def has_interval(self) -> bool:
        return self.n >= 2 and math.isfinite(self.low) and math.isfinite(self.high)

    @property
    def paper_in_ci(self) -> str:
        """yes/no when the paper gives a number and there are at least two seeds, else –. A paper range
        counts as inside when it overlaps the interval."""
        if self.paper is None or not self.has_interval:
            return "–"
        lo, hi = self.paper
        return "yes" if lo <= self.high and hi >= self.low else "no"

    def text(self, nd: int = 3) -> str:
        """``mean [low, high] (n seeds)``, or the single value."""
        if not self.has_interval:
            return f"{self.mean:.{nd}f}"
        return f"{self.mean:.{nd}f} [{self.low:.{nd}f}, {self.high:.{nd}f}] ({self.n} seeds)"

    def as_json(self) -> dict:
        return {"mean": self.mean, "ci_low": self.low if self.has_interval else None,
                "ci_high": self.high if self.has_interval else None, "n": self.n, "values": list(self.values),
                "paper": list(self.paper) if self.paper is not None else None, "paper_in_ci": self.paper_in_ci}


def interval(values: Iterable[float], paper: float | Sequence[float] | None = None) -> Interval:
    """The mean and 95 % interval of per-seed ``values`` (non-finite ones left out).

    Parameters
    ----------
    values : iterable of float
        One number per seed.
    paper : float or (float, float), optional
        The paper's number, or its (low, high) range, which the interval is compared with.
    """
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=float)
    if v.size == 0:
        raise ValueError("no finite value to take an interval over")
    ref = None if paper is None else ((float(paper), float(paper)) if np.isscalar(paper)
                                      else (float(min(paper)), float(max(paper))))
    m = float(v.mean())
    if v.size == 1:
        return Interval(m, m, m, 1, (m,), ref)
    half = t975(v.size - 1) * float(v.std(ddof=1)) / math.sqrt(v.size)
    return Interval(m, m - half, m + half, int(v.size), tuple(float(x) for x in v), ref)


def with_intervals(table: list[list[str]], intervals: dict[str, Interval],
                   nd: int | Callable[[str], int] = 3) -> list[list[str]]:
    """The table (rows of quantity, …, cerebx) with "; over seeds <mean [low, high] (n seeds)>" after the
    cerebx cell of each row whose quantity has an interval over several seeds.

    Parameters
    ----------
    table : list of list of str
        The paper-vs-cerebx rows, the quantity first and cerebx's value last.
    intervals : dict of str to Interval
        The interval of each quantity (by the row's first cell).
    nd : int or callable
        Decimals, or a function of the quantity giving them.
    """
    digits = nd if callable(nd) else (lambda _q: nd)
    return [row if row[0] not in intervals or not intervals[row[0]].has_interval
            else [*row[:-1], f"{row[-1]}; over seeds {intervals[row[0]].text(digits(row[0]))}"] for row in table]
