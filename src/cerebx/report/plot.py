"""Shared helpers of figure modules: saving a figure, panel letters, number formats. Importing it selects
matplotlib's file-only backend."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def save(fig, stem: Path) -> Path:
    """Write ``stem``.png and ``stem``.svg and close the figure; returns the PNG path.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    stem : Path
        The files' path without suffix (a figure function's ``stem``).
    """
    stem.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(stem.with_suffix(".png"), dpi=110)
    fig.savefig(stem.with_suffix(".svg"))
    plt.close(fig)
    return stem.with_suffix(".png")


def panel_letter(ax, letter: str) -> None:
    """A bold panel letter above the axes' top-left corner.

    Parameters
    ----------
    ax : matplotlib.axes.Axes
        The panel.
    letter : str
        Its letter (``"A"``, ``"B"``, ...).
    """
    ax.annotate(letter, (0, 1), xycoords="axes fraction", xytext=(-34, 8), textcoords="offset points",
                fontsize=13, fontweight="bold", va="bottom")


def fmt(x: float | None, nd: int = 3) -> str:
    """``x`` with ``nd`` decimals, or a dash for None.

    Parameters
    ----------
    x : float or None
        The number.
    nd : int
        Decimals.
    """
    return "–" if x is None else f"{x:.{nd}f}"


def mean_std(values, nd: int = 3) -> str:
    """"mean ± standard deviation" of ``values`` with ``nd`` decimals, or a dash for none.

    Parameters
    ----------
    values : array_like
        The numbers.
    nd : int
        Decimals.
    """
    v = np.asarray(values, dtype=float)
    if v.size == 0:
        return "–"
    return f"{v.mean():.{nd}f} ± {v.std():.{nd}f}"
