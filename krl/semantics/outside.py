"""What a backup cannot know: names declared by software that is installed on the controller
but absent from the backup (docs/diagnostics.md, "Names the backup cannot know").

The checker does not report an unresolved name at once. It records every use here
(:meth:`Unresolved.use`), with where the use is, and :meth:`Unresolved.finish` decides once the
whole workspace has been checked:

* a name is **outside the backup** (installed software: KUKA's system software and its
  technology packages, installed on the controller whether or not their files were exported)
  when there is evidence that installed software declares it, whatever resolved it:
  the platform tables name the technology package or KUKA hook program that declares it
  (kss.yaml ``packages``: the GLOBAL names of each package's data lists in the corpus; in a
  controller archive whose ``am.ini`` lists its installed technology packages, also the routines
  of the packages it lists, kss.yaml ``package_routines``: :func:`package_installed`; the
  warning says whether the archive lists the package),
  or one of its uses is a line that KUKA's software wrote (a KUKA system file: R1/System,
  R1/TP, R1/Mada, STEU or a ``$`` file, or wherever it lies a file whose own header lines say
  it is KUKA's, krl/project.py ``header_folder``; outside its USER folds; the template's INI fold of a
  program, not its USER INI fold; the lines of KUKA's submit template in a copy of sps.sub
  wherever it lies, :func:`submit_template_lines`; for a routine or a type, a KUKA inline form ``;FOLD ...
  ;%{PE}`` or one naming its module ``%M...``), or it is a routine that an ``EXT``/``EXTFCT``
  declaration names and no module of the backup defines (:func:`ext_evidence`: the EXT resolves
  the name, the body is installed), or a type of such a declaration, or a file of the backup
  that does not parse mentions it, or it is a ``$`` system variable (users cannot declare those);
  it is reported ONCE per (kind, name) per backup as a warning (W101 name, W105 type,
  W106 routine, W107 system variable) at its first use, saying how often and in how many
  files it is used and, where known, which package declares it where; an ENUM literal of such a
  type is one of its values (the run's stand-in ENUM has it, interp/runtime/kss.py);
* any other unresolved name is the program's error: E101/E105/E106 at every line that uses it.
  Code in the USER folds of KUKA's files (``USER INIT``, ``USER PLC`` of sps.sub, ``USER GLOBALS``
  of ``$config.dat``) is the user's: a name only it uses and nothing declares is the program's
  error there too (:func:`line_evidence`).

Only lines decide, never the spelling of a name: a misspelled variable in user code is an error
however KUKA-like it looks. The run stands in for exactly the names classified here
(interp/runtime/kss.py), with their declared signature where an EXT gives one.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from krl.diagnostics import DiagnosticSink, Note
from krl.semantics.builtins import load_builtins
from krl.diagnostics.render import split_lines
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
#: the module a KUKA inline form names in its opening comment: ``%MKUKATPBASIS`` (KSS 5 to 8's
#: form header ``;%{PE}%R 8.3.31,%MKUKATPBASIS,%CMOVE,%VPTP,%P ...``)
FOLD_MODULE = re.compile(r"%M([A-Z][A-Z0-9_]*)", re.IGNORECASE)
#: the editor markers of a fold's opening comment: ``%{PE}`` (an inline form), ``%{P}``,
#: ``%{E}``, ``%{SE}`` (KUKA's folds of older forms and of technology packages; with a module)
_MARKER = re.compile(r"%\{([A-Z]+)\}", re.IGNORECASE)
#: KSS 8's forms name their provider in a hidden parameter fold: ``;Params IlfProvider=...``
FOLD_PROVIDER = re.compile(r"^\s*;\s*Params\s+IlfProvider\s*=\s*([A-Za-z0-9_.]+)", re.IGNORECASE)


def fold_opening(line: str) -> str | None:
    """The opening comment of a ``;FOLD`` line (what follows FOLD: the title, then KUKA's
    markers after a second ``;``), or None for any other line."""
    m = _FOLD.match(line) if ";" in line else None
    return m.group(1) if m else None


def template_lines(text: str) -> tuple[dict[int, str], dict[int, str], dict[int, str]]:
    """(INI-fold lines, inline-form lines, USER-fold lines) of a KRL text: line (1-based) ->
    what wrote it.

    INI-fold lines lie inside a fold titled ``INI`` or ``<WORD> INI``/``INIT`` (``BASISTECH
    INI``, ``SPOTTECH INI``, ``AUTOEXT INIT``: the template and the technology packages write
    them) and not inside a ``USER INI`` fold (the programmer's part); each maps to the title of
    its innermost such fold (``SPOTTECH INI``). Inline-form lines lie inside a fold whose
    opening comment carries KUKA's editor marker ``%{PE}``, or another marker (``%{P}``,
    ``%{E}``, ``%{SE}``) with the module of a form provider (``%MKUKATPGRP``), and outside an
    INI fold; each maps to the module its form names (``KUKATPBASIS``; a KSS 8 form's
    ``IlfProvider`` in its parameter fold, ``GripperTech.GripperSet``), or "" when it names
    none. USER-fold lines lie inside a fold titled ``USER ...`` (``USER INI``, ``USER PLC``,
    ``USER GLOBALS``) and in no KUKA fold inside it; each maps to the fold's title: the
    programmer's part of a template or of a KUKA system file. In a file built from KUKA's submit
    template the INI map also holds :func:`submit_template_lines` (title :data:`SUBMIT_TITLE`)."""
    ini: dict[int, str] = {}
    inline: dict[int, str] = {}
    user: dict[int, str] = {}
    stack: list[list[str]] = []         # [kind, label] of each open fold
    for no, line in enumerate(split_lines(text), 1):
        m = _FOLD.match(line) if ";" in line else None
        if m:
            rest = m.group(1)
            title = rest.split(";", 1)[0].strip().upper()
            module = FOLD_MODULE.search(rest)
            marker = _MARKER.search(rest)
            if title.startswith("USER"):
                stack.append(["user", title])
            elif title == "INI" or title.endswith((" INI", " INIT")) or title == "INIT":
                stack.append(["ini", title])
            elif marker is not None and (marker.group(1).upper() == "PE" or module is not None) \
                    and marker.group(1).upper() != "H":
                stack.append(["inline", module.group(1).upper() if module else ""])
            else:
                stack.append(["", ""])
        elif stack and ";" in line:
            p = FOLD_PROVIDER.match(line)
            if p is not None:
                form = _innermost(stack)
                if form is not None and form[0] == "inline" and not form[1]:
                    form[1] = p.group(1)
        if stack:
            form = _innermost(stack)
            if form is None:
                pass
            elif form[0] == "ini":
                ini[no] = form[1]
            elif form[0] == "inline":
                inline[no] = form[1]
            else:
                user[no] = form[1]
        if not m and stack and ";" in line and _ENDFOLD.match(line):
            stack.pop()
    for no in submit_template_lines(text, user):
        if no not in ini and no not in inline:
            ini[no] = SUBMIT_TITLE
    return ini, inline, user


#: the fold KUKA's submit template (sps.sub) leaves for the user's PLC code
USER_PLC = "USER PLC"
#: what wrote a line of :func:`submit_template_lines` (its title in :func:`template_lines`' INI map)
SUBMIT_TITLE = "SUBMIT TEMPLATE"
_DEF = re.compile(r"^\s*(?:GLOBAL\s+)?(?:DEF|DEFFCT\s+[A-Za-z_$][\w$]*(?:\s*\[[^\]]*\])?)\s+([A-Za-z_$][\w$]*)\s*\(",
                  re.IGNORECASE)
_END = re.compile(r"^\s*END(?:FCT)?\s*(?:;.*)?$", re.IGNORECASE)


def submit_template_lines(text: str, user: dict[int, str]) -> set[int]:
    """The lines KUKA's submit template wrote in a file built from it (one that holds its
    ``USER PLC`` fold; else none), `user` the file's USER-fold lines: the file's first routine
    (``SPS``: its declarations, INI fold, ``LOOP`` with the technology packages' PLC folds
    ``BASISTECH PLC``, ``BACKUPMANAGER PLC``, ``GRIPPERTECH LOOP``) and every routine those lines
    call (``RESET_OUT`` of the INTERRUPT the AUTOEXT INIT fold declares), outside the USER folds.
    A routine only the user's code calls (one the user wrote below the template's) stays the
    user's. The template leaves the user the USER folds (``USER DECL``, ``USER INIT``, ``USER
    PLC``): KUKA's "KR C Submit Interpreter, Operation and Programming" §2.1, the expansion of
    SPS.SUB goes in the USER PLC fold. Issue 85: a copy of sps.sub outside R1/System classified
    ``BasisTech_PLC_INIT`` (INI fold) W106 but ``BasisTech_PLC_LOOP`` (the LOOP) E106."""
    if USER_PLC not in user.values():
        return set()
    routines: list[tuple[str, int, int]] = []          # (NAME, first line, last line)
    name, start = "", 0
    lines = split_lines(text)
    for no, line in enumerate(lines, 1):
        d = _DEF.match(line)
        if d and not name:
            name, start = d.group(1).upper(), no
        elif name and _END.match(line):
            routines.append((name, start, no))
            name = ""
    if not routines:
        return set()
    kuka = {routines[0][0]}
    while True:
        code = " ".join(lines[no - 1].split(";", 1)[0] for nm, a, b in routines if nm in kuka
                        for no in range(a, b + 1) if no not in user)
        more = {nm for nm, _a, _b in routines
                if nm not in kuka and re.search(rf"\b{re.escape(nm)}\s*\(", code, re.IGNORECASE)}
        if not more:
            break
        kuka |= more
    return {no for nm, a, b in routines if nm in kuka for no in range(a, b + 1) if no not in user}


#: the evidence of a use on a line of a KUKA system file outside its USER folds
KUKA_FILE = "KUKA's system files use it"


def line_evidence(template, line: int, kind: str, kuka: bool) -> str:
    """Why a use on `line` of a file says installed software declares the name ('name',
    'type', 'routine', 'sysvar' `kind`), or "": the one rule on lines (module docstring).
    `template`: the file's :func:`template_lines` (None: none); `kuka`: the file is KUKA's
    (a system file, a ``$`` data list, a file KUKA's by its header lines: krl.workspace
    ``is_kuka_file``). A line of a KUKA file is KUKA's, but inside a USER fold,
    which is the user's code (a KUKA inline form there still names its package); a line of the
    user's file is KUKA's inside the template's INI fold or (routines, types) an inline form."""
    if kuka and (template is None or line not in template[2]):
        return KUKA_FILE
    return fold_evidence(template, line, kind)


def ext_evidence(place: str) -> str:
    """The evidence of a routine an ``EXT``/``EXTFCT`` declaration at `place` (``FILE:LINE``)
    names and no module of the backup defines: the declaration resolves the name, the body is
    installed software's (a technology package's user routine such as SpotTech's USERSPOT)."""
    return (f"an EXT declaration ({place}) names it and no module of this backup defines it: the "
            "software that provides it is installed on the controller")


def fold_evidence(template, line: int, kind: str) -> str:
    """Why a use on `line` says installed software declares the name ('name', 'type',
    'routine', 'sysvar' `kind`), from the file's :func:`template_lines` (None: none): the
    template's INI fold (any kind), a KUKA inline form (a routine or a type: the points and
    data sets a form names are the program's), naming the fold or the form's module; else ""."""
    if template is None:
        return ""
    ini, inline = template[0], template[1]
    title = ini.get(line)
    if title == SUBMIT_TITLE:
        return ("KUKA's submit template uses it (the file holds the template's USER PLC fold; the template "
                "writes its routines outside their USER folds)")
    if title is not None:
        fold = "INI fold" if title == "INI" else f"INI fold {title}"
        return f"the template's {fold} uses it (KUKA's template and technology packages write that fold)"
    module = inline.get(line)
    if module is not None and kind in ("routine", "type"):
        return f"a KUKA inline form ({module}) uses it" if module else "a KUKA inline form (;FOLD ... ;%{PE}) uses it"
    return ""


def provided_routine(name: str) -> str:
    """Why KUKA's software provides the routine `name` of the platform tables that the
    simulator does not implement (krl/semantics/data: KSS's system functions, ``IS_KEY_PRESSED``
    of ``$operate.dat``), or "". A routine an EXT declares and no module defines is classified
    with the other names (:func:`ext_evidence`)."""
    if name.upper() in load_builtins().routines:
        return "a routine of the platform tables (krl/semantics/data)"
    return ""


def user_fold_lines(text: str) -> frozenset[int]:
    """Lines inside a fold titled ``USER ...`` (``;FOLD USER INI``, ``;FOLD USER PLC``): the
    programmer's part of a template or of a KUKA system file such as sps.sub."""
    out: set[int] = set()
    stack: list[bool] = []
    for no, line in enumerate(split_lines(text), 1):
        m = _FOLD.match(line)
        if m:
            stack.append(m.group(1).split(";", 1)[0].strip().upper().startswith("USER"))
        if any(stack):
            out.add(no)
        if not m and _ENDFOLD.match(line) and stack:
            stack.pop()
    return frozenset(out)


def _innermost(stack: list[list[str]]) -> list[str] | None:
    """The innermost open fold that classifies its lines (INI, inline form or USER), or None."""
    for fold in reversed(stack):
        if fold[0] in ("ini", "inline", "user"):
            return fold
    return None


def _package_key(name: str) -> str:
    """A technology package's name as am.ini and the backup's ``R1/TP`` folder both spell it:
    the product name without KUKA's ``KUKA.`` prefix, letters and digits only, any case
    (am.ini ``KUKA.GripperSpotTech`` and the folder ``TP/GripperSpotTech``)."""
    low = name.strip().lower()
    low = low[5:] if low.startswith("kuka.") else low
    return "".join(ch for ch in low if ch.isalnum())


def package_installed(package: str, installed) -> tuple[str, str] | None:
    """The (name, version) of `installed` (an archive's ``am.ini`` ``[TechPacks]``: (name,
    version) pairs, krl/kssarchive.py) that is the technology package `package` (its ``R1/TP``
    folder's name, kss.yaml ``packages``), or None."""
    want = _package_key(package)
    return next(((n, v) for n, v in installed if _package_key(n) == want), None) if want else None


def installed_clause(package: str, installed) -> str:
    """What an archive's am.ini says of `package`: '' without a package list, else that it
    lists the package as installed (with its version) or that it does not."""
    if not installed:
        return ""
    got = package_installed(package, installed)
    if got is None:
        return "; the archive's am.ini does not list it among its installed technology packages"
    return f"; the archive's am.ini lists it as installed ({f'{got[0]} {got[1]}'.strip()})"


@dataclass(slots=True)
class Use:
    path: str
    line: int
    column: int
    evidence: str = ""       # why this use says "installed software declares it", or ""
    declared: str = ""       # FILE:LINE of the EXT declaration that resolves the name, or ""


#: the evidence of rule 4: the only one that does not say KUKA's software declares the name
UNPARSED = "a line not understood of this backup mentions it"

#: what `krl run` does with a name classified outside the backup (interp/runtime/kss.py), by
#: kind: the checker's message says it
STANDS_IN = {
    "name": "`krl run` stands in for it: it reads the zero value of the type its uses give it "
            "(an ENUM: a value meaning \"not installed\"), a value the program writes is kept",
    "type": "`krl run` gives its values no type (an ENUM: the literals its uses name, and "
            "\"not installed\")",
    "routine": "`krl run` stands in for it with its declared signature: a procedure does nothing, "
               "a function returns its type's zero value (or its documented value)",
    "sysvar": "`krl run` stands in for it: it reads the zero value of the type its uses give it",
}


@dataclass(slots=True)
class Outside:
    """One name the checker found outside the backup (a W101/W105/W106/W107): its `kind`
    ('name', 'type', 'routine', 'sysvar'), its spelling at the first use, `why` (the evidence,
    as the warning says it), and its `uses` in the order they were recorded. The run's
    stand-ins for KUKA's software (interp/runtime/kss.py) are made for exactly these names."""

    kind: str
    name: str
    why: str
    uses: list
    #: True when the evidence says KUKA's software declares it (rules 1-3 and 5 of the module
    #: docstring); False when the only evidence is a file of the program that does not parse
    #: mentioning it (rule 4): the program's own declaration, perhaps, that the check cannot read
    kuka: bool = True
    #: FILE:LINE of the EXT/EXTFCT declaration that resolves the routine ("" for a name nothing
    #: declares): the run's stand-in follows its signature
    declared: str = ""


@dataclass
class Unresolved:
    """Collects the uses of unresolved names of one workspace (see the module docstring).

    `packages`: UPPER name -> (package, source "path:line") from kss.yaml; `maybe_declared`:
    name -> True when a line not understood of the backup mentions it; `installed`: the
    technology packages a controller archive's am.ini lists, (name, version) pairs (empty
    outside an archive or without a list); `unlisted`: UPPER routine name -> (package, source)
    of the packages' routines (kss.yaml ``package_routines``) whose package the archive does not
    list: an EXT or a KUKA line still says installed software declares such a routine, and the
    warning adds that the archive does not list its package."""

    packages: dict = field(default_factory=dict)
    maybe_declared: object = None
    installed: tuple = ()
    unlisted: dict = field(default_factory=dict)
    uses: dict = field(default_factory=dict)        # (kind, UPPER name) -> (spelling, [Use])

    def use(self, kind: str, name: str, path: str, line: int, column: int, evidence: str = "",
            declared: str = "") -> None:
        """Record one use of an unresolved `name` of `kind` ('name', 'type', 'routine', 'sysvar'),
        or of a routine an EXT at `declared` (FILE:LINE) names and no module defines."""
        key = (kind, name.upper())
        entry = self.uses.get(key)
        if entry is None:
            entry = self.uses[key] = (name, [])
        entry[1].append(Use(path, line, column, evidence, declared))

    def _why(self, kind: str, name: str, uses: list[Use]) -> str:
        got = self.packages.get(name.upper())
        if got is not None:
            package, source = got
            if package.startswith("KSS hook program "):
                return (f"declared by KUKA's hook program {package[17:]} ({source}), which KUKA's system "
                        f"files call and this backup does not contain")
            return (f"declared by technology package {package} ({source}), which this backup does not contain"
                    + installed_clause(package, self.installed))
        for u in uses:
            if u.evidence:
                unlisted = self.unlisted.get(name.upper()) if kind == "routine" else None
                if unlisted is None:
                    return u.evidence
                return (f"{u.evidence}; it is a routine of technology package {unlisted[0]} ({unlisted[1]})"
                        + installed_clause(unlisted[0], self.installed))
        if kind == "sysvar":
            return "a system variable of the controller that the platform tables do not list"
        if self.maybe_declared is not None and self.maybe_declared(name):
            return UNPARSED
        return ""

    def classify(self) -> dict[tuple[str, str], Outside]:
        """(kind, UPPER name) -> :class:`Outside`, for every recorded name that is outside the
        backup (the module docstring's rule, the one the warnings report); the other names are
        the program's errors. The one decision on what KUKA's software provides: the checker
        reports it (:meth:`finish`), the run stands in for each name whose :attr:`Outside.kuka`
        says KUKA's software declares it (interp/runtime/kss.py)."""
        out: dict[tuple[str, str], Outside] = {}
        for key, (name, uses) in self.uses.items():
            why = self._why(key[0], name, uses)
            if why:
                declared = next((u.declared for u in uses if u.declared), "")
                out[key] = Outside(key[0], name, why, uses, why != UNPARSED, declared)
        return out

    def finish(self, sink: DiagnosticSink) -> None:
        """Report every recorded name: one warning per outside name, else an error per use line."""
        outside = self.classify()
        for (kind, key), (name, uses) in self.uses.items():
            err, warn, noun = KINDS[kind]
            found = outside.get((kind, key))
            why = found.why if found is not None else ""
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
            form = warn("ext", noun=noun, name=name, times=times, why=why) if found.declared else \
                warn(noun=noun, name=name, times=times, why=why)
            sink.add(first.path, first.line, first.column, *form, notes=notes,
                     help="the controller must have the software that declares it installed; "
                          "if it does not, this is an error" + (". " + STANDS_IN[kind] if found.kuka else ""))
