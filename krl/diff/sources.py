"""The change report's own views of the files it names (``krl report --links source``, issue 63).

A link of the report (a finding, a changed line, a point, a run's end) opens the file at its
line in the page itself: an appendix holds each file a link names, line by line, and the link
is ``#src-<n>-L<line>``, the id of that line; the browser scrolls to it and the page marks it
(``:target``). A ``file:`` URL of a ``.src`` made Chromium download the file instead of showing
it, and a printed report cannot follow it anyway. The appendix is not printed.

Files are read as ``krl check`` reads them (krl.source.read_source: the limits, the decoding)
and reach the page only through the project's Jinja environment (autoescape). The appendix
holds whole files up to :data:`krl.limits.MAX_REPORT_SOURCE_CHARS` characters in all; past it a
file shows the lines around each line a link names (``WINDOW`` before and after).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from markupsafe import Markup

from krl.diagnostics.render import split_lines
from krl.limits import MAX_REPORT_SOURCE_CHARS
from krl.render import render_html
from krl.source import read_source

__all__ = ["SourceViews", "WINDOW"]

#: lines shown before and after a linked line of a file past the appendix's budget
WINDOW = 12


@dataclass
class _File:
    n: int
    side: str
    file: str
    lines: list[str]
    wanted: set[int] = field(default_factory=set)


class SourceViews:
    """The files the links of one report name, by side ("old", "new"): `roots` gives the folder
    of each side on this machine (None: its files cannot be shown, e.g. a side whose archive
    was extracted and removed)."""

    def __init__(self, roots: dict[str, str | None], budget: int = MAX_REPORT_SOURCE_CHARS) -> None:
        self.roots = roots
        self.budget = budget
        self._files: dict[tuple[str, str], _File | None] = {}

    def href(self, side: str, file: str, line: int | None) -> str:
        """The in-page link of `file` (relative to the side's root) at `line` (1-based; None: its
        first line), or "" when the file cannot be read."""
        root = self.roots.get(side)
        if not root:
            return ""
        key = (side, file.lower())
        f = self._files.get(key, False)
        if f is False:
            # a link in the backup is never followed (the walk of krl check follows none either)
            src = read_source(Path(root) / file, follow_symlinks=False)
            f = self._files[key] = (_File(len(self._files) + 1, side, file, split_lines(src.text or ""))
                                    if src.status == "ok" else None)
        if f is None:
            return ""
        n = min(max(line or 1, 1), max(len(f.lines), 1))
        f.wanted.add(n)
        return f"#src-{f.n}-L{n}"

    def render(self) -> Markup:
        """The appendix (``templates/_sources.html.j2``): every file a link named, whole while
        the budget lasts, else the lines around the linked ones."""
        left = self.budget
        views = []
        for f in sorted((f for f in self._files.values() if f is not None), key=lambda f: f.n):
            size = sum(len(t) + 1 for t in f.lines)
            if size <= left:
                shown = list(range(1, len(f.lines) + 1))
                left -= size
            else:
                keep: set[int] = set()
                for w in f.wanted:
                    keep.update(range(max(1, w - WINDOW), min(len(f.lines), w + WINDOW) + 1))
                shown = sorted(keep)
                left -= sum(len(f.lines[i - 1]) + 1 for i in shown)
            rows, prev = [], 0
            for i in shown:
                if i != prev + 1:
                    rows.append((None, ""))                   # a gap: lines left out
                rows.append((i, f.lines[i - 1]))
                prev = i
            views.append({"n": f.n, "side": f.side, "file": f.file, "rows": rows, "whole": len(shown) == len(f.lines)})
        return Markup(render_html("krl.diff", "_sources.html.j2", views=views))
