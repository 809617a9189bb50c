"""The change report a customer signs (``krl report NEW [--since OLD]``, issues 26 and 49).

One HTML page, rendered in the project's one Jinja environment (krl/render.py, autoescape on)
from ``templates/report.html.j2``, in this order:

1. **Summary** -- what changed, counted by kind (krl/diff/core.py KINDS); the check findings the
   change introduced and those it removed; the entry points whose run outcome changed; the
   routines that became dead or live.
2. **Changes** -- the diff (``_diff_body.html.j2``, shared with ``krl diff --format html``).
3. **Check findings** -- introduced and removed (:func:`findings_delta`), each with its source
   line.
4. **Run outcomes** -- the entry points the change touches (:func:`touched_entries`), old
   against new: how each ends, its cycle time, its motion events (interp/outcomes.py runs
   them; this module only shows the rows it is given).
5. **Program map** -- the interactive map of NEW (krl/programmap's page, embedded), its entry
   points by class, the modules only an operator starts, the dead routines.
6. **All check findings** of NEW.

A table of contents opens the page; every finding, change and routine names its file:line as
a link (``links``: ``file`` a file: URL, ``vscode`` a vscode: URL that opens the line, ``none``;
a file inside a ``.zip`` has no link). The page prints as a PDF a person reads (its print
style sheet: A4, the interactive map left out with a note, tables that wrap).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from markupsafe import Markup

from krl.diff.core import KIND_TITLES, KINDS, Diff
from krl.diff.text import format_delta, html_helpers
from krl.programmap.graph import ProgramMap
from krl.programmap.render import LINKS, context, file_href, map_widget
from krl.render import render_html

__all__ = ["Finding", "Touched", "findings_delta", "relative", "touched_entries", "report_html", "RUN_KINDS",
           "MAX_REPORT_DIAGNOSTICS"]

#: the findings listed in each table (introduced, removed, all of NEW; the counts are always complete)
MAX_REPORT_DIAGNOSTICS = 500
#: the entry kinds that are programs of their own (krl/programmap/graph.py), run old against new
RUN_KINDS = ("cell", "plc", "submit", "selected", "operator", "module")


@dataclass
class Finding:
    """One check finding as the report shows it: `file` relative to its backup's root, the
    source `text` of its line ("" when not readable), `href` its link ("" for none)."""
    code: str
    severity: str
    message: str
    file: str
    line: int
    column: int
    text: str = ""
    href: str = ""


@dataclass
class Touched:
    """An entry point the change touches: its node id, name, module and kind in the map of
    NEW (else OLD), the program file on each side (None where it is absent) and why it is
    touched (the first changed routine or data it reaches)."""
    id: str
    name: str
    module: str
    kind: str
    old: str | None
    new: str | None
    why: str
    old_outcome: dict | None = None
    new_outcome: dict | None = None
    changes: list[str] = field(default_factory=list)


def _rel(path: str, root: str) -> str:
    for p, r in ((path, root), (str(Path(path).resolve()), str(Path(root).resolve()))):
        try:
            return Path(p).relative_to(r).as_posix()
        except ValueError:
            continue
    return Path(path).name


_NUMBER = re.compile(r"\d+")


def _key(f: Finding) -> tuple:
    """What makes two findings of the two backups the same finding: the file, the code, the
    message with its numbers left out (the lines it names move when code is edited; "used 19
    times" becomes "used 26 times") and the text of the line it is on."""
    return f.file.lower(), f.code, _NUMBER.sub("N", f.message), f.text.strip()


def findings(diagnostics: list, root: str, lines: Callable[[str], list[str]], links: str = "file") -> list[Finding]:
    """The diagnostics (krl.diagnostics.Diagnostic, paths as shown) as :class:`Finding`, files
    relative to `root`; `lines(path)` gives a file's text lines ([] if unknown)."""
    out = []
    for d in diagnostics:
        text = lines(d.path)
        src = text[d.line - 1].rstrip() if 0 < d.line <= len(text) else ""
        out.append(Finding(d.code, d.severity, d.message.replace(str(root).rstrip("/") + "/", ""),
                           _rel(d.path, root), d.line, d.column, src, file_href(d.path, d.line, links)))
    return out


def findings_delta(old: list[Finding], new: list[Finding], files: tuple[set[str], set[str]] | None = None
                   ) -> tuple[list[Finding], list[Finding]]:
    """(introduced, removed): the findings of `new` with no counterpart in `old`, and of `old`
    with none in `new`, matched one to one, in order, by :func:`_key`. With `files` (the
    relative paths of each backup's files, :func:`relative`), what is left in a file only one
    side has is then matched by the file's name (a folder renamed or moved: the same finding in
    the same file); a file both sides have keeps its own findings."""
    introduced, removed = _unmatched(old, new, _key)
    if files is None:
        return introduced, removed
    old_files, new_files = files
    moved_in = [f for f in introduced if f.file.lower() not in old_files]
    moved_out = [f for f in removed if f.file.lower() not in new_files]
    still_in, still_out = _unmatched(moved_out, moved_in, _by_name)
    keep_in, keep_out = {id(f) for f in still_in}, {id(f) for f in still_out}
    return ([f for f in introduced if f.file.lower() in old_files or id(f) in keep_in],
            [f for f in removed if f.file.lower() in new_files or id(f) in keep_out])


def unread_lines(pm: ProgramMap, lines: Callable[[str], list[str]]) -> set[tuple[str, str]]:
    """(file relative to the map's root, lower-case; the line's text, stripped) of every line
    not understood of the backup of map `pm` (``ProgramMap.not_understood``, paths as shown;
    `lines(path)`: a file's text lines): where its check could not look (issue 63)."""
    out: set[tuple[str, str]] = set()
    for part in pm.not_understood:
        text = lines(part.path)
        rel = _rel(part.path, pm.root).lower()
        for n, _message in part.lines:
            if 0 < n <= len(text):
                out.add((rel, text[n - 1].strip()))
    return out


def apart(found: list[Finding], unread: set[tuple[str, str]]) -> tuple[list[Finding], list[Finding]]:
    """(the findings of `found` on a line the other backup understood, those on a line whose
    text the other backup has among its lines not understood): a finding the other side's
    check could not see is no change of the program (issue 63)."""
    keep, out = [], []
    for f in found:
        (out if (f.file.lower(), f.text.strip()) in unread else keep).append(f)
    return keep, out


def relative(paths, root: str) -> set[str]:
    """The paths relative to `root`, lower-case (the files of a backup, for :func:`findings_delta`)."""
    return {_rel(p, root).lower() for p in paths}


def _by_name(f: Finding) -> tuple:
    return (f.file.rsplit("/", 1)[-1].lower(), *_key(f)[1:])


def _unmatched(old: list[Finding], new: list[Finding], key) -> tuple[list[Finding], list[Finding]]:
    """(the findings of `new` no finding of `old` matches by `key`, those of `old` no finding of
    `new` matches), one to one, in order."""
    def left(a: list[Finding], b: list[Finding]) -> list[Finding]:
        pool: dict[tuple, int] = {}
        for f in b:
            pool[key(f)] = pool.get(key(f), 0) + 1
        out = []
        for f in a:
            k = key(f)
            if pool.get(k, 0):
                pool[k] -= 1
            else:
                out.append(f)
        return out
    return left(new, old), left(old, new)


# ---------------------------------------------------------------------- what the change touches

def _suffix(path: str, file: str) -> bool:
    p = path.replace("\\", "/").lower()
    f = file.replace("\\", "/").lower()
    return p == f or p.endswith("/" + f)


def _base(name: str) -> str:
    """``TOOL_DATA[1]`` -> ``TOOL_DATA``; ``PPDAT13.APO_DIST`` -> ``PPDAT13``."""
    return re.split(r"[\[.]", name, maxsplit=1)[0].strip().upper()


def _changed(d: Diff, pm: ProgramMap, side: str) -> dict[str, str]:
    """{node id of `pm`: why} of the routines the change touches on `side` (old/new): changed,
    added or removed routines and routines whose motions or declarations changed, and every
    routine that reads or writes a changed data-list value, point or frame."""
    out: dict[str, str] = {}
    routines = [n for n in pm.nodes.values() if n.kind == "routine"]

    def routine(file: str, name: str, why: str) -> None:
        for n in routines:
            if n.name.upper() == name.upper() and _suffix(n.path, file):
                out.setdefault(n.id, why)

    for e in d.routines:
        if e["change"] == "changed" or (e["change"] == "added") == (side == "new"):
            routine(e["file"], e["name"], f"routine {e['name']} {e['change']}")
    for e in d.motions:
        routine(e["file"], e["routine"], f"motion parameters of {e['routine']} (line {e['line']})")
    data: dict[tuple[str, str], str] = {}
    for kind in ("points", "frames", "values"):
        for e in getattr(d, kind):
            data.setdefault((e["file"], _base(e["name"])), f"{e['name']} ({e['file']}) {e['change']}")
    for e in d.declarations:
        if e["scope"]:
            routine(e["file"], e["scope"], f"declaration {e['name']} in {e['scope']} {e['change']}")
        else:
            data.setdefault((e["file"], e["name"].upper()), f"declaration {e['name']} ({e['file']}) {e['change']}")
    if data:
        for n in routines:
            for path, name in n.uses:
                for (file, base), why in data.items():
                    if base == name and _suffix(path, file):
                        out.setdefault(n.id, f"{why}, used by {n.name}")
    return out


def _reach_from(pm: ProgramMap, start: str) -> list[str]:
    out = {}
    for e in pm.edges:
        out.setdefault(e.source, []).append(e.target)
    seen = [start]
    known = {start}
    for nid in seen:
        for t in out.get(nid, ()):
            if t not in known:
                known.add(t)
                seen.append(t)
    return seen


def touched_entries(d: Diff, old: ProgramMap, new: ProgramMap) -> list[Touched]:
    """The entry points of :data:`RUN_KINDS` that can be run alone (``Node.runnable``) from which
    a routine the change touches is reached, on either side, in NEW's entry order then OLD's."""
    out: dict[str, Touched] = {}
    for side, pm in (("new", new), ("old", old)):
        changed = _changed(d, pm, side)
        if not changed:
            continue
        for nid in pm.entries:
            n = pm.nodes[nid]
            if n.entry_kind not in RUN_KINDS or not n.runnable:
                continue
            hit = next((changed[x] for x in _reach_from(pm, nid) if x in changed), None)
            if hit is None:
                continue
            t = out.get(nid)
            if t is None:
                t = out[nid] = Touched(nid, n.name, n.module, n.entry_kind, None, None, hit)
            setattr(t, side, n.path)
    for t in out.values():           # a program touched on one side runs on both where it exists
        for side, pm in (("new", new), ("old", old)):
            n = pm.nodes.get(t.id)
            if getattr(t, side) is None and n is not None and n.runnable:
                setattr(t, side, n.path)
    return list(out.values())


# ---------------------------------------------------------------------- the page

def report_html(backup: str, files: int, new_findings: list[Finding], pm: ProgramMap, *,
                diff: Diff | None = None, old_findings: list[Finding] | None = None,
                old_map: ProgramMap | None = None, touched: list[Touched] | None = None,
                runs: bool = False, max_sim_time: float | None = None,
                new_root: str | None = None, old_root: str | None = None, links: str = "file",
                file_sets: tuple[set[str], set[str]] | None = None,
                unread: tuple[set, set] = (set(), set())) -> str:
    """The page (module docstring). `new_findings`: the check findings of NEW (`files` files);
    `pm` NEW's map; with `diff`: OLD's findings and map, the touched entry points (their
    outcomes filled in when `runs`; `max_sim_time` the runs' limit, s), the two backups'
    roots (folders on this machine, else None) for the diff's links, their files
    (`file_sets`, :func:`relative`, for :func:`findings_delta`) and their lines not understood
    (`unread`: OLD's, NEW's, :func:`unread_lines`; a finding on such a line of the other
    side is listed apart, not as introduced or fixed)."""
    if links not in LINKS:
        raise ValueError(f"links must be one of {', '.join(LINKS)}")
    introduced, removed = findings_delta(old_findings or [], new_findings, file_sets) if diff is not None else ([], [])
    # findings on lines the other backup did not understand: its check could not see them
    introduced, newly_read = apart(introduced, unread[0])
    removed, now_unread = apart(removed, unread[1])
    errors = sum(f.severity == "error" for f in new_findings)
    reach = _reach_changes(old_map, pm) if old_map is not None else {"dead": [], "live": []}

    def link(file: str, line: int | None = None, side: str = "new", label: str | None = None) -> Markup:
        root = new_root if side == "new" else old_root
        text = label if label is not None else f"{file}:{line}" if line else file
        href = file_href(str(Path(root) / file), line or 1, links) if root else ""
        return Markup(render_html("krl.diff", "_link.html.j2", text=text, href=href))

    changed_runs = [t for t in touched or [] if t.changes]
    rows = [_run_row(t, link, {"old": old_root, "new": new_root}) for t in touched or []]
    return render_html(
        "krl.diff", "report.html.j2", title=f"Change report: {backup}", backup=backup, files=files,
        errors=errors, warnings=len(new_findings) - errors, all_findings=new_findings[:MAX_REPORT_DIAGNOSTICS],
        more=max(0, len(new_findings) - MAX_REPORT_DIAGNOSTICS), introduced=introduced, removed=removed,
        newly_read=newly_read, now_unread=now_unread,
        limit=MAX_REPORT_DIAGNOSTICS, by_code=_by_code,
        diff=diff, touched=touched or [], changed_runs=changed_runs, runs=runs, run_rows=rows,
        max_sim_time=max_sim_time,
        reach=reach, map_widget=map_widget(pm, links), format_delta=format_delta,
        map_tables=Markup(render_html("krl.programmap", "_map_body.html.j2", edges=False, **context(pm, None))),
        kind_counts=[(k, KIND_TITLES[k], len(getattr(diff, k))) for k in KINDS] if diff is not None else [],
        **html_helpers(link), **context(pm, None))


def _by_code(findings: list[Finding], n: int = 3) -> str:
    """``E101 5087, W107 30, ...``: the commonest codes of `findings` (a summary of many)."""
    counts: dict[str, int] = {}
    for f in findings:
        counts[f.code] = counts.get(f.code, 0) + 1
    top = sorted(counts.items(), key=lambda kv: (-kv[1], kv[0]))
    return ", ".join(f"{c} {k}" for c, k in top[:n]) + (", ..." if len(top) > n else "")


def _run_row(t: Touched, link, roots: dict) -> dict:
    """The report's row of one touched entry point: how each side's run ended and where (a
    link), its cause, the cycle times and the motion events, and whether both ended alike."""
    sides = {}
    for side in ("old", "new"):
        o = getattr(t, f"{side}_outcome")
        if o is None:
            sides[side] = {"missing": getattr(t, side) is None, "ending": None}
            continue
        root = roots.get(side)
        text = o.get("text") or ""
        where = ""
        if root:
            real = str(Path(root).resolve()) + "/"
            text = text.replace(real, "")
        if o.get("file"):
            where = link(_rel(o["file"], root) if root else Path(o["file"]).name, o.get("line"), side)
        sides[side] = {"missing": False, "ending": o["ending"], "cause": o.get("cause", ""), "text": text,
                       "where": where, "cycle_time": o.get("cycle_time"), "sim_time": o.get("sim_time"),
                       "motions": o.get("motions", 0), "counts": o.get("counts", {}),
                       "first_event": o["events"][0] if o.get("events") else None}
    a, b = sides["old"], sides["new"]
    same_end = bool(a["ending"] and b["ending"]) and "ends differently" not in t.changes \
        and "ends at another line" not in t.changes
    cycle = "—"
    if a.get("cycle_time") is not None or b.get("cycle_time") is not None:
        ca, cb = a.get("cycle_time"), b.get("cycle_time")
        cycle = f"{_s(ca)} → {_s(cb)}"
        if ca is not None and cb is not None and ca != cb:
            cycle += f" ({cb - ca:+.3f} s)"
    return {"t": t, "old": a, "new": b, "same_end": same_end, "cycle": cycle}


def _s(v: float | None) -> str:
    return "—" if v is None else f"{v:.3f} s"


def _reach_changes(old: ProgramMap, new: ProgramMap) -> dict[str, list]:
    """{"dead": routines of NEW that are dead and were not in OLD (or are new), "live": dead
    routines of OLD that NEW reaches or removed}."""
    dead_old = {n.id for n in old.unreachable}
    dead_new = {n.id for n in new.unreachable}
    return {"dead": [n for n in new.unreachable if n.id not in dead_old],
            "live": [n for n in old.unreachable if n.id not in dead_new]}
