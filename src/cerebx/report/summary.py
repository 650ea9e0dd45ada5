"""The table ``index.html`` opens with, and the shape checks as data: for each figure, whether the paper's
shapes hold in these runs (its :class:`~cerebx.report.registry.Check` s), whether the learning behind it has
converged (``report.convergence``) and the command that makes it converge."""

from __future__ import annotations

import html

from cerebx.report.convergence import FULL_PROFILE
from cerebx.report.registry import Check, Figure, FigureSpec

MARK = {True: "✓", False: "✗", None: "?"}
CLASS = {True: "ok", False: "bad", None: "na"}


def shape_rows(drawn: list[tuple[FigureSpec, Figure]]) -> list[list[str]]:
    """Every shape check of the drawn figures, a row each (``shapes.csv``)."""
    rows = [["figure", "claim", "holds", "numbers", "converged", "explained_at"]]
    for spec, fig in drawn:
        learning = fig.convergence
        conv = ("–" if learning is None else "unknown" if not learning.known
                else "yes" if learning.converged else "no")
        rows += [[spec.name, c.claim, {True: "yes", False: "no", None: "–"}[c.holds], c.numbers, conv,
                  c.explained_at or "–"] for c in fig.checks]
    return rows


def converge_command(name: str) -> str:
    """The command that runs a figure's studies with the full profile's trials, then draws it."""
    return f"cerebx report --profile full --figures {name}"


def summary_table(chosen: list[FigureSpec], drawn: dict[str, Figure]) -> str:
    """The table index.html opens with: each figure, whether its shapes hold in these runs, whether it has
    converged, and the command that makes it converge (or makes its runs)."""
    head = "<tr><th>figure</th><th>the paper's shape in these runs</th><th>converged</th><th>to converge</th></tr>"
    body = []
    for spec in chosen:
        link = f"<a href='#{spec.name}'>{html.escape(spec.name)}</a> {html.escape(spec.title)}"
        fig = drawn.get(spec.name)
        if fig is None:
            cmd = f"cerebx report --profile quick --figures {spec.name}"
            body.append(f"<tr><td>{html.escape(spec.name)} {html.escape(spec.title)}</td>"
                        f"<td class=na>not drawn: runs missing</td><td class=na>–</td><td><code>{cmd}</code></td></tr>")
            continue
        body.append(f"<tr><td>{link}</td>{shape_cell(fig)}{converged_cell(spec, fig)}</tr>")
    return f"<table class=summary>{head}{''.join(body)}</table>"


def checks_list(checks: list[Check]) -> str:
    """A figure's shape checks as an HTML list, each with its numbers."""
    return "".join(f"<li class={CLASS[c.holds]}>{MARK[c.holds]} {html.escape(c.claim)}"
                   f"{': ' + html.escape(c.numbers) if c.numbers else ''}{_why(c)}</li>" for c in checks)


def _why(c: Check) -> str:
    """The link to a failing check's explanation (docs-relative), or nothing."""
    if not c.explained_at:
        return ""
    return f" <span class=na>(why: <code>{html.escape(c.explained_at)}</code>)</span>"


def shape_cell(fig: Figure) -> str:
    told = [c for c in fig.checks if c.holds is not None]
    if not told:
        return "<td class=na>no shape check</td>"
    failed = [c for c in told if not c.holds]
    items = "".join(f"<li class={'ok' if c.holds else 'bad'}>{'✓' if c.holds else '✗'} {html.escape(c.claim)}"
                    f"{' (' + html.escape(c.numbers) + ')' if c.numbers and not c.holds else ''}{_why(c)}</li>"
                    for c in sorted(told, key=lambda c: c.holds))
    explained = sum(1 for c in failed if c.explained_at)
    verdict = (f"holds ({len(told)} of {len(told)})" if not failed
               else f"does not hold ({len(failed)} of {len(told)} fail, {explained} explained)")
    return f"<td class={'bad' if failed else 'ok'}><b>{verdict}</b><ul class=checks>{items}</ul></td>"


def converged_cell(spec: FigureSpec, fig: Figure) -> str:
    conv = fig.convergence
    if conv is None:
        return "<td class=na>– (nothing learns)</td><td>–</td>"
    n = len(conv.curves)
    if not n:
        return (f"<td class=na>unknown: its learning runs are not among these</td>"
                f"<td><code>{converge_command(spec.name)}</code></td>")
    if conv.converged:
        return f"<td class=ok>yes <span class=na>({n} learning curve{'s' * (n != 1)} level)</span></td><td>–</td>"
    short = conv.short
    cmd = (f"<code>{converge_command(spec.name)}</code>" if any(c.trials < c.needed for c in short)
           else "more learning than the full profile's")
    why = conv.badge.removeprefix("not converged: ").removesuffix(f"; {FULL_PROFILE}")
    return (f"<td class=bad>no: {html.escape(why)} <span class=na>({len(short)} of {n} learning "
            f"curve{'s' * (n != 1)} still falling)</span></td><td>{cmd}</td>")
