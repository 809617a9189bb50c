"""Derive the KSS platform table (krl/semantics/data/kss.yaml) from system files of a corpus.

Facts, not files: from every KUKA system data list of the corpus (``DEFDAT $OPERATE``,
``$OPERATE_R1``, ``$MACHINE``, ``$ROBCOR``, ``$CUSTOM``, ``$OPTION``; ``$CONFIG`` is left out:
its user part belongs to one robot cell, and its BASIS part is the ``basis`` table of
types.yaml) the names of the declared types, variables and routine signatures are read,
each with the ``path:line`` it came from. From the files of technology packages
(``R1/TP/<package>/``) the GLOBAL names of the data lists are read with the package that
declares them (``packages``), and the routines a program may call without the package's files,
each code file's main routine and its GLOBAL routines (``package_routines``), with the package
(the folder's name: ``GripperSpotTech``) that a controller archive's am.ini must list for the
checker to take them as installed (krl/workspace.py ``Workspace.unresolved``).

Usage (the corpus is read in place, never copied)::

    python -m krl.survey.derive_tables ../shared/krl-corpus > krl/semantics/data/kss.yaml

tests/frontend/test_kss_tables.py checks that the committed table equals a fresh derivation
when the corpus is present. The first declaration of a name (in the order of
:func:`system_files`) wins; the hand-written tables (types.yaml, sysvars.yaml,
functions.yaml, from the reference) win over this one, and a backup's own declarations win
over all tables (they live in its global scope, above the system scope).
"""

from __future__ import annotations

import csv
import re
import sys
from pathlib import Path

import yaml

from krl.ast import nodes as N
from krl.limits import PARSE_TIMEOUT_S
from krl.parsecache import load_files
from krl.source import is_krl_file, read_source
from krl.project import find_backups, is_system_path
from krl.semantics.outside import user_fold_lines

# system data lists whose declarations are platform facts, in the order in which they win
SYSTEM_DATALISTS = ("$OPERATE", "$OPERATE_R1", "$MACHINE", "$ROBCOR", "$CUSTOM", "$OPTION")
_SYSTEM_DEFDAT = re.compile(r"^\s*DEFDAT\s+\$", re.IGNORECASE | re.MULTILINE)


def _known_invalid(corpus: Path) -> set[str]:
    listing = Path(__file__).resolve().parents[2] / "corpus" / "known-invalid.csv"
    try:
        with open(listing, encoding="utf-8") as fh:
            return {row["path"] for row in csv.DictReader(fh)}
    except OSError:
        return set()


def _data_lists(corpus: Path, invalid: set[str]) -> list[Path]:
    """The .dat files of the corpus the table reads, sorted: KUKA's system data lists
    (``DEFDAT $...``) and the data lists of technology packages (a ``TP`` folder's)."""
    out = []
    for p in sorted(corpus.rglob("*")):
        if not p.is_file() or p.suffix.lower() != ".dat" or p.relative_to(corpus).as_posix() in invalid:
            continue
        in_tp = "tp" in [q.lower() for q in p.relative_to(corpus).parts[:-1]]
        try:
            head = p.read_bytes()[:4096].decode("latin-1")
        except OSError:
            continue
        if in_tp or _SYSTEM_DEFDAT.search(head):
            out.append(p)       # only system data lists and technology-package files are read
    return out


def _parsed(paths: list[Path]) -> dict[Path, N.Module | None]:
    """The AST of each of `paths`, None for a file that does not parse cleanly: one batch
    through the one store (krl.parsecache.load_files: by content hash, the rest parsed in
    worker processes within krl.limits.PARSE_TIMEOUT_S each, the Java engine where there is a
    JDK), so that a derivation after ``krl check`` of the corpus (or a test session's other
    corpus tests) reads the parses instead of making them again (tests/frontend/test_kss_tables.py:
    the Python engine file by file took 12 s of CPU, 2026-11-28)."""
    paths = list(dict.fromkeys(paths))
    loaded = load_files([str(p) for p in paths], timeout=PARSE_TIMEOUT_S)
    return {p: lf.module if lf.ok else None for p, lf in zip(paths, loaded)}


def _modules(corpus: Path, parsed: dict) -> list:
    """(relative path, Module) of every data list of :func:`_data_lists` that parses, sorted."""
    out = []
    for p in _data_lists(corpus, _known_invalid(corpus)):
        module = parsed.get(p)
        if module is not None and module.data is not None:
            out.append((p.relative_to(corpus).as_posix(), module))
    return out


def _dims(dims) -> str:
    return f"[{','.join(str(d) for d in dims)}]" if dims else ""


def _components(d: N.StrucDecl) -> str:
    out, cur = [], None
    for c in d.components:
        head = f"{c.type_name} " if c.type_name.upper() != cur else ""
        cur = c.type_name.upper()
        out.append(f"{head}{c.name}{_dims(c.dims)}")
    return ", ".join(out)


def _signature(d: N.ExtDecl) -> str:
    params = []
    for i, p in enumerate(d.params):
        size = p.name_size if p.name_size is not None else p.type_size
        dims = "" if size is None else f"[{size or ''}]"
        mode = f" :{p.mode.upper()}" if p.mode else ""
        params.append(f"{p.type_name} {p.name or f'P{i + 1}'}{dims}{mode}")
    ret = f"{d.return_type.name} " if d.return_type is not None else ""
    return f"{ret}{d.name}({', '.join(params)})"


def derive(corpus: str | Path) -> dict:
    """The table as a dict (see the module docstring); empty sections when nothing is found."""
    corpus = Path(corpus)
    types: dict[str, dict] = {}
    variables: dict[str, dict] = {}
    routines: dict[str, dict] = {}
    packages: dict[str, dict] = {}
    invalid = _known_invalid(corpus)
    parsed = _parsed(_data_lists(corpus, invalid) + _package_code(corpus, invalid) + _hook_code(corpus, invalid))
    files = _modules(corpus, parsed)
    rank = {n: i for i, n in enumerate(SYSTEM_DATALISTS)}
    system = sorted(((rel, m) for rel, m in files if m.data.name.upper() in rank),
                    key=lambda rm: (rank[rm[1].data.name.upper()], rm[0]))
    for rel, module in system:
        for d in module.data.items:
            where = f"{rel}:{d.span.line}"
            if isinstance(d, N.StrucDecl):
                types.setdefault(d.name.upper(), {"name": d.name, "struc": _components(d), "source": where})
            elif isinstance(d, N.EnumDecl):
                types.setdefault(d.name.upper(), {"name": d.name, "enum": list(d.values), "source": where})
            elif isinstance(d, N.VarDecl):
                for v in d.names:
                    entry = {"type": d.type.name + (f"[{d.type.size}]" if d.type.size else ""),
                             "source": where}
                    if d.is_const:
                        entry["const"] = True
                    variables.setdefault(v.name.upper(), {"name": v.name + _dims(v.dims), **entry})
            elif isinstance(d, N.SignalDecl):
                typ = "INT" if d.end is not None else "BOOL"
                variables.setdefault(d.name.upper(), {"name": d.name, "type": typ, "source": where,
                                                      "signal": True})
            elif isinstance(d, N.ExtDecl):
                routines.setdefault(d.name.upper(), {"signature": _signature(d),
                                                     "function": d.return_type is not None,
                                                     "source": where})
    # technology packages: GLOBAL names of the data lists in R1/TP/<package>/
    for rel, module in files:
        package = _tp_package(rel)
        if package is None:
            continue
        for d in module.data.items:
            if not getattr(d, "is_global", False):
                continue
            names = [v.name for v in d.names] if isinstance(d, N.VarDecl) else [getattr(d, "name", "")]
            for n in names:
                if n:
                    packages.setdefault(n.upper(), {"package": package, "source": f"{rel}:{d.span.line}"})
    hooks, programs = _hooks(corpus, parsed)
    for name, entry in hooks.items():
        packages.setdefault(name, entry)
    return {"types": dict(sorted(types.items())),
            "variables": dict(sorted(variables.items())),
            "routines": dict(sorted(routines.items())),
            "packages": dict(sorted(packages.items())),
            "package_routines": dict(sorted(_package_routines(corpus, parsed).items())),
            "programs": dict(sorted(programs.items()))}


def _tp_package(rel: str) -> str | None:
    """The technology package of a corpus path ``.../R1/TP/<package>/...``, or None."""
    parts = rel.split("/")
    low = [p.lower() for p in parts]
    if "tp" not in low[:-1] or low.index("tp") + 2 >= len(parts):
        return None
    return parts[low.index("tp") + 1]


def _package_code(corpus: Path, invalid: set[str]) -> list[Path]:
    """The code files (``.src``, ``.sub``) of technology packages (``R1/TP/<package>/``), sorted."""
    return [p for p in sorted(corpus.rglob("*"))
            if p.is_file() and p.suffix.lower() in (".src", ".sub")
            and _tp_package(p.relative_to(corpus).as_posix()) is not None
            and p.relative_to(corpus).as_posix() not in invalid]


def _package_routines(corpus: Path, parsed: dict) -> dict[str, dict]:
    """UPPER routine name -> {package, source} of the code files of technology packages
    (``R1/TP/<package>/*.src``, ``.sub``): each file's main routine and its GLOBAL routines,
    the routines a program calls by name (reference 2.6), with or without an EXT."""
    out: dict[str, dict] = {}
    for p in _package_code(corpus, _known_invalid(corpus)):
        rel = p.relative_to(corpus).as_posix()
        module = parsed.get(p)
        if module is None:
            continue
        for i, r in enumerate(module.routines):
            if i == 0 or r.is_global:
                out.setdefault(r.name.upper(), {"package": _tp_package(rel), "source": f"{rel}:{r.span.line}"})
    return out


def _hook_files(corpus: Path, invalid: set[str]):
    """(backup root, [(file, is a system file)]) of every backup of the corpus: its code files
    (no ``.dat``) that are KUKA's system files or lie under a Program folder, sorted."""
    for b in find_backups(corpus):
        files = []
        for p in sorted(b.rglob("*")):
            if not p.is_file() or not is_krl_file(p) or p.suffix.lower() == ".dat":
                continue
            system = is_system_path(str(p.relative_to(b)))
            in_program = "program" in [q.lower() for q in p.relative_to(b).parts[:-1]]
            if p.relative_to(corpus).as_posix() not in invalid and (system or in_program):
                files.append((p, system))
        yield b, files


def _hook_code(corpus: Path, invalid: set[str]) -> list[Path]:
    return [p for _b, files in _hook_files(corpus, invalid) for p, _s in files]


def _hooks(corpus: Path, parsed: dict) -> tuple[dict, dict]:
    """KUKA's hook programs under R1/Program: a routine that a KUKA system file of a backup
    calls (outside its USER folds) and that a file under R1/Program declares as its main
    routine or GLOBAL (masref_user.src's MASREFSTARTG1, called by System/masref_main.src).
    Returns (packages entries of the routines, programs: UPPER file name -> source)."""

    hooks: dict[str, dict] = {}
    programs: dict[str, dict] = {}
    for _b, files in _hook_files(corpus, _known_invalid(corpus)):
        called: dict[str, str] = {}
        defined: list[tuple[str, str, Path]] = []
        for p, system in files:
            rel = p.relative_to(corpus).as_posix()
            module = parsed.get(p)
            if module is None:
                continue
            if system:
                user = user_fold_lines(read_source(p).text or "")
                for n in module.walk():
                    if isinstance(n, N.Call) and n.span.line not in user:
                        called.setdefault(n.name.upper(), f"{rel}:{n.span.line}")
            else:
                for i, r in enumerate(module.routines):
                    if i == 0 or r.is_global:
                        defined.append((r.name, f"{rel}:{r.span.line}", p))
        for name, where, p in defined:
            if name.upper() in called:
                hooks.setdefault(name.upper(), {"package": "KSS hook program " + p.name,
                                                "source": where})
                programs.setdefault(p.name.upper(), {"source": where,
                                                     "called_from": called[name.upper()]})
    return hooks, programs


HEADER = """\
# KSS platform facts derived from the system files of the corpus (read in place):
# types, variables and routine signatures of KUKA's system data lists ($OPERATE,
# $OPERATE_R1, $MACHINE, $ROBCOR, $CUSTOM, $OPTION) and the GLOBAL names of technology
# packages (R1/TP/<package>/; their routines in `package_routines`) and of KUKA's hook programs under R1/Program (routines that
# KUKA's system files call; `programs` lists those files). Each entry names its source file and line (paths relative
# to ../shared/krl-corpus; MANIFEST.csv there gives repository and commit).
# Generated by: python -m krl.survey.derive_tables ../shared/krl-corpus
# Do not edit by hand; the hand-written tables (types.yaml, sysvars.yaml, functions.yaml)
# win over this one, and a backup's own declarations win over every table.
"""


def render(table: dict) -> str:
    """The YAML text of a derived table (stable: sorted keys, one entry per line)."""
    return HEADER + yaml.safe_dump(table, sort_keys=True, allow_unicode=True, width=200,
                                   default_flow_style=None)


def main(argv: list[str]) -> int:
    if len(argv) != 1 or not Path(argv[0]).is_dir():
        print("usage: python -m krl.survey.derive_tables CORPUS_FOLDER", file=sys.stderr)
        return 2
    sys.stdout.write(render(derive(argv[0])))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main(sys.argv[1:]))
