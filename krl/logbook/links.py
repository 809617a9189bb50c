"""Logbook parameters that name a program module or one of its variables, tied to the archive's code.

The controller names a module three ways in its logbook:

* its module path, ``/R1/B3_PARCA_BIRAKMA.SRC`` (XEdit's ``logOpenFile``) and a variable of it,
  ``/R1/B3_PARCA_BIRAKMA.SRC/b3_parcasirasi`` (Varkor's ``logSetVar``: a variable set from the
  pendant; CrossMeld messages that name a program: ``/R1/B4_PARCA_BIRAKMA.SRC/p``; the shared
  archive's records): the robot's module namespace (``/R1/``, or the controller's, ``/STEU/``),
  where a module is known by its name whatever its folder;
* its file, ``KRC:\\R1\\cell.src`` (XEdit's ``logCancelProgram``, OnlineServices' file
  operations) or, without the extension, ``KRC:\\R1\\Program\\Parca_Birakma\\B3_Parca_Birakma``
  (Navigator's ``LogSelect``): a path below the archive's ``KRC`` folder;
* a program line, ``Module@line[:point]`` (``B1_Parca_Birakma@48:XPre_Pick_Point``,
  ``Alt_Programlar@176``; issue 85: 1,795 of the 6,975 records of a KSS 8.7.8 archive, the
  shared logs hold none): the module of the robot's namespace and a line of its code file.
  Decision: the line counts the lines of the module's ``.src`` as it lies in the archive (1 is
  its first line); a line the file does not have gives the file and no line.

A record that names a module (or its file) without a line or a variable gets the line of the
module's declaration in that file: its ``DEF``/``DEFFCT``/``DEFDAT`` of the module's name, else
the file's first one (``/R1/CELL.SRC`` opened in XEdit: ``DEF CELL ( )`` below its header
lines), so every record naming a module the archive holds carries file and line (issue 85).

:class:`Linker` resolves them against the archive's KRL backup (krl/project.py finds it): the
module's file (``.src``, else ``.sub``, else ``.dat``; any letter case) as its path in the
archive -- of the namespace's folder (``R1``, ``STEU``) where the backup has one, so that
``/R1/$MACHINE.DAT`` is R1's machine data and not STEU's -- and for a variable the line of its
declaration, found by the front end (krl/workspace.py loads and checks the backup once, on the
first variable asked for): the module's scope (its data list, then the global names:
``$config.dat``), else a local of one of its routines. A name that does not resolve keeps the
module's file and no line. The first parameter that names a module gives the record its
``file``, ``line`` and ``names``.
"""

from __future__ import annotations

import re
from pathlib import Path

from krl.limits import MAX_FILE_BYTES, PARSE_TIMEOUT_S
from krl.project import collect_files, find_backups, project_of
from krl.source import read_limited
from krl.parsecache import load_project
from krl.workspace import Workspace

from .record import LogRecord

__all__ = ["Linker", "link_all", "module_reference"]

_MODULE_PATH = re.compile(r"^/(R\d+|STEU)/(?:[^/]+/)*?([A-Za-z_$][\w$]*)\.(SRC|SUB|DAT)(?:/(.*))?$", re.I)
#: ``Module@line[:point]``: a program line of a module of the robot's namespace
_LINE_REF = re.compile(r"^([A-Za-z_$][\w$]*)@(\d{1,9})(?::[A-Za-z_$][\w$]*)?$")
#: the folders of a backup that are module namespaces of their own (a robot's, the controller's)
_NAMESPACE = re.compile(r"^(R\d+|STEU)$", re.I)
_KRC_PATH = re.compile(r"^KRC:\\(.+)$", re.I)
_NAME = re.compile(r"[A-Za-z_$][\w$]*")
_ORDER = {".src": 0, ".sub": 1, ".dat": 2}
#: a module's declaration line: ``DEF NAME(``, ``GLOBAL DEFFCT TYPE NAME(``, ``DEFDAT NAME``
_DECL = re.compile(r"^\s*(?:GLOBAL\s+)?(?:DEF|DEFFCT\s+[\w$]+(?:\s*\[[^\]]*\])?|DEFDAT)\s+([A-Za-z_$][\w$]*)", re.I)


def module_reference(param: str) -> tuple[str, str, str, str] | None:
    """(kind, what, variable, namespace) of a parameter naming a module: ``("module", NAME, var,
    "R1")`` for ``/R1/NAME.SRC[/var]`` (``/R1/NAME.SRC/ROUTINE/var``: a routine's local;
    ``/STEU/...``: namespace ``STEU``), ``("file", "R1/x/name.src", "", "")`` for
    ``KRC:\\R1\\x\\name.src`` (the extension may be absent), ``("line", NAME, "48", "R1")`` for
    ``NAME@48[:point]``; None for any other parameter. ``var`` is the variable's name without
    indices or components ("" when none)."""
    s = param.strip()
    m = _MODULE_PATH.match(s)
    if m:
        # /R1/MOD.SRC/var, /R1/MOD.SRC/var[2].x, or a local of a routine: /R1/MOD.SRC/ROUTINE/var
        var = _NAME.match((m.group(4) or "").rsplit("/", 1)[-1])
        return "module", m.group(2), var.group(0) if var else "", m.group(1).upper()
    m = _KRC_PATH.match(s)
    if m:
        return "file", m.group(1).replace("\\", "/").strip("/"), "", ""
    m = _LINE_REF.match(s)
    if m:
        return "line", m.group(1), m.group(2), "R1"
    return None


class Linker:
    """Resolves module references against the KRL backup of the archive at `root` (a folder;
    paths are given relative to it, ``/``-separated, as the user sees them in the archive)."""

    def __init__(self, root: Path) -> None:
        self.root = root
        backups = find_backups(root)
        self.backup = backups[0] if backups else None
        self._files: dict[str, list[Path]] | None = None
        self._ws: Workspace | None = None
        self._tried = False
        self._lines: dict[Path, int] = {}

    def _by_name(self) -> dict[str, list[Path]]:
        if self._files is None:
            self._files = {}
            for f in collect_files(self.backup) if self.backup is not None else []:
                self._files.setdefault(f.stem.upper(), []).append(f)
            for fs in self._files.values():
                fs.sort(key=lambda f: _ORDER.get(f.suffix.lower(), 3))
        return self._files

    def _rel(self, f: Path) -> str:
        try:
            return f.relative_to(self.root).as_posix()
        except ValueError:
            return f.as_posix()

    def module_file(self, name: str, namespace: str = "") -> Path | None:
        """The file of the module `name` (any case): its ``.src``, else ``.sub``, else ``.dat``;
        with a `namespace` (``R1``, ``STEU``) one below the backup's folder of that name, else
        for a robot's namespace one in no namespace's folder (a backup laid out flat); None when
        there is none."""
        got = self._by_name().get(name.upper(), [])
        if namespace and self.backup is not None:
            def ns(f: Path) -> str:
                top = f.relative_to(self.backup).parts[0]
                return top.upper() if _NAMESPACE.match(top) and len(f.relative_to(self.backup).parts) > 1 else ""
            flat = [f for f in got if not ns(f)] if namespace.upper() != "STEU" else []
            got = [f for f in got if ns(f) == namespace.upper()] or flat
        return got[0] if got else None

    def line_of(self, f: Path, line: int) -> int | None:
        """`line` when the file `f` has it (1 .. its line count), else None (a file that cannot
        be read, or larger than ``MAX_FILE_BYTES``: None)."""
        count = self._lines.get(f)
        if count is None:
            data = read_limited(f, MAX_FILE_BYTES)[0]
            count = self._lines[f] = 0 if data is None else len(data.splitlines())
        return line if 1 <= line <= count else None

    def declaration_line(self, f: Path) -> int | None:
        """The line (1-based) of the module's declaration in its file `f`: the first ``DEF``,
        ``DEFFCT`` or ``DEFDAT`` of the file's own name (any case), else the file's first one;
        None when it has none or cannot be read (larger than ``MAX_FILE_BYTES``)."""
        data = read_limited(f, MAX_FILE_BYTES)[0]
        if data is None:
            return None
        first = None
        for no, text in enumerate(data.decode("latin-1").splitlines(), 1):
            m = _DECL.match(text)
            if m is None:
                continue
            if m.group(1).upper() == f.stem.upper():
                return no
            first = first or no
        return first

    def krc_file(self, rel: str) -> Path | None:
        """The file of ``KRC:\\<rel>``: below the backup's root, any letter case; a path without
        extension is its module's code file."""
        if self.backup is None:
            return None
        want = rel.lower()
        for f in self._by_name().get(Path(rel).stem.upper(), []):
            got = f.relative_to(self.backup).as_posix().lower()
            if got == want or got.rsplit(".", 1)[0] == want:
                return f
        return None

    def _workspace(self) -> Workspace | None:
        if not self._tried and self.backup is not None:
            self._tried = True
            files = self._by_name()
            first = next((fs[0] for fs in files.values()), None)
            if first is not None:
                # each file's parse from the one store (krl/store.py), the others in worker
                # processes stopped past the parse timeout, as krl check reads a backup: an
                # archive's files are untrusted input (docs/security.md)
                ws = load_project(project_of(first), timeout=PARSE_TIMEOUT_S)
                ws.check(resolve=False)
                self._ws = ws
        return self._ws

    def declared(self, module: str, variable: str) -> tuple[Path, int] | None:
        """(file, line) of the declaration of `variable` as module `module` sees it (module scope,
        then global), else as a local of one of the module's routines; None when it does not
        resolve. The file is the symbol's (a data list, ``$config.dat``, the module)."""
        ws = self._workspace()
        unit = ws.modules.get(module.upper()) if ws is not None else None
        if unit is None:
            return None
        sym = unit.scope.lookup(variable) if unit.scope is not None else None
        if sym is None:
            for r in unit.routines:
                scope = ws.routine_scope(r)
                sym = scope.values.get(variable.upper()) if scope is not None else None
                if sym is not None:
                    break
        span = getattr(getattr(sym, "decl", None), "span", None)
        if span is None or not span.line:
            return None
        return Path(span.file or sym.path), span.line

    def link(self, rec: LogRecord) -> None:
        """Fill `rec`'s ``file``, ``line`` and ``names`` from its first parameter that names a
        module of the archive (see the module docstring); leaves it alone otherwise."""
        for p in rec.params:
            ref = module_reference(p)
            if ref is None:
                continue
            kind, what, var, namespace = ref
            f = self.krc_file(what) if kind == "file" else self.module_file(what, namespace)
            if f is None:
                continue
            rec.file = self._rel(f)
            rec.names = f.stem.upper() if kind == "file" else what.upper()
            if kind == "line":
                rec.line = self.line_of(f, int(var))
            elif not var:
                rec.line = self.declaration_line(f)
            else:
                rec.names += "." + var
                got = self.declared(f.stem, var)
                if got is not None:
                    rec.file, rec.line = self._rel(got[0]), got[1]
            return


def link_all(records: list[LogRecord], root: Path | None) -> int:
    """Fill ``file``/``line``/``names`` of every record of `records` whose parameters name a
    module of the archive at `root` (None: no archive, nothing to link); returns how many."""
    if root is None:
        return 0
    linker = Linker(root)
    if linker.backup is None:
        return 0
    for r in records:
        if r.params:
            linker.link(r)
    return sum(1 for r in records if r.file)
