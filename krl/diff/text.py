"""The text and HTML forms of a :class:`krl.diff.core.Diff` (``krl diff``).

Text from the input (names, KRL lines, file names) is made printable by
:func:`krl.terminal.printable` in the text form and escaped by the project's one Jinja
environment (krl/render.py, template ``diff.html.j2``) in the HTML form.
"""

from __future__ import annotations

from krl.diff.core import Diff
from krl.render import render_html
from krl.terminal import printable

__all__ = ["diff_text", "diff_html", "format_delta"]

_UNITS = {"X": "mm", "Y": "mm", "Z": "mm", "A": "deg", "B": "deg", "C": "deg"}


def format_delta(delta: dict) -> str:
    """``ΔX +1.5 mm, ΔZ -2 mm`` (axis values without a unit: degrees or mm by the axis)."""
    return ", ".join(f"Δ{c} {v:+g}" + (f" {_UNITS[c]}" if c in _UNITS else "") for c, v in delta.items())


def _values(values: dict) -> str:
    return ", ".join(f"{c}: {a!r} -> {b!r}" for c, (a, b) in values.items())


def diff_text(d: Diff) -> list[str]:
    """The report as lines: one section per non-empty list, in the order of the issue."""
    p = printable
    out: list[str] = []
    if d.points:
        out.append(f"Points ({len(d.points)}):")
        for e in d.points:
            what = e["change"] if e["change"] != "changed" else format_delta(e["delta"])
            extra = [] if not e.get("status_turn") else [
                "status/turn changed " + ", ".join(f"{c} {a}->{b}" for c, (a, b) in e["status_turn"].items())]
            if e.get("values"):
                extra.append(_values(e["values"]))
            out.append(f"  {p(e['file'])} {p(e['name'])} ({e['kind']}): " + "; ".join(x for x in [what, *extra] if x))
    if d.frames:
        out.append(f"Frames and loads ({len(d.frames)}):")
        for e in d.frames:
            what = e["change"] if e["change"] != "changed" else format_delta(e["delta"])
            if e.get("values"):
                what = "; ".join(x for x in (what, _values(e["values"])) if x)
            out.append(f"  {p(e['file'])} {p(e['name'])} ({e['kind']}): {p(what)}")
    if d.routines:
        out.append(f"Routines ({len(d.routines)}):")
        for e in d.routines:
            edits = ""
            if e["comment_edits"] or e["fold_edits"]:
                edits = f" (and {e['comment_edits']} comment, {e['fold_edits']} fold line(s) edited)"
            out.append(f"  {e['change']} {p(e['module'])}:{p(e['name'])} ({p(e['file'])}:{e['line']}){edits}")
            for ln in e["before"]:
                out.append(f"    - {ln['line']}: {p(ln['text'])}")
            for ln in e["after"]:
                out.append(f"    + {ln['line']}: {p(ln['text'])}")
            if e.get("lines_left_out"):
                out.append(f"    ... {e['lines_left_out']} more line(s)")
    if d.declarations:
        out.append(f"Declarations and signals ({len(d.declarations)}):")
        for e in d.declarations:
            where = f"{p(e['file'])}" + (f" {p(e['scope'])}" if e["scope"] else "")
            what = {"added": f"added {p(e['after'])}", "removed": f"removed {p(e['before'])}",
                    "retyped": f"retyped {p(e['before'])} -> {p(e['after'])}"}[e["change"]]
            out.append(f"  {where}: {e['kind']} {p(e['name'])} {what}")
    if d.motions:
        out.append(f"Inline-form motions ({len(d.motions)}):")
        for e in d.motions:
            ch = ", ".join(f"{k} {p(repr(a))} -> {p(repr(b))}" for k, (a, b) in e["changed"].items())
            out.append(f"  {p(e['file'])}:{e['line']} {p(e['routine'])}: {e['motion']} {p(e['point'])}: {ch}")
    for f in d.not_compared:
        out.append(f"not compared (syntax errors): {p(f)}")
    if d.left_out:
        out.append(f"... {d.left_out} more entries left out (limit MAX_DIFF_ENTRIES)")
    summary = ("no change" + (" in the files compared" if d.not_compared else "")) if not d.changed else ", ".join(
        f"{len(getattr(d, k))} {k}" for k in ("points", "frames", "routines", "declarations", "motions")
        if getattr(d, k))
    out.append(f"{p(d.old)} -> {p(d.new)}: {summary}; {d.comment_edits} comment and "
               f"{d.fold_edits} fold line(s) edited (not changes)")
    return out


def diff_html(d: Diff) -> str:
    """The report as one HTML page (template krl/diff/templates/diff.html.j2)."""
    return render_html("krl.diff", "diff.html.j2", diff=d, format_delta=format_delta,
                       title=f"KRL backup diff: {d.old} -> {d.new}")
