"""The figure registry: each thesis figure is one function of the runs, declared with the studies
(experiment presets, conf/report/studies.yaml) whose runs it needs.

A figure function takes the run set and an output stem (``reports/figures/fig3_4``), draws from
the logs, saves PNG + SVG and returns a :class:`Figure` with its caption and a table of the paper's
numbers beside cerebx's. When no run it needs is there it raises :class:`MissingRuns`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from cerebx.report.runs import RunSet  # noqa: E402


class MissingRuns(Exception):
    """The runs a figure needs are not in the run set (the message says which)."""


@dataclass
class Figure:
    files: list[Path]
    caption: str
    # header row + rows, typically [quantity, paper, cerebx]
    table: list[list[str]] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class FigureSpec:
    name: str
    title: str
    studies: tuple[str, ...]
    draw: Callable[[RunSet, Path], Figure]


FIGURES: dict[str, FigureSpec] = {}


def figure(name: str, title: str, studies: tuple[str, ...]) -> Callable:
    """Register a figure function under ``name`` (the thesis figure, e.g. ``fig3_4``)."""
    def deco(fn: Callable[[RunSet, Path], Figure]) -> Callable[[RunSet, Path], Figure]:
        if name in FIGURES:
            raise ValueError(f"figure {name!r} registered twice")
        FIGURES[name] = FigureSpec(name, title, tuple(studies), fn)
        return fn
    return deco


def all_figures() -> dict[str, FigureSpec]:
    """Every registered figure, in thesis order (importing the modules registers them)."""
    from cerebx.report import capolei, ch2, ch3, ch4, ch4_muscles, luque2011  # noqa: F401

    def order(name: str) -> tuple:
        parts = name.replace("fig", "").replace("table", "").split("_")
        return tuple(int(p) if p.isdigit() else 0 for p in parts)
    return {k: FIGURES[k] for k in sorted(FIGURES, key=order)}


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
    import numpy as np

    v = np.asarray(values, dtype=float)
    if v.size == 0:
        return "–"
    return f"{v.mean():.{nd}f} ± {v.std():.{nd}f}"
