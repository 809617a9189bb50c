"""The semantic diff of two loaded sides (krl/diff/load.py), on the AST.

:func:`diff_sides` returns a :class:`Diff` whose lists are, in the order of the report:

* ``points`` -- every E6POS, E6AXIS, POS, AXIS and FRAME a data list declares with a value
  (reference 3.7), matched by file and name: ``delta`` maps a component to new minus old (X Y Z
  in mm; A B C in degrees, wrapped into -180..180; A1..A6 and E1..E6 in degrees or mm), only the
  components that moved more than the tolerance; ``status_turn_changed`` when S or T differ;
* ``frames`` -- TOOL_DATA, BASE_DATA, LOAD_DATA of ``$config.dat`` and the values of
  ``$machine.dat`` (numbers as deltas, other values as ``[old, new]``);
* ``routines`` -- added, removed, or changed; a routine changes when its case-folded AST
  differs (krl.ast.compare.structure with ``fold_case``: formatting, letter case, comments and
  fold lines are not in the AST), with the statement lines before and after, and, apart, the
  count of comment and fold lines edited;
* ``declarations`` -- variables, constants, types (STRUC, ENUM), SIGNAL names and EXT
  declarations added, removed or retyped, per data list or routine;
* ``motions`` -- inline-form motions (the ``PDAT_ACT``/``LDAT_ACT``/``FDAT_ACT`` and ``BAS``
  lines before a motion, KUKA's inline forms) whose velocity, approximation, tool, base or
  motion data changed.

``comment_edits`` and ``fold_edits`` count the comment and fold lines edited in all routines
present on both sides (they are never a change). Each list is cut at krl.limits.MAX_DIFF_ENTRIES.
"""

from __future__ import annotations

import difflib
import math
from dataclasses import dataclass, field

from krl.ast import nodes as N
from krl.ast.compare import structure
from krl.diff.load import Side
from krl.diff.values import CARTESIAN, POINT_TYPES, data_items, flatten, number
from krl.limits import MAX_DIFF_ENTRIES, MAX_DIFF_LINES

__all__ = ["Diff", "diff_sides"]

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
    routines: list[dict] = field(default_factory=list)
    declarations: list[dict] = field(default_factory=list)
    motions: list[dict] = field(default_factory=list)
    comment_edits: int = 0
    fold_edits: int = 0
    not_compared: list[str] = field(default_factory=list)
    left_out: int = 0

    @property
    def changed(self) -> bool:
        return bool(self.points or self.frames or self.routines or self.declarations or self.motions)

    def as_json(self) -> dict:
        """The JSON object of ``krl diff --format json`` (docs/diff.md)."""
        return {"old": self.old, "new": self.new, "changed": self.changed,
                "points": self.points, "frames": self.frames, "routines": self.routines,
                "declarations": self.declarations, "motions": self.motions,
                "comment_edits": self.comment_edits, "fold_edits": self.fold_edits,
                "not_compared": self.not_compared, "left_out": self.left_out}


def diff_sides(old: Side, new: Side, tolerance: float = 0.0) -> Diff:
    """Compare two loaded sides; `tolerance` (mm or deg) hides smaller deltas. A file that did
    not parse on either side is unchanged when its text is the same on both, else listed in
    ``not_compared`` (its errors are the sides')."""
    d = Diff(old.path, new.path)
    keys = sorted(set(old.files) | set(new.files))
    ok_keys = []
    for k in keys:
        fo, fn = old.files.get(k), new.files.get(k)
        if (fo is not None and not fo.ok) or (fn is not None and not fn.ok):
            if fo is not None and fn is not None and old.text(k) is not None and old.text(k) == new.text(k):
                continue        # the same text on both sides: unchanged, though it does not parse
            d.not_compared.append(new.shown(k) if fn is not None else old.shown(k))
        else:
            ok_keys.append(k)
    records_old, records_new = _records(old), _records(new)
    for k in ok_keys:
        mo = old.files[k].module if k in old.files else None
        mn = new.files[k].module if k in new.files else None
        show = new.rel(k) if k in new.files else old.rel(k)
        dlo = mo.data if mo is not None else None
        dln = mn.data if mn is not None else None
        if dlo is not None or dln is not None:
            _data(d, show, dlo, dln, tolerance)
            _declarations(d, show, "", dlo.items if dlo else [], dln.items if dln else [])
        ro = {r.name.upper(): r for r in (mo.routines if mo is not None else [])}
        rn = {r.name.upper(): r for r in (mn.routines if mn is not None else [])}
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
            _motions(d, show, a, b, records_old.get(_module_key(k), {}), records_new.get(_module_key(k), {}),
                     records_old.get("*", {}), records_new.get("*", {}))
    for name in ("points", "frames", "routines", "declarations", "motions"):
        items = getattr(d, name)
        if len(items) > MAX_DIFF_ENTRIES:
            d.left_out += len(items) - MAX_DIFF_ENTRIES
            del items[MAX_DIFF_ENTRIES:]
    return d


def _order(name: str, ro: dict, rn: dict) -> tuple:
    r = rn.get(name) or ro.get(name)
    return (0 if name in rn else 1, r.span.line, name)


def _module_name(m: N.Module, show: str) -> str:
    stem = show.rsplit("/", 1)[-1]
    return stem.rsplit(".", 1)[0] if "." in stem else (m.name if m is not None else stem)


# ---------------------------------------------------------------------- points and frames

def _data(d: Diff, show: str, dlo: N.DataList | None, dln: N.DataList | None, tol: float) -> None:
    name = (dln or dlo).name.upper()
    io = {n: (t, v) for n, t, v, _ in data_items(dlo)} if dlo is not None else {}
    inn = {n: (t, v) for n, t, v, _ in data_items(dln)} if dln is not None else {}
    for key in [k for k in inn if k not in io] + [k for k in io if k not in inn] + [k for k in inn if k in io]:
        typ = (inn.get(key) or io.get(key))[0]
        base = key.split("[", 1)[0]
        if name == "$CONFIG" and base in FRAME_ARRAYS:
            kind = base
        elif name == "$MACHINE":
            kind = "machine"
        elif typ in POINT_TYPES:
            kind = None
        else:
            continue
        if key not in io or key not in inn:
            entry = {"file": show, "name": key, "kind": kind or typ, "change": "added" if key in inn else "removed",
                     "delta": {}}
            if kind is None:
                entry["status_turn_changed"] = False
            (d.frames if kind else d.points).append(entry)
            continue
        a, b = flatten(io[key][1]), flatten(inn[key][1])
        delta, other = _delta(a, b, typ in CARTESIAN, tol)
        if kind is None:
            st = {c: [a.get(c), b.get(c)] for c in ("S", "T") if a.get(c) != b.get(c)}
            other = {c: v for c, v in other.items() if c not in ("S", "T")}
            delta = {c: v for c, v in delta.items() if c not in ("S", "T")}
            if delta or st or other:
                entry = {"file": show, "name": key, "kind": typ, "change": "changed", "delta": delta,
                         "status_turn_changed": bool(st)}
                if st:
                    entry["status_turn"] = st
                if other:
                    entry["values"] = other
                d.points.append(entry)
        elif delta or other:
            entry = {"file": show, "name": key, "kind": kind, "change": "changed", "delta": delta}
            if other:
                entry["values"] = other
            d.frames.append(entry)


def _delta(a: dict, b: dict, cartesian: bool, tol: float) -> tuple[dict, dict]:
    """({component: new - old} beyond `tol`, {component: [old, new]} for the other changes)."""
    delta, other = {}, {}
    for c in sorted(set(a) | set(b)):
        x, y = a.get(c), b.get(c)
        if _is_num(x) and _is_num(y):
            diff = y - x
            if cartesian and c in ("A", "B", "C"):
                diff = math.remainder(diff, 360.0)
            diff = round(diff, 6)
            if abs(diff) > tol and diff != 0:
                delta[c or "value"] = diff
        elif x != y:
            other[c or "value"] = [x, y]
    return delta, other


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


# ---------------------------------------------------------------------- declarations

def _declared(items: list) -> dict[str, tuple[str, str, object]]:
    out: dict[str, tuple[str, str, object]] = {}
    for d in items:
        if isinstance(d, N.DeclStmt):
            d = d.decl
        if isinstance(d, N.VarDecl):
            t = d.type.name.upper() + (f"[{d.type.size or ''}]" if d.type.size is not None else "")
            for v in d.names:
                dims = f"[{','.join(str(x) for x in v.dims)}]" if v.dims else ""
                out[v.name.upper()] = ("constant" if d.is_const else "variable", t + dims, d)
        elif isinstance(d, N.StrucDecl):
            comps = ", ".join(f"{c.type_name.upper()} {c.name.upper()}"
                              + (f"[{','.join(map(str, c.dims))}]" if c.dims else "") for c in d.components)
            out[d.name.upper()] = ("type", f"STRUC {comps}", d)
        elif isinstance(d, N.EnumDecl):
            out[d.name.upper()] = ("type", "ENUM " + ", ".join(v.upper() for v in d.values), d)
        elif isinstance(d, N.SignalDecl):
            wire = "FALSE" if d.start is None else f"{d.start.sysvar.upper()}[{d.start.index}]"
            if d.end is not None:
                wire += f" TO {d.end.sysvar.upper()}[{d.end.index}]"
            out[d.name.upper()] = ("signal", wire, d)
        elif isinstance(d, N.ExtDecl):
            out[d.name.upper()] = ("external", repr(structure(d, fold_case=True)), d)
    return out


def _declarations(d: Diff, show: str, scope: str, old_items: list, new_items: list) -> None:
    a, b = _declared(old_items), _declared(new_items)
    for name in [n for n in b if n not in a] + [n for n in a if n not in b] + [n for n in b if n in a]:
        x, y = a.get(name), b.get(name)
        if x is not None and y is not None and x[:2] == y[:2]:
            continue
        change = "added" if x is None else "removed" if y is None else "retyped"
        node = (y or x)[2]
        d.declarations.append({"file": show, "scope": scope, "name": node_name(node, name),
                               "kind": (y or x)[0], "change": change,
                               "before": x[1] if x else None, "after": y[1] if y else None,
                               "line": node.span.line})


def node_name(node, key: str) -> str:
    if isinstance(node, N.VarDecl):
        for v in node.names:
            if v.name.upper() == key:
                return v.name
    return getattr(node, "name", key)


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


# ---------------------------------------------------------------------- inline-form motions

def _records(s: Side) -> dict[str, dict[str, dict]]:
    """{file key: {NAME: flattened value}} of every data list; key "*" holds the system data
    lists' and $config.dat's (the global motion data such as PDEFAULT)."""
    out: dict[str, dict[str, dict]] = {"*": {}}
    for k, f in s.files.items():
        dl = f.module.data
        if dl is None or not f.ok:
            continue
        own = out.setdefault(_module_key(k), {})
        glob = dl.name.startswith("$")
        for name, _t, v, _n in data_items(dl):
            (out["*"] if glob else own)[name] = flatten(v)
    return out


def _module_key(k: str) -> str:
    return k.rsplit(".", 1)[0]


def _inline_motions(r: N.Routine) -> list[tuple[tuple, int, dict]]:
    """((target, occurrence), line, {param: value}) of the routine's inline-form motions."""
    out, seen = [], {}
    work: list = [list(r.body)]
    while work:
        ctx: dict[str, object] = {}
        for s in work.pop():
            if isinstance(s, N.Assign) and isinstance(s.target, N.Name) and s.target.name.upper() in _MOTION_DATA:
                if isinstance(s.value, N.Name):
                    ctx[s.target.name.upper()] = s.value.name.upper()
            elif isinstance(s, N.CallStmt) and s.call.name.upper() == "BAS" and len(s.call.args) == 2:
                v = s.call.args[1]
                ctx["BAS"] = number(v) if number(v) is not None else flatten(v).get("")
            elif isinstance(s, N.Motion):
                if ctx:
                    target = flatten(s.target).get("") if not isinstance(s.target, N.Aggregate) else "{...}"
                    n = seen.get(target, 0)
                    seen[target] = n + 1
                    ctx["approximation"] = " ".join(a.upper() for a in s.approx)
                    out.append(((s.kind.upper(), target, n), s.span.line, ctx))
                ctx = {}
            else:
                for name in s.__dataclass_fields__:
                    v = getattr(s, name, None)
                    if isinstance(v, list) and v and all(isinstance(x, N.Stmt) for x in v):
                        work.append(v)
                    elif isinstance(v, list) and v and all(isinstance(x, N.Case) for x in v):
                        work.extend(c.body for c in v)
    return out


def _params(ctx: dict, local: dict, glob: dict) -> dict[str, object]:
    out: dict[str, object] = {"approximation": ctx.get("approximation", "")}
    if "BAS" in ctx:
        out["velocity"] = ctx["BAS"]
    for var in _MOTION_DATA:
        name = ctx.get(var)
        if name is None:
            continue
        rec = local.get(name, glob.get(name))
        out[var.split("_")[0]] = name
        for comp, value in (rec or {}).items():
            out[_MOTION_PARAMS.get(comp, f"{var.split('_')[0]}.{comp}")] = value
    return out


def _motions(d: Diff, show: str, a: N.Routine, b: N.Routine, lo: dict, ln: dict, go: dict, gn: dict) -> None:
    ma = {key: (line, ctx) for key, line, ctx in _inline_motions(a)}
    for key, line, ctx in _inline_motions(b):
        if key not in ma:
            continue
        pa, pb = _params(ma[key][1], lo, go), _params(ctx, ln, gn)
        changed = {p: [pa.get(p), pb.get(p)] for p in sorted(set(pa) | set(pb)) if pa.get(p) != pb.get(p)}
        if changed:
            d.motions.append({"file": show, "routine": b.name, "motion": key[0], "point": key[1],
                              "line": line, "changed": changed})
