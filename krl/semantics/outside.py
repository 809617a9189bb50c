"""What a backup cannot know: names declared by software that is installed on the controller
but absent from the backup (docs/diagnostics.md, "Names the backup cannot know").

The checker does not report an unresolved name at once. It records every use here
(:meth:`Unresolved.use`), with where the use is, and :meth:`Unresolved.finish` decides once the
whole workspace has been checked:

* a name is **outside the backup** when there is evidence that installed software declares it:
  the platform tables name the technology package or KUKA hook program that declares it
  (kss.yaml ``packages``),
  or one of its uses is a line that KUKA's software wrote (a KUKA system file: R1/System,
  R1/TP, R1/Mada, STEU or a ``$`` file; the template's INI fold of a program, not its
  USER INI fold; for a routine or a type, a KUKA inline form ``;FOLD ... ;%{PE}``), or it is
  a type of an ``EXT``/``EXTFCT`` declaration, or a file of the backup that does not parse
  mentions it, or it is a ``$`` system variable (users cannot declare those);
  it is reported ONCE per (kind, name) per backup as a warning (W101 name, W105 type,
  W106 routine, W107 system variable) at its first use, saying how often and in how many
  files it is used and, where known, which package declares it where;
* any other unresolved name is the program's error: E101/E105/E106 at every line that uses it.

Only lines decide, never the spelling of a name: a misspelled variable in user code is an error
however KUKA-like it looks.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from krl.diagnostics import DiagnosticSink, Note
from krl.diagnostics.codes import E101, E105, E106, W101, W105, W106, W107

# kind -> (error code, warning code, noun)
KINDS = {
    "name": (E101, W101, "name"),
    "type": (E105, W105, "type"),
    "routine": (E106, W106, "routine"),
    "sysvar": (W107, W107, "system variable"),      # always a warning: _why names the controller
}

_FOLD = re.compile(r"^\s*;\s*FOLD\b(.*)$", re.IGNORECASE)
_ENDFOLD = re.compile(r"^\s*;\s*ENDFOLD\b", re.IGNORECASE)


def template_lines(text: str) -> tuple[frozenset[int], frozenset[int]]:
    """(INI-fold lines, inline-form lines) of a KRL text, 1-based.

    INI-fold lines lie inside a fold titled ``INI`` or ``<WORD> INI``/``INIT`` (``BASISTECH
    INI``, ``SPOTTECH INI``, ``AUTOEXT INIT``: the template and the technology packages write
    them) and not inside a ``USER INI`` fold (the programmer's part). Inline-form lines lie inside
    a fold whose opening comment carries KUKA's editor marker ``%{PE}`` (an inline form written
    by a KUKA or package form provider) and outside an INI fold."""
    ini: set[int] = set()
    inline: set[int] = set()
    stack: list[str] = []
    for no, line in enumerate(text.splitlines(), 1):
        m = _FOLD.match(line) if ";" in line else None
        if m:
            rest = m.group(1)
            title = rest.split(";", 1)[0].strip().upper()
            if title.startswith("USER"):
                stack.append("user")
            elif title == "INI" or title.endswith((" INI", " INIT")) or title == "INIT":
                stack.append("ini")
            elif "%{PE}" in rest.upper():
                stack.append("inline")
            else:
                stack.append("")
        if stack:
            where = _innermost(stack)
            if where == "ini":
                ini.add(no)
            elif where == "inline":
                inline.add(no)
        if not m and stack and ";" in line and _ENDFOLD.match(line):
            stack.pop()
    return frozenset(ini), frozenset(inline)


def user_fold_lines(text: str) -> frozenset[int]:
    """Lines inside a fold titled ``USER ...`` (``;FOLD USER INI``, ``;FOLD USER PLC``): the
    programmer's part of a template or of a KUKA system file such as sps.sub."""
    out: set[int] = set()
    stack: list[bool] = []
    for no, line in enumerate(text.splitlines(), 1):
        m = _FOLD.match(line)
        if m:
            stack.append(m.group(1).split(";", 1)[0].strip().upper().startswith("USER"))
        if any(stack):
            out.add(no)
        if not m and _ENDFOLD.match(line) and stack:
            stack.pop()
    return frozenset(out)


def _innermost(stack: list[str]) -> str:
    for kind in reversed(stack):
        if kind == "user":
            return ""
        if kind in ("ini", "inline"):
            return kind
    return ""


@dataclass(slots=True)
class Use:
    path: str
    line: int
    column: int
    evidence: str = ""       # why this use says "installed software declares it", or ""


@dataclass
class Unresolved:
    """Collects the uses of unresolved names of one workspace (see the module docstring).

    `packages`: UPPER name -> (package, source "path:line") from kss.yaml; `maybe_declared`:
    name -> True when a file of the backup that does not parse mentions it."""

    packages: dict = field(default_factory=dict)
    maybe_declared: object = None
    uses: dict = field(default_factory=dict)        # (kind, UPPER name) -> (spelling, [Use])

    def use(self, kind: str, name: str, path: str, line: int, column: int, evidence: str = "") -> None:
        """Record one use of an unresolved `name` of `kind` ('name', 'type', 'routine', 'sysvar')."""
        key = (kind, name.upper())
        entry = self.uses.get(key)
        if entry is None:
            entry = self.uses[key] = (name, [])
        entry[1].append(Use(path, line, column, evidence))

    def _why(self, kind: str, name: str, uses: list[Use]) -> str:
        got = self.packages.get(name.upper())
        if got is not None:
            package, source = got
            if package.startswith("KSS hook program "):
                return (f"declared by KUKA's hook program {package[17:]} ({source}), which KUKA's system "
                        f"files call and this backup does not contain")
            return f"declared by technology package {package} ({source}), which this backup does not contain"
        for u in uses:
            if u.evidence:
                return u.evidence
        if kind == "sysvar":
            return "a system variable of the controller that the platform tables do not list"
        if self.maybe_declared is not None and self.maybe_declared(name):
            return "a file of this backup that does not parse mentions it"
        return ""

    def finish(self, sink: DiagnosticSink) -> None:
        """Report every recorded name: one warning per outside name, else an error per use line."""
        for (kind, _key), (name, uses) in self.uses.items():
            err, warn, noun = KINDS[kind]
            why = self._why(kind, name, uses)
            if not why:
                for u in uses:
                    helps = {"name": "declare it in the routine or in the module's data list (.dat)"}
                    sink.add(u.path, u.line, u.column, *err(name=name), help=helps.get(kind, ""))
                continue
            uses = sorted(uses, key=lambda u: (u.path, u.line, u.column))
            first = uses[0]
            files = len({u.path for u in uses})
            times = f"used {len(uses)} time{'s' if len(uses) != 1 else ''}"
            if files > 1:
                times += f" in {files} files"
            notes = []
            seen_files = {first.path}
            for u in uses[1:]:
                if u.path not in seen_files and len(notes) < 3:
                    seen_files.add(u.path)
                    notes.append(Note(u.path, u.line, u.column, f"also used here"))
            sink.add(first.path, first.line, first.column, *warn(noun=noun, name=name, times=times, why=why),
                     notes=notes,
                     help="the controller must have the software that declares it installed; "
                          "if it does not, this is an error")
