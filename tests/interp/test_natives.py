"""The natives registry (issue 47, interp/runtime/natives): each system routine declared once,
with its KRL signature beside its implementation.

* completeness: every routine of the registry has exactly one way to run (a Python
  implementation, a KRL routine of the project's BASIS that exists with the declared kind, or a
  stand-in that says what a call gives), and every function
  of a module of the package is declared or used by the project's code, whatever its
  parameters are called (no implementation without a signature); each field of a declaration
  fits its routine, and its readers take it from there (issue 62);
  every module's Family is registered in ``FAMILIES``; :func:`missing_sides` is shown to fail
  on a family with each side missing;
* the front end's table krl/semantics/data/functions.yaml is what the registry generates
  (a stale table fails, as CPython's generated files do);
* a run links each built-in call to its implementation once (``Callee.native``), both
  interpreters give the same values, and the stand-ins do what their declarations say.

Expected values are worked out by hand from the programs below.
"""

from __future__ import annotations

import ast
import dataclasses
import importlib
import inspect
import pkgutil
import types
from pathlib import Path

import pytest
import yaml

from interp.run import make_runtime, run_spec, RunSinks
from interp.runtime import natives
from interp.runtime.natives import FAMILIES, LINKS, REGISTRY
from interp.runtime.kss import DOCUMENTED
from interp.runtime.natives.registry import FUNCTIONS, NO_VALUE, PROCEDURES, Family, build, functions_yaml
from interp.runtime.passes import PURE_NATIVES
from interp.runtime.program import BASIS_DIR
from krl.ast import nodes as N
from krl.semantics.advance import STOP_ROUTINES
from krl.semantics.builtins import DATA_DIR, parse_signature
from krl.semantics.resolve import NATIVE
from krl.parsecache import load_file, load_files
from robot.trace import TraceWriter

from .helpers import run_krl, write

INTERPS = ("tree", "vm")


def _modules() -> list[types.ModuleType]:
    return [importlib.import_module(f"{natives.__name__}.{m.name}") for m in pkgutil.iter_modules(natives.__path__)]


def _basis_routines(file: str, basis_dir: Path) -> dict[str, bool]:
    """UPPER name -> is a function, of the routines of BASIS file `file` (its parse through the
    store, krl/parsecache.py, as a run's: each BASIS file was parsed again with the Python
    engine here, twice for those a declaration names, 2026-11-29)."""
    lf = load_file(basis_dir / file)
    return {r.name.upper(): r.is_function for r in lf.module.routines}


def _every_basis_routine(basis_dir: Path) -> dict[str, str]:
    """UPPER name -> file, of the routines a program may call in the BASIS: GLOBAL ones and each
    module's main routine."""
    out = {}
    files = sorted(basis_dir.glob("*.src"))
    for f, lf in zip(files, load_files(files)):
        routines = lf.module.routines
        out.update({r.name.upper(): f.name for i, r in enumerate(routines)
                    if r.is_global or (i == 0 and r.name.upper() == f.stem.upper())})
    return out


#: the project's packages whose code may use a function of the natives package
PROJECT = Path(__file__).resolve().parents[2]
PACKAGES = ("interp", "net", "krl", "robot", "pendant", "audit", "conformance", "recovery")

#: the Python type of a documented stand-in value, by the declared result type
VALUE_TYPES = {"BOOL": bool, "INT": int, "REAL": float}


def _used_names() -> set[str]:
    """Every identifier the project's code reads (a name or an attribute), over its packages."""
    out: set[str] = set()
    for pkg in PACKAGES:
        for f in (PROJECT / pkg).rglob("*.py"):
            if "generated" in f.parts:
                continue
            for node in ast.walk(ast.parse(f.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Name):
                    out.add(node.id)
                elif isinstance(node, ast.Attribute):
                    out.add(node.attr)
    return out


def missing_sides(registry: dict, modules: list, basis_dir: Path = BASIS_DIR, used: set | None = None) -> list[str]:
    """What keeps the registry from being complete: a routine without a way to run (or with
    two), a KRL routine the BASIS does not have (or of the other kind), a function of a natives
    module that no declaration names and no code of the project uses, whatever its parameters
    are called (a forgotten implementation), a Family that is not registered, a stand-in that a
    BASIS file implements (declare it ``krl``), and a field that does not fit its routine: a
    ``pure`` or ``stops`` routine the simulator does not implement, a ``value`` on a routine
    that is not a stand-in or of another type than the declared result."""
    problems = []
    basis: dict[str, dict[str, bool]] = {}
    everywhere = _every_basis_routine(basis_dir)
    for n in registry.values():
        ways = [n.fn is not None, bool(n.krl), bool(n.stand_in.strip())]
        if sum(ways) != 1:
            problems.append(f"{n.name}: {sum(ways)} ways to run (an implementation, a BASIS routine or a stand-in)")
        if n.krl:
            have = basis.setdefault(n.krl, _basis_routines(n.krl, basis_dir))
            if n.name not in have:
                problems.append(f"{n.name}: no routine of that name in the BASIS file {n.krl}")
            elif n.section in (FUNCTIONS, PROCEDURES) and have[n.name] != n.is_function:
                problems.append(f"{n.name}: the BASIS routine is a {'function' if have[n.name] else 'procedure'}")
        if n.stand_in and n.name in everywhere:
            problems.append(f"{n.name}: declared a stand-in, but the BASIS file {everywhere[n.name]} implements it")
        for flag in ("pure", "stops"):
            if getattr(n, flag) and n.fn is None:
                problems.append(f"{n.name}: declared {flag}, but the simulator does not implement it")
        if n.value is not NO_VALUE:
            result = n.signature.split("(", 1)[0].split()[0] if n.section == FUNCTIONS else ""
            if not n.stand_in:
                problems.append(f"{n.name}: a documented value on a routine that is not a stand-in")
            elif type(n.value) is not VALUE_TYPES.get(result.upper()):
                problems.append(f"{n.name}: its documented value {n.value!r} is no {result or 'value of a procedure'}")
    declared = {id(getattr(n.fn, "__wrapped__", n.fn)) for n in registry.values() if n.fn is not None}   # (a clock reader's: Family.add)
    registered = {id(f) for f in FAMILIES}
    used = _used_names() if used is None else used
    for mod in modules:
        for name, obj in vars(mod).items():
            if isinstance(obj, Family) and id(obj) not in registered:
                problems.append(f"{mod.__name__}.{name}: a family not in FAMILIES")
            if inspect.isfunction(obj) and obj.__module__ == mod.__name__ and id(obj) not in declared \
                    and name not in used:
                problems.append(f"{mod.__name__}.{name}: an implementation without a signature (nothing uses it)")
    return problems


def test_every_routine_has_one_way_to_run_and_every_implementation_a_signature():
    assert missing_sides(REGISTRY, _modules()) == []


def test_the_completeness_check_fails_when_a_side_is_missing():
    """A family with a BASIS routine the BASIS lacks, a procedure declared for a BASIS function,
    a stand-in for a routine the BASIS has, implementations that no declaration names whatever
    their parameters are called, and fields that do not fit: each is found."""
    fam = Family("test")
    fam.krl("REAL NOT_IN_BASIS(REAL X :IN)", "bas.src")
    fam.krl("SVEL_JOINT(REAL VEL :IN)", "bas.src")           # bas.src: GLOBAL DEFFCT REAL SVEL_JOINT
    fam.stand_in("REAL SACC_CP(LDAT L :OUT)", "nothing")      # bas.src: GLOBAL DEFFCT CP SACC_CP
    fam.stand_in("INT ANSWER(INT K :IN)", "a number", value=True)       # a BOOL for an INT
    fam.stand_in("BOOL CLEAN(INT K :IN)", "FALSE", value=False)         # fits: not reported
    fam.krl("BAS_FAKE(INT K :IN)", "bas.src")
    fam.entries[-1] = dataclasses.replace(fam.entries[-1], stops=True)  # stops, but nothing runs it

    def _forgotten(rt, a):
        return 0

    def _spelled_otherwise(runtime, argv):
        return 0

    mod = types.ModuleType("interp.runtime.natives.fake")
    mod.FAKE = fam
    for fn in (_forgotten, _spelled_otherwise):
        fn.__module__ = mod.__name__
        setattr(mod, fn.__name__, fn)
    got = missing_sides(build([fam]), [mod], used=set())
    assert got == ["NOT_IN_BASIS: no routine of that name in the BASIS file bas.src",
                   "SVEL_JOINT: the BASIS routine is a function",
                   "SACC_CP: declared a stand-in, but the BASIS file bas.src implements it",
                   "ANSWER: its documented value True is no INT",
                   "BAS_FAKE: no routine of that name in the BASIS file bas.src",
                   "BAS_FAKE: declared stops, but the simulator does not implement it",
                   "interp.runtime.natives.fake.FAKE: a family not in FAMILIES",
                   "interp.runtime.natives.fake._forgotten: an implementation without a signature (nothing uses it)",
                   "interp.runtime.natives.fake._spelled_otherwise: an implementation without a signature "
                   "(nothing uses it)"]


def test_the_readers_take_each_field_from_the_declarations():
    """The spin watch's pure built-ins, the front end's advance-run stops and the stand-ins'
    documented values are the registry's fields (issue 62), not lists of their own."""
    assert PURE_NATIVES == {n for n, x in REGISTRY.items() if x.pure} and "STRLEN" in PURE_NATIVES
    assert STOP_ROUTINES == {n for n, x in REGISTRY.items() if x.stops} == {"PULSE"}
    assert DOCUMENTED == {n: (x.value, x.stand_in) for n, x in REGISTRY.items() if x.value is not NO_VALUE}
    assert DOCUMENTED["IS_KEY_PRESSED"][0] is False


def test_a_declaration_needs_its_signature_and_its_behaviour():
    fam = Family("test")
    with pytest.raises(ValueError, match="function without return type|bad signature"):
        fam.add("ABS(REAL X :IN", lambda rt, a: 0)
    with pytest.raises(ValueError, match="says what a call gives"):
        fam.stand_in("REAL NOTHING(REAL X :IN)", " ")
    with pytest.raises(ValueError, match="not callable"):
        fam.add("REAL X1(REAL X :IN)", None)
    lenient = Family("pkg", lenient="pkg")
    with pytest.raises(ValueError, match="by its name alone"):
        lenient.stand_in("INT PKG_F(INT A :IN)", "nothing")
    a, b = Family("a"), Family("b")
    a.add("REAL TWICE(REAL X :IN)", lambda rt, x: 0)
    b.add("REAL TWICE(REAL X :IN)", lambda rt, x: 0)
    with pytest.raises(ValueError, match="TWICE is declared by a and by b"):
        build([a, b])


def test_the_front_end_table_is_generated_from_the_registry():
    text = (DATA_DIR / "functions.yaml").read_text(encoding="utf-8")
    assert text == functions_yaml(REGISTRY), "stale: run python -m interp.runtime.natives.tables"
    doc = yaml.safe_load(text)
    names = [parse_signature(s, True).name for s in doc["functions"]]
    names += [parse_signature(s, False).name for s in doc["procedures"]]
    names += [str(n).upper() for fam in doc["lenient"].values() for n in fam]
    assert sorted(names) == sorted(REGISTRY)


def test_the_table_keeps_the_signatures_the_checker_knew():
    """A few signatures as the reference writes them (4.5-4.8), read back from the table."""
    doc = yaml.safe_load((DATA_DIR / "functions.yaml").read_text(encoding="utf-8"))
    assert "REAL ATAN2(REAL Y :IN, REAL X :IN)" in doc["functions"]
    assert "INT STRFIND(INT STARTAT :IN, CHAR STRVAR[] :IN, CHAR STRFIND[] :IN, CASE_SENSE_T MODE :IN)" \
        in doc["functions"]
    assert "PULSE(BOOL SIGNAL :OUT, BOOL LEVEL :IN, REAL DURATION :IN)" in doc["procedures"]
    assert "EKI_INIT" in doc["lenient"]["ethernet_krl"] and "RSI_ON" in doc["lenient"]["rsi"]


PROG = """
DEF prog()
  x = ABS(-2.5)
  n = STRLEN("abcd")
  y = ATAN2(1.0, 1.0)
  ok = STRTOINT("'H1F'", k)
END
"""
DAT = "DEFDAT prog\n  DECL REAL x, y\n  DECL INT n, k\n  DECL BOOL ok\nENDDAT\n"


@pytest.mark.parametrize("interp", INTERPS)
def test_a_run_links_each_builtin_call_once_and_both_interpreters_agree(tmp_path, interp):
    run = run_krl(tmp_path, PROG, DAT, interp=interp)
    assert run.result.reason == "completed"
    assert (run.var("prog", "x"), run.var("prog", "n"), run.var("prog", "y")) == (2.5, 4, 45.0)
    assert (run.var("prog", "ok"), run.var("prog", "k")) == (True, 31)
    routine = run.rt.program.module("prog").main
    calls = [n for n in routine.walk() if isinstance(n, N.Call)]
    assert [c.name for c in calls] == ["ABS", "STRLEN", "ATAN2", "STRTOINT"]
    for c in calls:
        assert c.ann.callee.kind == NATIVE and c.ann.callee.native is LINKS[c.name] is REGISTRY[c.name].fn


def _backup(tmp: Path, program: str) -> Path:
    for d in ("R1/System", "R1/Program"):
        (tmp / d).mkdir(parents=True, exist_ok=True)
    write(tmp, "R1/System/$config.dat", "DEFDAT $CONFIG\nENDDAT\n")
    return write(tmp, "R1/Program/cell.src", program)


def _run(prog: Path, interp: str):
    tw = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(prog, mujoco=False, check=False, interp=interp), RunSinks(trace=tw))
    res = rt.run()
    io = [(e["signal"], e["value"]) for e in tw.events if e["kind"] == "io"]
    return io, res, [e["text"] for e in tw.events if e["kind"] == "message"]


@pytest.mark.parametrize("interp", INTERPS)
def test_stand_ins_do_what_their_declarations_say(tmp_path, interp):
    """In a backup: GET_SINGUL returns an E6POS of zeros, EB (an ANY result) the zero of the type
    its use gives it (REAL: 0.0), MSGNOTIFY does nothing (each noted once); STOOL, a BASIS
    routine the backup's own bas.src lacks (an older BASIS: BAS alone), stands in too (a FRAME
    of zeros). EKI_LOAD, a network routine, stops the run in a backup too."""
    write(tmp_path, "R1/System/bas.src", "DEF BAS(COMMAND :IN, VALUE :IN)\n  DECL BAS_COMMAND COMMAND\n"
          "  DECL REAL VALUE\nEND\n")
    prog = _backup(tmp_path, """
DEF cell()
  DECL REAL r
  DECL FRAME f
  DECL FDAT fd
  DECL E6POS p
  r = 7.0
  r = EB(1)
  p = GET_SINGUL(1)
  f = STOOL(1)
  MSGNOTIFY("x")
  $OUT[1] = (r == 0.0) AND (f.X == 0.0) AND (f.C == 0.0) AND (p.Y == 0.0)
  EKI_LOAD("x.xml")
END
""")
    io, res, notes = _run(prog, interp)
    assert io == [("$OUT[1]", True)]
    # (EK was a stand-in until issue 64: now interp/runtime/natives/geometry.py computes it)
    assert [n.split(" (", 1)[0] for n in notes] == ["stub: EB", "stub: GET_SINGUL", "stub: STOOL", "stub: MSGNOTIFY"]
    assert (res.reason, res.line, res.text) == ("error", 12, "routine EKI_LOAD not found")
    assert "routine NAME not found" in REGISTRY["EKI_LOAD"].stand_in
    assert "the zero value of the type its use gives it" in REGISTRY["EB"].stand_in
    assert "E6POS of zeros" in REGISTRY["GET_SINGUL"].stand_in
    assert REGISTRY["STOOL"].krl == "bas.src" and "does nothing" in REGISTRY["MSGNOTIFY"].stand_in


@pytest.mark.parametrize("interp", INTERPS)
def test_outside_a_backup_a_stand_in_runs_too_and_a_basis_routine_runs(tmp_path, interp):
    """One decision (docs/robot.md "KUKA's system software at run time", issue 46): the checker
    knows GET_SINGUL as KUKA's (the platform tables), so the run stands in for it outside a
    backup as inside one; a name nothing declares stays "routine NAME not found"."""
    run = run_krl(tmp_path, "DEF prog()\n  x = GET_SINGUL(1)\nEND\n",
                  "DEFDAT prog\n  DECL E6POS x\nENDDAT\n", interp=interp)
    assert run.result.reason == "completed", run.result.text
    assert run.var("prog", "x").f["X"] == 0.0
    assert "E6POS of zeros" in REGISTRY["GET_SINGUL"].stand_in
    run = run_krl(tmp_path, "DEF prog()\n  NOT_A_KUKA_ROUTINE(1)\nEND\n", "DEFDAT prog\nENDDAT\n", interp=interp)
    assert (run.result.reason, run.result.line, run.result.text) == ("error", 2, "routine NOT_A_KUKA_ROUTINE not found")
    # SCIRC_M is KRL of the project's BASIS (bas.src: the LDAT's CB)
    run = run_krl(tmp_path, "DEF prog()\n  m = SCIRC_M(ld)\nEND\n",
                  "DEFDAT prog\n  DECL CIRC_MODE m\n  DECL LDAT ld = {CB {AUX_PT {ORI #CONSIDER}}}\nENDDAT\n",
                  interp=interp)
    assert run.result.reason == "completed", run.result.text
    assert run.var("prog", "m").f["AUX_PT"].f["ORI"].name == "CONSIDER"
