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
5. **Retest on the robot** -- what to try on the robot before it produces again, derived from
   the changes (:func:`retest`), each row with boxes to tick and sign.
6. **Program map** -- the interactive map of NEW (krl/programmap's page, embedded), its entry
   points by class, the modules only an operator starts, the dead routines.
7. **All check findings** of NEW.

A cover opens the page (issue 63): both backups identified (krl/diff/ident.py: path, kind,
controller, robot, KSS version, date of the newest file, KRL files, SHA-256), the generator's
version and the date, and a signature block (print only: on screen one line names the
backups). A table of contents follows; every finding, change and routine names its file:line
as a link (``links``: ``source`` the report's own view of the file at that line,
krl/diff/sources.py, shown below the report on screen; ``file`` a file: URL, ``vscode`` a
vscode: URL that opens the line, ``none``; with ``file`` and ``vscode`` a file inside a
``.zip`` has no link). The page prints as a PDF a person signs (its print style sheet: A4,
"Page N of M" and the backups' hashes at the foot of each page, the interactive map and the
source views left out, the unchanged context -- lines not understood that did not change,
the findings NEW had already -- collapsed to their counts, tables of fixed column widths).
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from markupsafe import Markup

from krl.diff.core import KIND_TITLES, KINDS, Diff
from krl.diff.sources import SourceViews
from krl.diff.text import format_delta, html_helpers
from krl.programmap.graph import ProgramMap
from krl.programmap.render import LINKS, context, file_href, logbook_marks, map_widget
from krl.render import render_html
from krl.semantics.outside import user_fold_lines
from krl.source import read_source

__all__ = ["Finding", "Touched", "findings_delta", "cause_remains", "relative", "touched_entries", "report_html", "RUN_KINDS",
           "MAX_REPORT_DIAGNOSTICS", "REPORT_LINKS", "retest", "css_string"]

#: the findings listed in each table (introduced, removed, all of NEW; the counts are always complete)
MAX_REPORT_DIAGNOSTICS = 500
#: the entry kinds that are programs of their own (krl/programmap/graph.py), run old against new
RUN_KINDS = ("cell", "plc", "submit", "selected", "operator", "module")
#: how the report links a file:line: its own view of the source (the default), or as the map does
REPORT_LINKS = ("source", *LINKS)


@dataclass
class Finding:
    """One check finding as the report shows it: `file` relative to its backup's root, the
    source `text` of its line ("" when not readable), `href` its link ("" for none), the
    `symbol` it is about (the name at its column, else the first name its message quotes; "")
    and the `routine` it stands in (by the program map's routine spans; "" outside a routine
    or without a map)."""
    code: str
    severity: str
    message: str
    file: str
    line: int
    column: int
    text: str = ""
    href: str = ""
    symbol: str = ""
    routine: str = ""


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
    #: both runs end the same way (interp.outcomes ``ends_alike``: reason, cause, message and
    #: statement), set with `changes`: the report's "the same"
    ends_alike: bool = False


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
    symbol, the routine and the message with its numbers left out (the lines it names move when
    code is edited; "used 19 times" becomes "used 26 times"). Not the line nor its text: an edit
    above moves the line, an edit of the call changes its text, and the finding stays the same
    (issue 72: the same two missing routines were "8 new" and "7 fixed")."""
    return f.file.lower(), f.code, f.symbol.upper(), f.routine.upper(), _NUMBER.sub("N", f.message)


_NAME = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]*")
_QUOTED = re.compile(r"'([A-Za-z_$][A-Za-z0-9_$]*)")


def _symbol(src: str, column: int, message: str) -> str:
    """The name a finding is about: the identifier at its (1-based) `column` of the line `src`,
    else the first name its message quotes, else ""."""
    m = _NAME.match(src, column - 1) if 0 < column <= len(src) else None
    if m is not None and (column == 1 or not (src[column - 2].isalnum() or src[column - 2] in "_$")):
        return m.group(0)
    q = _QUOTED.search(message)
    return q.group(1) if q else ""


def _routines(pm: ProgramMap | None) -> dict[str, list[tuple[int, int, str]]]:
    """Resolved file path -> (first line, END line, name) of each routine of the map `pm`."""
    out: dict[str, list[tuple[int, int, str]]] = {}
    if pm is None:
        return out
    for n in pm.nodes.values():
        if n.kind == "routine" and n.path and n.line:
            out.setdefault(str(Path(n.path).resolve()), []).append((n.line, n.end or n.line, n.name))
    return out


def findings(diagnostics: list, root: str, lines: Callable[[str], list[str]], links: str = "file",
             pm: ProgramMap | None = None) -> list[Finding]:
    """The diagnostics (krl.diagnostics.Diagnostic, paths as shown) as :class:`Finding`, files
    relative to `root`; `lines(path)` gives a file's text lines ([] if unknown); `pm` the
    backup's program map, whose routines name the routine of each finding."""
    out = []
    spans = _routines(pm)
    for d in diagnostics:
        text = lines(d.path)
        src = text[d.line - 1].rstrip() if 0 < d.line <= len(text) else ""
        href = file_href(d.path, d.line, links) if links in LINKS else ""   # "source": report_html links it
        routine = next((name for first, end, name in spans.get(str(Path(d.path).resolve()), ())
                        if first <= d.line <= end), "")
        out.append(Finding(d.code, d.severity, d.message.replace(str(root).rstrip("/") + "/", ""),
                           _rel(d.path, root), d.line, d.column, src, href, _symbol(src, d.column, d.message), routine))
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


def cause_remains(removed: list[Finding], new: list[Finding]) -> tuple[list[Finding], list[Finding]]:
    """(fixed, fewer): the findings of `removed` (:func:`findings_delta`'s) whose finding is
    gone from `new` altogether, and those of which `new` still has one with the same
    :func:`_key` (the same file, code, symbol, routine and message: one of two identical
    occurrences went and the cause remains, issue 85 item 5). Only the first are fixed."""
    left = {_key(f) for f in new}
    fixed, fewer = [], []
    for f in removed:
        (fewer if _key(f) in left else fixed).append(f)
    return fixed, fewer


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
            # the uses in order (a set's order is the process's string hashes': the first of a
            # routine's changed values named, and so the report's text, varied from run to run)
            for path, name in sorted(n.uses):
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
                unread: tuple[set, set] = (set(), set()), idents: list[dict] | None = None,
                generated: str = "", logbooks: list[dict] | None = None) -> str:
    """The page (module docstring). `new_findings`: the check findings of NEW (`files` files);
    `pm` NEW's map; with `diff`: OLD's findings and map, the touched entry points (their
    outcomes filled in when `runs`; `max_sim_time` the runs' limit, s), the two backups'
    roots (folders on this machine, else None) for the diff's links, their files
    (`file_sets`, :func:`relative`, for :func:`findings_delta`) and their lines not understood
    (`unread`: OLD's, NEW's, :func:`unread_lines`; a finding on such a line of the other
    side is listed apart, not as introduced or fixed). `idents`: the cover's backups, OLD
    first (krl/diff/ident.py ``identify``, each with ``role``); `generated`: the generator and
    the date for the cover. `logbooks`: each side's controller logbook (app/reportlog.py
    ``report_logbooks``; a place ``where`` = (file relative to its side's root, line) is linked
    here). With `links` "source" the roots must be readable while this runs
    (an archive still extracted): the page carries its views of the files it links to."""
    if links not in REPORT_LINKS:
        raise ValueError(f"links must be one of {', '.join(REPORT_LINKS)}")
    introduced, removed = findings_delta(old_findings or [], new_findings, file_sets) if diff is not None else ([], [])
    # findings on lines the other backup did not understand: its check could not see them
    introduced, newly_read = apart(introduced, unread[0])
    removed, now_unread = apart(removed, unread[1])
    # an occurrence gone while the same finding remains is no fix (issue 85 item 5)
    removed, fewer = cause_remains(removed, new_findings)
    errors = sum(f.severity == "error" for f in new_findings)
    reach = _reach_changes(old_map, pm) if old_map is not None else {"dead": [], "live": []}
    views = SourceViews({"old": old_root, "new": new_root}) if links == "source" else None
    # a file moved to another folder: the diff names its new place; its old lines are at the old one
    moved_back = {e["new"]: e["old"] for e in diff.moved} if diff is not None else {}

    def link(file: str, line: int | None = None, side: str = "new", label: str | None = None) -> Markup:
        root = new_root if side == "new" else old_root
        text = label if label is not None else f"{file}:{line}" if line else file
        place = moved_back.get(file, file) if side == "old" else file
        if views is not None:
            href = views.href(side, place, line)
        else:
            href = file_href(str(Path(root) / place), line or 1, links) if root else ""
        return Markup(render_html("krl.diff", "_link.html.j2", text=text, href=href))

    shown_new = new_findings[:MAX_REPORT_DIAGNOSTICS]
    if views is not None:
        for side, group in (("new", introduced[:MAX_REPORT_DIAGNOSTICS]), ("old", removed[:MAX_REPORT_DIAGNOSTICS]),
                            ("old", fewer[:MAX_REPORT_DIAGNOSTICS]),
                            ("new", newly_read[:MAX_REPORT_DIAGNOSTICS]), ("old", now_unread[:MAX_REPORT_DIAGNOSTICS]),
                            ("new", shown_new)):
            for f in group:
                f.href = views.href(side, f.file, f.line)
    changed_runs = [t for t in touched or [] if t.changes]
    rows = [_run_row(t, link, {"old": old_root, "new": new_root}) for t in touched or []]
    checks = retest(diff, touched or [], {"new": pm, "old": old_map} if old_map is not None else {"new": pm},
                    lambda file: _text_of(new_root, file)) if diff is not None else []
    for r in checks:
        r["where"] = link(r["file"], r["line"], r["side"]) if r.get("file") else ""
    for lb in logbooks or []:
        side = "old" if lb["role"] == "old" else "new"
        for item in lb["summary"]["programs"] + lb["summary"]["actions"]:
            w = item.get("where")
            item["link"] = link(w[0], w[1], side) if w and w[0] else ""
    body = dict(
        title=f"Change report: {backup}", backup=backup, files=files,
        errors=errors, warnings=len(new_findings) - errors, all_findings=shown_new,
        more=max(0, len(new_findings) - MAX_REPORT_DIAGNOSTICS), introduced=introduced, removed=removed, fewer=fewer,
        newly_read=newly_read, now_unread=now_unread, code_groups=code_groups(new_findings),
        limit=MAX_REPORT_DIAGNOSTICS, by_code=_by_code,
        diff=diff, touched=touched or [], changed_runs=changed_runs, runs=runs, run_rows=rows,
        max_sim_time=max_sim_time, retest=checks, idents=idents or [], generated=generated,
        logbooks=logbooks or [],
        footer=css_string(_footer(backup, idents or [])),
        reach=reach, map_widget=map_widget(pm, links if links in LINKS else "none", _marks(pm, logbooks)),
        format_delta=format_delta,
        map_tables=Markup(render_html("krl.programmap", "_map_body.html.j2", edges=False, **context(pm, None))),
        kind_counts=[(k, KIND_TITLES[k], len(getattr(diff, k))) for k in KINDS] if diff is not None else [],
        **html_helpers(link), **context(pm, None))
    # the source views last, once the page's every link has named its file and line (the
    # template calls link()); the mark cannot come from a backup: its text is escaped
    page = render_html("krl.diff", "report.html.j2", sources=Markup(_SOURCES_MARK), **body)
    return page.replace(_SOURCES_MARK, views.render() if views is not None else "", 1)


_SOURCES_MARK = "<!-- krl report: the source views -->"


def _text_of(root: str | None, file: str) -> str | None:
    """The text of `file` (relative to `root`, a folder on this machine), None when unread."""
    if not root:
        return None
    path = Path(root) / file
    src = read_source(path, follow_symlinks=False) if path.is_file() else None
    return src.text if src is not None else None


def _marks(pm: ProgramMap, logbooks: list[dict] | None) -> dict[str, str]:
    """The map's marks (krl/programmap/render.py ``logbook_marks``) from the newer side's
    logbook: the modules and variables its records name."""
    lb = next((b for b in reversed(logbooks or []) if b["role"] != "old"), None)
    if lb is None:
        return {}
    return logbook_marks(pm, {p["names"]: p["count"] for p in lb["summary"]["programs"]})


def _footer(backup: str, idents: list[dict]) -> str:
    """The foot of each printed page: the backup(s) by the start of their hash."""
    if not idents:
        return f"Change report: {backup}"
    return "Change report: " + " \u2192 ".join(f"{'/'.join(Path(i['path']).parts[-2:])} ({i['sha256'][:12]})"
                                                for i in idents)


def css_string(text: str) -> Markup:
    """`text` as a CSS string literal for the page's style sheet (``content: ...`` of the printed
    page's foot): every character but letters, digits, space and ``._-:()/`` as a CSS escape,
    so nothing of a file name (a quote, ``</style>``) can end the string or the style element."""
    out = []
    for ch in text:
        out.append(ch if ch.isascii() and (ch.isalnum() or ch in " ._-:()/") else f"\\{ord(ch):06x}")
    return Markup('"' + "".join(out) + '"')


def code_groups(found: list[Finding]) -> list[dict]:
    """The findings by code, the commonest first: {code, severity, count, message (the first's),
    files (how many), first (the first's file:line)} -- the printed report's list of the findings
    NEW had (the whole list is on screen)."""
    groups: dict[str, dict] = {}
    for f in found:
        g = groups.setdefault(f.code, {"code": f.code, "severity": f.severity, "count": 0, "message": f.message,
                                       "files": set(), "first": f"{f.file}:{f.line}"})
        g["count"] += 1
        g["files"].add(f.file.lower())
    return [dict(g, files=len(g["files"])) for g in sorted(groups.values(), key=lambda g: (-g["count"], g["code"]))]


#: the start of the name of a frame of the robot's installation (machine data), not of a tool or base
_MACHINE_FRAMES = ("$ROBROOT", "$TIRORO", "$ERSYSROOT", "$TFLA_TIRO", "$TX3P3", "$TFLWP", "$ET")
_FRAME_CHECKS = (("TOOL_DATA", "tool", "measure its TCP on the robot (a fixed point approached in several "
                  "orientations) before a motion uses it"),
                 ("BASE_DATA", "base", "touch its reference points on the robot before a motion uses it"),
                 ("LOAD_DATA", "load", "check the payload's mass and centre of gravity (load data determination)"))


def retest(d: Diff, touched: list[Touched], maps: dict[str, ProgramMap] | None = None,
           texts: Callable[[str], str | None] | None = None) -> list[dict]:
    """What to try on the robot before it produces again, derived from the changes of `d` and
    the entry points they touch (`maps`: the program map of each side, "old" and "new", for
    the programs' places and the routines they reach); each row {area, what, why, file, line,
    side}, `file` relative to its side's root ("" for none):

    * **program** -- each touched program that runs alone: run it in T1, then at its speed;
      ``why`` names the first change it reaches and how its run outcome changed;
    * **routine** -- a routine changed or added that none of those programs reaches: run it
      where it is used;
    * **tool / base / load** -- each tool, base or load data changed or added ($config.dat's
      TOOL_DATA, BASE_DATA, LOAD_DATA): measure or check it;
    * **machine data** -- the values of a system file ($machine.dat, $config.dat: not a tool,
      base or load) changed, and the frames of the robot's installation ($ROBROOT...): one row
      per file with their names;
    * **global data** -- the values of a system file that lie in one of its USER folds (``USER
      GLOBALS`` of ``$config.dat``: the programmers' globals, krl/semantics/outside.py
      ``user_fold_lines``, read from the new side's text, `texts(file)`): one row per file, not
      machine data (issue 85 item 5);
    * **points** -- the points changed or added, one row per file: approach each in T1;
    * **motions** -- the motions whose parameters changed (velocity, acceleration,
      approximation...), one row per routine;
    * **signal** -- each signal declaration changed or added: check its wiring (an I/O test).

    Removed entries need no retest on their own: what used them is a changed routine."""
    rows: list[dict] = []
    maps = maps or {}

    def row(area: str, what: str, why: str, file: str = "", line: int | None = None, side: str = "new") -> None:
        rows.append({"area": area, "what": what, "why": why, "file": file, "line": line, "side": side})

    covered: set[tuple[str, str]] = set()         # (file, routine) of the routines a touched program reaches
    for t in touched:
        side = "new" if t.new is not None else "old"
        pm = maps.get(side)
        n = pm.nodes.get(t.id) if pm is not None else None
        why = t.why + (f"; its run changed: {', '.join(t.changes)}" if t.changes else "")
        row("program", f"run {t.name} ({t.kind}) in T1, then at its programmed speed", why,
            _rel(n.path, pm.root) if n is not None and n.path else "", n.line if n is not None else None, side)
        if pm is not None:
            for nid in _reach_from(pm, t.id):
                m = pm.nodes[nid]
                if m.kind == "routine" and m.path:
                    covered.add((_rel(m.path, pm.root).lower(), m.name.upper()))
    for e in d.routines:
        if e["change"] in ("changed", "added") and (e["file"].lower(), e["name"].upper()) not in covered:
            row("routine", f"run {e['module']}:{e['name']} where it is used (no program that runs alone was "
                "found to reach it)", f"routine {e['name']} {e['change']}", e["file"], e["line"])
    system: dict[str, list[dict]] = {}
    for e in d.frames:
        if e["change"] == "removed":
            continue
        check = next((c for c in _FRAME_CHECKS if e["name"].upper().startswith(c[0])), None)
        if check is None:
            system.setdefault(e["file"], []).append(e)
            continue
        row(check[1], f"{e['name']}: {check[2]}", f"{check[1]} data {e['change']}", e["file"], e.get("line"))
    points: dict[str, list[dict]] = {}
    for e in d.points:
        if e["change"] == "removed":
            continue
        if e["name"].upper().startswith(_MACHINE_FRAMES) or e["file"].rsplit("/", 1)[-1].startswith("$"):
            system.setdefault(e["file"], []).append(e)
        else:
            points.setdefault(e["file"], []).append(e)
    users: dict[str, list[dict]] = {}
    for e in d.values:
        if e["file"].rsplit("/", 1)[-1].startswith("$"):
            own = e.get("line") in _user_lines(texts, e["file"])
            (users if own else system).setdefault(e["file"], []).append(e)
    for file, es in system.items():
        names = _names([e["name"] for e in es])
        row("machine data", f"check on the robot what depends on {names} (installation, limits, brakes, "
            "I/O as the names say)", f"{len(es)} value(s) of {file.rsplit('/', 1)[-1]} changed", file, es[0].get("line"))
    for file, es in users.items():
        row("global data", f"run the programs that use {_names([e['name'] for e in es])} (the backup's own "
            "globals, declared in a USER fold of the file: not machine data)",
            f"{len(es)} value(s) of {file.rsplit('/', 1)[-1]} changed", file, es[0].get("line"))
    for file, es in points.items():
        turned = [e["name"] for e in es if e.get("status_turn_changed")]
        row("points", f"approach {_names([e['name'] for e in es])} in T1 at reduced speed"
            + (f"; {_names(turned)}: status/turn changed, another arm configuration" if turned else ""),
            f"{len(es)} point(s) changed or added", file, es[0].get("line"))
    motions: dict[tuple[str, str], list[dict]] = {}
    for e in d.motions:
        motions.setdefault((e["file"], e["routine"]), []).append(e)
    for (file, routine), es in motions.items():
        params = sorted({k for e in es for k in e["changed"]})
        row("motions", f"run the motions of {routine} at line(s) {', '.join(str(e['line']) for e in es[:8])}"
            f"{', ...' if len(es) > 8 else ''} at their speed", f"changed: {', '.join(params)}", file, es[0]["line"])
    for e in d.declarations:
        if e["kind"] == "signal" and e["change"] != "removed":
            row("signal", f"check the wiring of {e['name']} ({e['after']}): set or read it at the pendant",
                f"signal {e['change']}", e["file"], e["line"])
    return rows


def _user_lines(texts: Callable[[str], str | None] | None, file: str) -> frozenset[int]:
    """The lines of `file` (relative to the new side's root) inside a USER fold; none when
    its text is not at hand."""
    text = texts(file) if texts is not None else None
    return user_fold_lines(text) if text else frozenset()


def _names(names: list[str], n: int = 8) -> str:
    return ", ".join(names[:n]) + (f" and {len(names) - n} more" if len(names) > n else "")


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
    same_end = bool(a["ending"] and b["ending"]) and t.ends_alike
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
