"""Shared helpers of figure modules: saving a figure, panel letters, number formats. Importing it selects
matplotlib's file-only backend."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def save(fig, stem: Path) -> Path:
    """Write ``stem``.png and ``stem``.svg and close the figure; returns the PNG path."""
    stem.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(stem.with_suffix(".png"), dpi=110)
    fig.savefig(stem.with_suffix(".svg"))
    plt.close(fig)
    return stem.with_suffix(".png")


def panel_letter(ax, letter: str) -> None:
    """A bold panel letter above the axes' top-left corner."""
    ax.annotate(letter, (0, 1), xycoords="axes fraction", xytext=(-34, 8), textcoords="offset points",
                fontsize=13, fontweight="bold", va="bottom")


def fmt(x: float | None, nd: int = 3) -> str:
    return "–" if x is None else f"{x:.{nd}f}"


def mean_std(values, nd: int = 3) -> str:
    v = np.asarray(values, dtype=float)
    if v.size == 0:
        return "–"
    return f"{v.mean():.{nd}f} ± {v.std():.{nd}f}"
