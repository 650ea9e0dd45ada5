"""The badge of an unconverged figure: a band across the top of each of its images (PNG and SVG) saying
why its numbers are not a reproduction yet. The band is added above the figure, so it covers nothing."""

from __future__ import annotations

import html
import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

BAND = "#c62828"  # the band's colour (white text on it)
BAND_PX = 34  # band height in pixels (PNG)
FONT_PX = 17  # text height at most (shrunk to fit narrow images)
BAND_PT = 24.0  # band height in points (SVG)
FONT_PT = 12.0
CHAR_WIDTH = 0.58  # mean glyph width per font size of a bold sans face, to fit the text into the band


def stamp(png: Path, text: str) -> None:
    """Add the badge ``text`` above the PNG ``png`` and above its SVG twin (when there is one)."""
    stamp_png(png, text)
    svg = png.with_suffix(".svg")
    if svg.exists():
        stamp_svg(svg, text)


def _fit(width: float, size: float, text: str) -> float:
    return min(size, 0.94 * width / (CHAR_WIDTH * max(len(text), 1)))


def stamp_png(png: Path, text: str) -> None:
    img = plt.imread(png)
    h, w = img.shape[:2]
    dpi = 100.0
    fig = plt.figure(figsize=(w / dpi, (h + BAND_PX) / dpi), dpi=dpi)
    fig.figimage(img, xo=0, yo=0, origin="upper")
    band = BAND_PX / (h + BAND_PX)
    fig.patches.append(plt.Rectangle((0, 1 - band), 1, band, transform=fig.transFigure, color=BAND, zorder=5))
    px = _fit(w, FONT_PX, text)
    fig.text(0.5, 1 - band / 2, text, ha="center", va="center", color="white", fontweight="bold",
             fontsize=px * 72 / dpi, zorder=6)
    fig.savefig(png, dpi=dpi)
    plt.close(fig)


_SVG_OPEN = re.compile(r'<svg\b[^>]*\bheight="([\d.]+)pt"[^>]*\bviewBox="([\d.\s-]+)"[^>]*>')


def stamp_svg(svg: Path, text: str) -> None:
    """The same band in a matplotlib SVG: the page grows by the band, the drawing moves below it."""
    src = svg.read_text()
    m = _SVG_OPEN.search(src)
    if m is None:
        return
    x0, y0, w, h = (float(v) for v in m.group(2).split())
    tag = m.group(0)
    grown = (tag.replace(f'height="{m.group(1)}pt"', f'height="{float(m.group(1)) + BAND_PT:g}pt"')
             .replace(f'viewBox="{m.group(2)}"', f'viewBox="{x0:g} {y0:g} {w:g} {h + BAND_PT:g}"'))
    size = _fit(w, FONT_PT, text)
    band = (f'<rect x="{x0:g}" y="{y0:g}" width="{w:g}" height="{BAND_PT:g}" fill="{BAND}"/>'
            f'<text x="{x0 + w / 2:g}" y="{y0 + BAND_PT / 2:g}" fill="#ffffff" font-family="DejaVu Sans, sans-serif" '
            f'font-weight="bold" font-size="{size:.1f}" text-anchor="middle" dominant-baseline="central">'
            f"{html.escape(text)}</text>"
            f'<g transform="translate(0 {BAND_PT:g})">')
    end = src.rindex("</svg>")
    svg.write_text(src[:m.start()] + grown + band + src[m.end():end] + "</g>\n" + src[end:])
