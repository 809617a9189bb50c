"""The semantic diff of two loaded sides (krl/diff/load.py), on the AST and the checker's types.

:func:`diff_sides` returns a :class:`Diff` whose lists are, in the order of the report
(:data:`KINDS`; docs/diff.md has the JSON of each entry):

* ``points`` -- every point (E6POS, E6AXIS, POS, AXIS, FRAME, E3POS, E3AXIS) a data list gives
  a value, matched by file and name: ``delta`` maps a component to new minus old (X Y Z in mm;
  A B C in degrees, wrapped into -180..180; A1..A6 and E1..E6 in degrees or mm), only the
  components that moved; ``status_turn`` when S or T differ; an added or removed point has its
  ``coordinates``; ``line``: where the NEW side gives the value (the OLD side's for a removed one);
* ``frames`` -- TOOL_DATA, BASE_DATA and LOAD_DATA of ``$config.dat``, as points;
* ``values`` -- every other value of every data list (``.dat`` files, ``$config.dat``,
  ``$machine.dat``, the other system data lists): scalars, array elements and STRUC
  components, compared with their types (krl/diff/values.py: REAL as 32-bit floats or within
  the tolerance, ENUM by name, STRING exactly);
* ``routines`` -- added, removed, or changed; a routine changes when its case-folded AST
  differs (krl.ast.compare.structure with ``fold_case``: formatting, letter case, comments and
  fold lines are not in the AST), with the statement lines before and after, and, apart, the
  count of comment and fold lines edited;
* ``declarations`` -- variables, constants, types (STRUC, ENUM), SIGNAL names and EXT
  declarations added, removed or retyped, per data list or routine, shown as KRL;
* ``motions`` -- the parameters of each motion of a routine present on both sides: KUKA's
  inline forms (``PDAT_ACT``/``LDAT_ACT``/``FDAT_ACT`` and ``BAS`` lines before a motion), the
  ``WITH`` parameters of the KSS 8 motions (SPTP, SLIN, SCIRC, SPL, spline blocks) and every
  component of the motion data sets (PDAT, LDAT, FDAT records) they name.

A file with syntax errors is compared from what parsed (issue 63): every declaration, value
and routine it holds; each line not understood (krl.ast.nodes.Unparsed, the file's
``Module.unparsed``) is compared by its text: ``unparsed`` lists each with its change
(unchanged, changed, added, removed), and ``partial`` says of each such file how much was
compared (krl.workspace.NotUnderstood). Only a file that could not be read or parsed at all
(E001, E005, past a limit) is ``not_compared``, named as its side's file.

A name defined twice (the checker's E102) is compared by its first definition, the one the
checker keeps; the checker's E102 diagnostics of the compared files are listed in
``duplicates``. Names are shown as written (the NEW side's spelling). ``comment_edits`` and
``fold_edits`` count the comment and fold lines edited in all routines present on both sides
(they are never a change). Each list is cut at krl.limits.MAX_DIFF_ENTRIES.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field

from krl.ast import nodes as N
from krl.ast import printer
from krl.ast.compare import structure
from krl.diff.load import Side
from krl.diff.values import CARTESIAN, POINT_TYPES, DataValue, Leaf, data_values, number, real32, same
from krl.limits import MAX_DIFF_ENTRIES, MAX_DIFF_LINES

__all__ = ["Diff", "KINDS", "KIND_TITLES", "diff_sides"]

# the kinds of change compared, in the order of the report, with the title each is shown under
KINDS = ("points", "frames", "values", "routines", "declarations", "motions")
KIND_TITLES = {"points": "Points", "frames": "Frames and loads", "values": "Data values",
               "routines": "Routines", "declarations": "Declarations and signals",
               "motions": "Motion parameters"}

FRAME_ARRAYS = ("TOOL_DATA", "BASE_DATA", "LOAD_DATA")
_MOTION_DATA = ("PDAT_ACT", "LDAT_ACT", "FDAT_ACT")
_MOTION_PARAMS = {"TOOL_NO": "tool", "BASE_NO": "base"}   # the BAS call gives "velocity"


@dataclass
class Diff:
    """The result of :func:`diff_sides` (see the module docstring); JSON with :meth:`as_json`."""
    old: str
    new: str
    points: list[dict] = field(default_factory=list)
    frames: list[dict] = field(default_factory=list)
    values: list[dict] = field(default_factory=list)
    routines: list[dict] = field(default_factory=list)
    declarations: list[dict] = field(default_factory=list)
    motions: list[dict] = field(default_factory=list)
    duplicates: list[dict] = field(default_factory=list)
    comment_edits: int = 0
    fold_edits: int = 0
    files_compared: int = 0
    unparsed_same: int = 0          # files not read or not parsed whose text is the same on both sides
    not_compared: list[str] = field(default_factory=list)
    left_out: int = 0
    # the lines not understood of the files compared, by their text (issue 63)
    unparsed: list[dict] = field(default_factory=list)
    # files moved to another folder, compared with their old place: {old, new} (issue 63)
    moved: list[dict] = field(default_factory=list)
    # of each side's file with lines not understood: {side, file, lines: [{line, message}],
    # understood, total, noun} (krl.workspace.NotUnderstood)
    partial: list[dict] = field(default_factory=list)

    @property
    def changed(self) -> bool:
        return (any(getattr(self, k) for k in KINDS) or bool(self.moved)
                or any(e["change"] != "unchanged" for e in self.unparsed))

    def summary(self) -> dict[str, int]:
        """{kind: number of changes} for every kind compared (zeros included)."""
        return {k: len(getattr(self, k)) for k in KINDS}

    def as_json(self) -> dict:
        """The JSON object of ``krl diff --format json`` (docs/diff.md)."""
        out: dict = {"old": self.old, "new": self.new, "changed": self.changed,
                     "summary": {**self.summary(), "files_compared": self.files_compared,
                                 "unparsed_same": self.unparsed_same,
                                 "not_compared": len(self.not_compared),
                                 "not_understood": len(self.unparsed),
                                 "not_understood_changed": sum(e["change"] != "unchanged" for e in self.unparsed)}}
        for k in KINDS:
            out[k] = getattr(self, k)
        out.update({"duplicates": self.duplicates, "comment_edits": self.comment_edits,
                    "fold_edits": self.fold_edits, "not_compared": self.not_compared,
                    "left_out": self.left_out, "unparsed": self.unparsed, "not_understood": self.partial,
                    "moved": self.moved})
        return out


def diff_sides(old: Side, new: Side, tolerance: float = 0.0) -> Diff:
    """Compare two loaded sides; `tolerance` (mm, deg, or the REAL value's unit) hides smaller
    differences of REAL values. A file with syntax errors is compared from what parsed, its
    lines not understood by their text; a file not read or not parsed at all on either side is
    unchanged when its text is the same on both, else listed in ``not_compared`` (the side's
    file that could not be read: its errors are that side's)."""
    d = Diff(old.path, new.path)
    pairs: list[tuple[str | None, str | None]] = []
    for ko, kn in _pairs(old, new, d):
        fo, fn = old.files.get(ko) if ko is not None else None, new.files.get(kn) if kn is not None else None
        if not _readable(fo) or not _readable(fn):
            if fo is not None and fn is not None and old.text(ko) is not None and old.text(ko) == new.text(kn):
                d.unparsed_same += 1    # the same text on both sides: unchanged, though it was not parsed
                continue
            d.not_compared += [s.shown(k) for s, f, k in ((old, fo, ko), (new, fn, kn)) if not _readable(f)]
        else:
            pairs.append((ko, kn))
    d.files_compared = len(pairs)
    compared = ({ko for ko, _ in pairs if ko is not None}, {kn for _, kn in pairs if kn is not None})
    for (name, s), keys in zip((("old", old), ("new", new)), compared):
        d.partial += [{"side": name, "file": s.rel(s.key_of(p.path)), "lines": [{"line": n, "message": m} for n, m in p.lines],
                       "understood": p.understood, "total": p.total, "noun": p.noun}
                      for p in s.not_understood if s.key_of(p.path) in keys]
    values_old, values_new = _all_values(old), _all_values(new)
    records_old, records_new = _records(old, values_old), _records(new, values_new)
    for ko, kn in pairs:
        mo = old.files[ko].module if ko is not None else None
        mn = new.files[kn].module if kn is not None else None
        show = new.rel(kn) if kn is not None else old.rel(ko)
        dlo = mo.data if mo is not None else None
        dln = mn.data if mn is not None else None
        if dlo is not None or dln is not None:
            system = (dln or dlo).name.upper()
            _data(d, show, system, _first(values_old.get(ko, [])), _first(values_new.get(kn, [])), tolerance)
            _declarations(d, show, "", dlo.items if dlo else [], dln.items if dln else [])
        ro = _routines(mo)
        rn = _routines(mn)
        module = _module_name(mn or mo, show)
        for name in sorted(set(ro) | set(rn), key=lambda n: _order(n, ro, rn)):
            a, b = ro.get(name), rn.get(name)
            if a is None or b is None:
                r = a or b
                d.routines.append({"file": show, "module": module, "name": r.name,
                                   "change": "added" if a is None else "removed",
                                   "line": r.span.line, "before": [], "after": [],
                                   "comment_edits": 0, "fold_edits": 0})
                continue
            _routine(d, old, new, show, module, a, b)
            _declarations(d, show, b.name, a.decls, b.decls)
            _motions(d, show, a, b, (records_old.get(_module_key(ko), {}), records_old["*"]),
                     (records_new.get(_module_key(kn), {}), records_new["*"]), tolerance)
    for ko, kn in pairs:
        _unparsed(d, old, new, ko, kn)
    _duplicates(d, old, new, *compared)
    for name in (*KINDS, "duplicates", "unparsed"):
        items = getattr(d, name)
        if len(items) > MAX_DIFF_ENTRIES:
            d.left_out += len(items) - MAX_DIFF_ENTRIES
            del items[MAX_DIFF_ENTRIES:]
    return d


def _pairs(old: Side, new: Side, d: Diff) -> list[tuple[str | None, str | None]]:
    """(OLD's key, NEW's key) of each file to compare, in the order of the keys: the same key on
    both sides, or a file of one side alone (None on the other). A file only OLD has and a file
    only NEW has are one file **moved** when no other file of either side alone has its name
    (``Program/Service/x.src`` -> ``TP/x.src``; letter case ignored): they are compared with
    each other, and ``d.moved`` names the move."""
    only_old = [k for k in old.files if k not in new.files]
    only_new = [k for k in new.files if k not in old.files]
    by_name: dict[str, tuple[list, list]] = {}
    for k in only_old:
        by_name.setdefault(k.rsplit("/", 1)[-1], ([], []))[0].append(k)
    for k in only_new:
        by_name.setdefault(k.rsplit("/", 1)[-1], ([], []))[1].append(k)
    moved = {ko[0]: kn[0] for ko, kn in by_name.values() if len(ko) == 1 and len(kn) == 1}
    out: list[tuple[str | None, str | None]] = []
    for k in sorted(set(old.files) | set(new.files)):
        if k in moved.values():
            continue                # compared with its old place
        if k in moved:
            out.append((k, moved[k]))
            d.moved.append({"old": old.rel(k), "new": new.rel(moved[k])})
        else:
            out.append((k if k in old.files else None, k if k in new.files else None))
    return out


def _readable(f) -> bool:
    """A file of a side that was read and parsed (with or without syntax errors), or absent."""
    return f is None or f.status in ("ok", "syntax_error")


def _unparsed(d: Diff, old: Side, new: Side, ko: str | None, kn: str | None) -> None:
    """The lines not understood of the file `k` on either side, compared by their text (spaces
    collapsed): the same text in the same order is unchanged, a text replaced by another at its
    place changed, the rest added or removed."""
    def lines(s: Side, k: str | None) -> list[tuple[int, str]]:
        f = s.files.get(k) if k is not None else None
        if f is None or not f.module.unparsed:
            return []
        return [(n, s.line(f.path, n)) for n in f.module.unparsed]
    a, b = lines(old, ko), lines(new, kn)
    if not a and not b:
        return
    show = new.rel(kn) if kn is not None else old.rel(ko)
    ka, kb = [" ".join(t.split()).upper() for _, t in a], [" ".join(t.split()).upper() for _, t in b]
    sm = difflib.SequenceMatcher(None, ka, kb, autojunk=False)
    for op, i1, i2, j1, j2 in sm.get_opcodes():
        pairs = list(zip(range(i1, i2), range(j1, j2))) if op in ("equal", "replace") else []
        for i, j in pairs:
            d.unparsed.append({"file": show, "line": b[j][0], "old_line": a[i][0], "text": b[j][1],
                               "old_text": a[i][1], "change": "unchanged" if op == "equal" else "changed"})
        for i in range(i1 + len(pairs), i2):
            d.unparsed.append({"file": show, "line": a[i][0], "old_line": a[i][0], "text": None,
                               "old_text": a[i][1], "change": "removed"})
        for j in range(j1 + len(pairs), j2):
            d.unparsed.append({"file": show, "line": b[j][0], "old_line": None, "text": b[j][1],
                               "old_text": None, "change": "added"})


def _routines(m: N.Module | None) -> dict[str, N.Routine]:
    """{NAME: routine}; of a name defined twice, the first (the checker's E102 is on the second)."""
    out: dict[str, N.Routine] = {}
    for r in (m.routines if m is not None else []):
        out.setdefault(r.name.upper(), r)
    return out


def _first(values: list[DataValue]) -> dict[str, DataValue]:
    """{NAME: value}; of a name given twice, the first (as the checker keeps it)."""
    out: dict[str, DataValue] = {}
    for v in values:
        out.setdefault(v.name.upper().replace(" ", ""), v)
    return out


def _order(name: str, ro: dict, rn: dict) -> tuple:
    r = rn.get(name) or ro.get(name)
    return (0 if name in rn else 1, r.span.line, name)


def _module_name(m: N.Module, show: str) -> str:
    stem = show.rsplit("/", 1)[-1]
    return stem.rsplit(".", 1)[0] if "." in stem else (m.name if m is not None else stem)


# ---------------------------------------------------------------------- data-list values

def _section(system: str, value: DataValue) -> str:
    base = value.name.split("[", 1)[0].upper()
    if system == "$CONFIG" and base in FRAME_ARRAYS:
        return "frames"
    if value.type.upper() in POINT_TYPES:
        return "points"
    return "values"


def json_value(leaf: Leaf):
    """A leaf in JSON: a number for INT and REAL (and a CHAR given as a number), true/false for
    BOOL, else its KRL text."""
    if leaf.kind in ("INT", "REAL", "CHAR") and _is_num(leaf.value):
        return leaf.value
    if leaf.kind == "BOOL":
        return leaf.value
    return leaf.text


def _coordinates(v: DataValue) -> dict:
    return {leaf.path or "value": json_value(leaf) for leaf in v.leaves.values()}


def _data(d: Diff, show: str, system: str, io: dict[str, DataValue], inn: dict[str, DataValue],
          tol: float) -> None:
    order = [k for k in inn if k not in io] + [k for k in io if k not in inn] + [k for k in inn if k in io]
    for key in order:
        a, b = io.get(key), inn.get(key)
        v = b or a
        section = _section(system, v)
        if a is None or b is None:
            change = "added" if a is None else "removed"
            if section == "values":
                shown = json_value(v.leaves[""]) if list(v.leaves) == [""] else v.text
                d.values.append({"file": show, "name": v.name, "type": v.type,
                                 "kind": _whole_kind(v), "change": change,
                                 "old": None if a is None else shown, "new": None if b is None else shown,
                                 "line": v.line})
            else:
                entry = {"file": show, "name": v.name, "kind": _point_kind(section, v), "change": change,
                         "delta": {}, "coordinates": _coordinates(v), "line": v.line}
                if section == "points":
                    entry["status_turn_changed"] = False
                getattr(d, section).append(entry)
            continue
        if section == "values":
            _value_changes(d, show, a, b, tol)
        else:
            _point_change(d, show, section, a, b, tol)


def _whole_kind(v: DataValue) -> str:
    if list(v.leaves) == [""]:
        return v.leaves[""].kind
    return "record"


def _point_kind(section: str, v: DataValue) -> str:
    if section == "frames":
        return v.name.split("[", 1)[0].upper()
    return v.type.upper()


def _value_changes(d: Diff, show: str, a: DataValue, b: DataValue, tol: float) -> None:
    for path in [p for p in b.leaves if p not in a.leaves] + [p for p in a.leaves if p not in b.leaves] \
            + [p for p in b.leaves if p in a.leaves]:
        x, y = a.leaves.get(path), b.leaves.get(path)
        if x is not None and y is not None and same(x, y, tol):
            continue
        leaf = y or x
        name = b.name + (f".{leaf.path}" if leaf.path else "")
        entry = {"file": show, "name": name, "type": leaf.type, "kind": leaf.kind,
                 "change": "added" if x is None else "removed" if y is None else "changed",
                 "old": json_value(x) if x is not None else None,
                 "new": json_value(y) if y is not None else None,
                 "line": (y or x).line}
        if x is not None and y is not None and _is_num(x.value) and _is_num(y.value):
            entry["delta"] = round(y.value - x.value, 9)
        d.values.append(entry)


def _point_change(d: Diff, show: str, section: str, a: DataValue, b: DataValue, tol: float) -> None:
    cartesian = section == "frames" or b.type.upper() in CARTESIAN
    delta, other, st = {}, {}, {}
    for path in list(b.leaves) + [p for p in a.leaves if p not in b.leaves]:
        x, y = a.leaves.get(path), b.leaves.get(path)
        comp = (y or x).path or "value"
        if x is not None and y is not None and _is_num(x.value) and _is_num(y.value) \
                and comp.upper() not in ("S", "T"):
            diff = y.value - x.value
            if cartesian and comp.upper() in ("A", "B", "C"):
                # an angle modulo 360 degrees: C -180 -> 179 is -1
                diff = math.remainder(diff, 360.0)
                if abs(diff) <= tol or real32(x.value) == real32(x.value + diff):
                    continue
            elif same(x, y, tol):
                continue
            delta[comp] = float(f"{diff:.9g}")
        elif x is not None and y is not None and same(x, y, 0.0):
            continue
        elif comp.upper() in ("S", "T") and section == "points":
            st[comp] = [json_value(x) if x else None, json_value(y) if y else None]
        else:
            other[comp] = [json_value(x) if x else None, json_value(y) if y else None]
    if not (delta or other or st):
        return
    entry = {"file": show, "name": b.name, "kind": _point_kind(section, b), "change": "changed", "delta": delta,
             "line": b.line}
    if section == "points":
        entry["status_turn_changed"] = bool(st)
        if st:
            entry["status_turn"] = st
    if other:
        entry["values"] = other
    getattr(d, section).append(entry)


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


# ---------------------------------------------------------------------- declarations

def _type_text(d: N.VarDecl, v: N.VarName) -> str:
    t = d.type.name + (f"[{d.type.size or ''}]" if d.type.size is not None else "")
    return t + (f"[{','.join(str(x) for x in v.dims)}]" if v.dims else "")


def _declared(items: list) -> dict[str, tuple[str, object, str, N.Node, str]]:
    """{NAME: (kind, compared key, KRL text, node, name as written)}; the first of a name
    given twice."""
    out: dict[str, tuple[str, object, str, N.Node, str]] = {}
    for d in items:
        if isinstance(d, N.DeclStmt):
            d = d.decl
        if isinstance(d, N.VarDecl):
            for v in d.names:
                text = _type_text(d, v)
                out.setdefault(v.name.upper(), ("constant" if d.is_const else "variable", text.upper(), text, d,
                                                v.name))
        elif isinstance(d, (N.StrucDecl, N.EnumDecl, N.SignalDecl, N.ExtDecl)):
            kind = {N.StrucDecl: "type", N.EnumDecl: "type", N.SignalDecl: "signal", N.ExtDecl: "external"}[type(d)]
            text = printer.decl(d)
            if isinstance(d, N.SignalDecl):
                text = text.split(" ", 2)[-1] if not d.is_global else text.split(" ", 3)[-1]
            key = structure(d, fold_case=True) if not isinstance(d, N.SignalDecl) else text.upper()
            out.setdefault(d.name.upper(), (kind, key, text, d, d.name))
    return out


def _declarations(d: Diff, show: str, scope: str, old_items: list, new_items: list) -> None:
    a, b = _declared(old_items), _declared(new_items)
    for name in [n for n in b if n not in a] + [n for n in a if n not in b] + [n for n in b if n in a]:
        x, y = a.get(name), b.get(name)
        if x is not None and y is not None and (x[0], x[1]) == (y[0], y[1]):
            continue
        change = "added" if x is None else "removed" if y is None else "retyped"
        node = (y or x)[3]
        d.declarations.append({"file": show, "scope": scope, "name": (y or x)[4],
                               "kind": (y or x)[0], "change": change,
                               "before": x[2] if x else None, "after": y[2] if y else None,
                               "line": node.span.line})


def _duplicates(d: Diff, old: Side, new: Side, old_keys: set[str], new_keys: set[str]) -> None:
    """The names declared twice in the compared files, of each side (the workspace's facts,
    krl/semantics/checker.py DeclaredTwice), worded as the checker words E102."""
    for name, s, keys in (("old", old, old_keys), ("new", new, new_keys)):
        for fact, key in s.duplicates:
            if key in keys:
                code, message = fact.worded(lambda span, s=s: s.relative(str(span)))
                d.duplicates.append({"side": name, "file": s.rel(key), "line": fact.span.line,
                                     "code": code, "message": message})


# ---------------------------------------------------------------------- routines

def _statements(r: N.Routine) -> list[tuple[object, int]]:
    """(key, line) of the routine's header, declarations and statements in source order;
    a compound statement's key leaves out the statements it holds (they follow it)."""
    out: list[tuple[object, int]] = [
        (("DEF", r.kind, r.name.upper(), repr(structure(r.params, fold_case=True)),
          repr(structure(r.return_type, fold_case=True)), r.is_global), r.span.line)]
    out += [(structure(x, fold_case=True), x.span.line) for x in r.decls]
    work: list = list(reversed(r.body))
    while work:
        s = work.pop()
        own, inner = [], []
        for name in s.__dataclass_fields__:
            if name in ("span", "ann"):
                continue
            v = getattr(s, name)
            if isinstance(v, list) and v and all(isinstance(x, (N.Stmt, N.Case)) for x in v):
                inner.extend(v)
            else:
                own.append(structure(v, fold_case=True))
        out.append(((type(s).__name__, *own), s.span.line))
        work.extend(reversed(inner))
    return out


def _comments(side: Side, path: str, r: N.Routine) -> tuple[list[str], list[str]]:
    """(comment texts, fold-line texts) of the routine's lines, whitespace-collapsed."""
    comments, folds = [], []
    for n in range(r.span.line, (r.end_line or r.span.line) + 1):
        c = _comment(side.line(path, n))
        if c is None:
            continue
        text = " ".join(c.split())
        word = text.split(" ", 1)[0].upper() if text else ""
        (folds if word.startswith(("FOLD", "ENDFOLD")) else comments).append(text)
    return comments, folds


def _comment(line: str) -> str | None:
    """The text after the ';' that starts a comment (not inside a string), else None."""
    quoted = False
    for i, ch in enumerate(line):
        if ch == '"':
            quoted = not quoted
        elif ch == ";" and not quoted:
            return line[i + 1:]
    return None


def _edits(a: list, b: list) -> int:
    if a == b:          # most routines of two versions: no edit, and no matching to run
        return 0
    sm = difflib.SequenceMatcher(None, a, b, autojunk=False)
    return sum(max(i2 - i1, j2 - j1) for op, i1, i2, j1, j2 in sm.get_opcodes() if op != "equal")


def _routine(d: Diff, old: Side, new: Side, show: str, module: str, a: N.Routine, b: N.Routine) -> None:
    ca, fa = _comments(old, a.span.file, a)
    cb, fb = _comments(new, b.span.file, b)
    comment_edits, fold_edits = _edits(ca, cb), _edits(fa, fb)
    d.comment_edits += comment_edits
    d.fold_edits += fold_edits
    sa, sb = _statements(a), _statements(b)
    ka, kb = [k for k, _ in sa], [k for k, _ in sb]
    if ka == kb:
        return
    before, after = [], []
    sm = difflib.SequenceMatcher(None, ka, kb, autojunk=False)
    for op, i1, i2, j1, j2 in sm.get_opcodes():
        if op == "equal":
            continue
        before += [{"line": ln, "text": old.line(a.span.file, ln)} for _, ln in sa[i1:i2]]
        after += [{"line": ln, "text": new.line(b.span.file, ln)} for _, ln in sb[j1:j2]]
    d.routines.append({"file": show, "module": module, "name": b.name, "change": "changed",
                       "line": b.span.line, "before": before[:MAX_DIFF_LINES], "after": after[:MAX_DIFF_LINES],
                       "lines_left_out": max(0, len(before) - MAX_DIFF_LINES) + max(0, len(after) - MAX_DIFF_LINES),
                       "comment_edits": comment_edits, "fold_edits": fold_edits})


# ---------------------------------------------------------------------- motion parameters

def _all_values(s: Side) -> dict[str, list[DataValue]]:
    """{file key: the values of its data list} of the files read (with or without syntax errors:
    the values that parsed)."""
    return {k: data_values(f.module.data, s.lines(k)) for k, f in s.files.items()
            if _readable(f) and f.module.data is not None}


def _records(s: Side, values: dict[str, list[DataValue]]) -> dict[str, dict[str, DataValue]]:
    """{module key: {NAME: value}} of every data list's values; key "*" holds those of the
    system data lists ($config.dat's PDEFAULT and the like) and the GLOBAL ones."""
    out: dict[str, dict[str, DataValue]] = {"*": {}}
    for k, vals in values.items():
        dl = s.files[k].module.data
        own = out.setdefault(_module_key(k), {})
        system = dl.name.startswith("$")
        for v in vals:
            glob = system or (isinstance(v.node, N.VarDecl) and v.node.is_global)
            (out["*"] if glob else own).setdefault(v.name.upper(), v)
            if glob and not system:
                own.setdefault(v.name.upper(), v)
    return out


def _module_key(k: str) -> str:
    return k.rsplit(".", 1)[0]


def _text_leaf(e: N.Expr) -> Leaf:
    n = number(e)
    if n is not None:
        kind = "REAL" if isinstance(n, float) else "INT"
        return Leaf("", kind, kind, n, n, printer.expr(e), e.span.line)
    text = printer.expr(e)
    return Leaf("", "expression", "", text, structure(e, fold_case=True), text, e.span.line)


def _names(e: N.Expr) -> list[str]:
    return [n.name for n in e.walk() if isinstance(n, N.Name)]


def _set_record(params: dict[str, Leaf], prefix: str, rec: DataValue | None) -> None:
    for leaf in (rec.leaves.values() if rec is not None else ()):
        params[f"{prefix}.{leaf.path}" if leaf.path else prefix] = leaf


def _motion_list(r: N.Routine, records: tuple[dict, dict]) -> list[tuple[tuple, int, dict[str, Leaf]]]:
    """((kind, target, occurrence), line, {parameter: Leaf}) of each motion and spline block
    of the routine that has parameters: an inline form's (the ``*DAT_ACT`` and ``BAS`` lines
    before it), its WITH parameters, and the components of the data sets they name."""
    local, glob = records
    out, seen = [], {}
    work: list = [list(r.body)]
    while work:
        ctx: dict[str, Leaf] = {}
        for s in work.pop():
            if isinstance(s, N.Assign) and isinstance(s.target, N.Name) and s.target.name.upper() in _MOTION_DATA:
                if isinstance(s.value, N.Name):
                    var = s.target.name.upper().split("_")[0]
                    ctx[var] = _text_leaf(s.value)
                    rec = local.get(s.value.name.upper()) or glob.get(s.value.name.upper())
                    for leaf in (rec.leaves.values() if rec is not None else ()):
                        ctx[_MOTION_PARAMS.get(leaf.path.upper(), f"{var}.{leaf.path}")] = leaf
            elif isinstance(s, N.CallStmt) and s.call.name.upper() == "BAS" and len(s.call.args) == 2 \
                    and s.call.args[1] is not None:
                ctx["velocity"] = _text_leaf(s.call.args[1])
            elif isinstance(s, (N.Motion, N.SplineBlock)):
                params = dict(ctx)
                if isinstance(s, N.Motion):
                    params["approximation"] = Leaf("", "expression", "", " ".join(s.approx),
                                                   " ".join(a.upper() for a in s.approx), " ".join(s.approx), s.span.line)
                    target = printer.expr(s.target)
                else:
                    if s.approx:
                        params["approximation"] = Leaf("", "expression", "", s.approx, s.approx.upper(), s.approx,
                                                       s.span.line)
                    target = ""
                for w in s.with_:
                    params[f"WITH {printer.expr(w.target)}"] = _text_leaf(w.value)
                    for name in _names(w.value):
                        rec = local.get(name.upper()) or glob.get(name.upper())
                        if rec is not None and len(rec.leaves) > 1:
                            _set_record(params, rec.name, rec)
                if isinstance(s, N.SplineBlock):
                    work.append(s.body)
                if ctx or s.with_ or isinstance(s, N.SplineBlock):
                    key = (s.kind.upper(), target.upper(), seen.get((s.kind.upper(), target.upper()), 0))
                    seen[key[:2]] = key[2] + 1
                    out.append(((key, target), s.span.line, params))
                ctx = {}
            else:
                for name in s.__dataclass_fields__:
                    v = getattr(s, name, None)
                    if isinstance(v, list) and v and all(isinstance(x, N.Stmt) for x in v):
                        work.append(v)
                    elif isinstance(v, list) and v and all(isinstance(x, N.Case) for x in v):
                        work.extend(c.body for c in v)
    return out


def _motions(d: Diff, show: str, a: N.Routine, b: N.Routine, ro: tuple, rn: tuple, tol: float) -> None:
    ma = {key: params for (key, _t), _line, params in _motion_list(a, ro)}
    for (key, target), line, pb in _motion_list(b, rn):
        pa = ma.get(key)
        if pa is None:
            continue
        changed = {}
        for p in list(pb) + [p for p in pa if p not in pb]:
            x, y = pa.get(p), pb.get(p)
            if x is not None and y is not None and same(x, y, tol):
                continue
            changed[p] = [json_value(x) if x is not None else None, json_value(y) if y is not None else None]
        if changed:
            d.motions.append({"file": show, "routine": b.name, "motion": key[0], "point": target,
                              "line": line, "changed": changed})
