"""The text and HTML forms of a :class:`krl.diff.core.Diff` (``krl diff``).

Text from the input (names, KRL lines, file names) is made printable by
:func:`krl.terminal.printable` in the text form and escaped by the project's one Jinja
environment (krl/render.py, template ``diff.html.j2``) in the HTML form.
"""

from __future__ import annotations

from markupsafe import Markup

from krl.diff.core import KIND_TITLES, KINDS, Diff
from krl.render import render_html
from krl.terminal import printable

__all__ = ["diff_text", "diff_html", "format_delta", "format_coordinates", "html_helpers", "krl_text", "summary_line",
           "partial_lines"]

_UNITS = {"X": "mm", "Y": "mm", "Z": "mm", "A": "deg", "B": "deg", "C": "deg"}


def format_delta(delta: dict) -> str:
    """``ΔX +1.5 mm, ΔZ -2 mm`` (axis values without a unit: degrees or mm by the axis)."""
    return ", ".join(f"Δ{c} {v:+g}" + (f" {_UNITS[c]}" if c in _UNITS else "") for c, v in delta.items())


def krl_text(v: object) -> str:
    """A JSON value of the diff as KRL shows it: numbers as numbers, TRUE/FALSE, "-" for none,
    text (already KRL) as it is."""
    if v is None:
        return "-"
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, float):
        return f"{v:.9g}"
    return str(v)


def _values(values: dict) -> str:
    return ", ".join(f"{c} {krl_text(a)} -> {krl_text(b)}" for c, (a, b) in values.items())


def format_coordinates(coords: dict) -> str:
    """``X 1070, Y -610, Z 500, ...`` (the components of an added or removed point)."""
    return ", ".join(f"{c} {krl_text(v)}" for c, v in coords.items())


def partial_lines(d: Diff) -> list[tuple[str, dict]]:
    """(which side: "old", "new" or "both", entry of ``d.partial``) of each file with lines not
    understood; a file whose lines and counts are the same on both sides is named once."""
    def key(e: dict) -> tuple:
        return (e["file"].lower(), tuple((x["line"], x["message"]) for x in e["lines"]), e["understood"], e["total"])
    new = {key(e) for e in d.partial if e["side"] == "new"}
    old = {key(e) for e in d.partial if e["side"] == "old"}
    out = []
    for e in d.partial:
        if e["side"] == "old" and key(e) in new:
            continue
        out.append(("both" if e["side"] == "new" and key(e) in old else e["side"], e))
    return out


def headline(e: dict, verb: str = "compared") -> str:
    """``FILE:LINE[, LINE...] not understood: N of M declarations compared`` of a ``Diff.partial`` entry."""
    nums = [str(x["line"]) for x in e["lines"]]
    where = ", ".join(nums[:8]) + (f" and {len(nums) - 8} more lines" if len(nums) > 8 else "")
    return f"{e['file']}:{where} not understood: {e['understood']:,} of {e['total']:,} {e['noun']} {verb}"


def summary_line(d: Diff) -> str:
    """Every kind compared with its count, then the edits that are not changes and the files
    not compared."""
    counts = ", ".join(f"{n} {KIND_TITLES[k].lower()}" for k, n in d.summary().items())
    out = f"compared {d.files_compared} file(s): {counts}"
    if d.moved:
        out += f"; {len(d.moved)} file(s) moved"
    if d.unparsed_same:
        out += f"; {d.unparsed_same} file(s) with syntax errors unchanged (the same text)"
    if d.unparsed:
        out += f"; {len(d.unparsed)} line(s) not understood, compared by their text"
    if d.not_compared:
        out += f"; {len(d.not_compared)} file(s) not compared (not read or not parsed)"
    return out + f"; {d.comment_edits} comment and {d.fold_edits} fold line(s) edited (not changes)"


def diff_text(d: Diff) -> list[str]:
    """The report as lines: one section per non-empty list, in the order of the issue."""
    p = printable
    out: list[str] = []
    for side, e in partial_lines(d):
        out.append(f"{side}: {p(headline(e))}")
        for x in e["lines"][:8]:
            out.append(f"  {p(e['file'])}:{x['line']}: {p(x['message'])}")
        if len(e["lines"]) > 8:
            out.append(f"  ... and {len(e['lines']) - 8} more lines not understood")
    if d.points:
        out.append(f"Points ({len(d.points)}):")
        for e in d.points:
            what = e["change"] if e["change"] != "changed" else format_delta(e["delta"])
            if e.get("coordinates"):
                what += f" {{{format_coordinates(e['coordinates'])}}}"
            extra = [] if not e.get("status_turn") else [
                "status/turn changed " + ", ".join(f"{c} {a}->{b}" for c, (a, b) in e["status_turn"].items())]
            if e.get("values"):
                extra.append(_values(e["values"]))
            out.append(f"  {p(e['file'])}:{e['line']} {p(e['name'])} ({e['kind']}): "
                       + "; ".join(x for x in [what, *extra] if x))
    if d.frames:
        out.append(f"Frames and loads ({len(d.frames)}):")
        for e in d.frames:
            what = e["change"] if e["change"] != "changed" else format_delta(e["delta"])
            if e.get("coordinates"):
                what += f" {{{format_coordinates(e['coordinates'])}}}"
            if e.get("values"):
                what = "; ".join(x for x in (what, _values(e["values"])) if x)
            out.append(f"  {p(e['file'])}:{e['line']} {p(e['name'])} ({e['kind']}): {p(what)}")
    if d.values:
        out.append(f"Data values ({len(d.values)}):")
        for e in d.values:
            typ = e["type"] or e["kind"]
            if e["change"] == "changed":
                what = f"{krl_text(e['old'])} -> {krl_text(e['new'])}"
                if "delta" in e:
                    what += f" ({e['delta']:+.9g})"
            else:
                what = f"{e['change']} {krl_text(e['new'] if e['change'] == 'added' else e['old'])}"
            out.append(f"  {p(e['file'])}:{e['line']} {p(e['name'])} ({p(typ)}): {p(what)}")
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
        out.append(f"Motion parameters ({len(d.motions)}):")
        for e in d.motions:
            ch = ", ".join(f"{k} {krl_text(a)} -> {krl_text(b)}" for k, (a, b) in e["changed"].items())
            out.append(f"  {p(e['file'])}:{e['line']} {p(e['routine'])}: {e['motion']} {p(e['point'])}: {p(ch)}")
    if d.duplicates:
        out.append(f"Duplicate definitions, compared by the first as krl check does ({len(d.duplicates)}):")
        for e in d.duplicates:
            out.append(f"  {e['side']} {p(e['file'])}:{e['line']}: {e['code']} {p(e['message'])}")
    if d.moved:
        out.append(f"Moved, compared with their old place ({len(d.moved)}):")
        out += [f"  {p(e['old'])} -> {p(e['new'])}" for e in d.moved]
    if d.unparsed:
        out.append(f"Lines not understood, compared by their text ({len(d.unparsed)}):")
        for e in d.unparsed:
            if e["change"] == "changed":
                what = f"changed {p(e['old_text'])} -> {p(e['text'])}"
            else:
                what = f"{e['change']}: {p(e['text'] if e['text'] is not None else e['old_text'])}"
            out.append(f"  {p(e['file'])}:{e['line']} {what}")
    for f in d.not_compared:
        out.append(f"not compared (not read or not parsed): {p(f)}")
    if d.left_out:
        out.append(f"... {d.left_out} more entries left out (limit MAX_DIFF_ENTRIES)")
    verdict = ("no change" + (" in the files compared" if d.not_compared else "")) if not d.changed else "changed"
    out.append(f"{p(d.old)} -> {p(d.new)}: {verdict}; {summary_line(d)}")
    return out


def _plain_link(file: str, line: int | None = None, side: str = "new", label: str | None = None) -> Markup:
    """``file:line`` (or `label`) as code, no link (``krl diff --format html`` names no folder to
    link into)."""
    text = label if label is not None else f"{file}:{line}" if line else file
    return Markup(render_html("krl.diff", "_link.html.j2", text=text, href=""))


def html_helpers(link=None) -> dict:
    """The template helpers of the diff section (shared with the change report); `link(file,
    line, side, label)` renders a place (default: as code, without a link)."""
    return {"format_coordinates": format_coordinates, "krl_text": krl_text, "kinds": KINDS,
            "kind_titles": KIND_TITLES, "summary_line": summary_line, "link": link or _plain_link,
            "partial_lines": partial_lines, "headline": headline}


def diff_html(d: Diff) -> str:
    """The report as one HTML page (template krl/diff/templates/diff.html.j2)."""
    return render_html("krl.diff", "diff.html.j2", diff=d, format_delta=format_delta, **html_helpers(),
                       title=f"KRL backup diff: {d.old} -> {d.new}")
