"""The back ends decide meaning from the front end's typed facts, never from a name's spelling
(issue 38): every fact the resolver gives (place, callee, GOTO target, cyclic flag, BRAKE
handler, analog channel, STRUC of an aggregate) on a program written for it, and no KRL name
spelled as a string in the tree interpreter or the compiler."""

from __future__ import annotations

import ast
from pathlib import Path

from krl.ast import nodes as N
from krl.semantics.builtins import load_builtins
from krl.semantics.resolve import MODULE, NATIVE, ROUTINE, STUB, SYSTEM, Callee, Layout, Storage
from krl.semantics import types as T
from krl.workspace import check_texts

REPO = Path(__file__).resolve().parents[2]
BACK_ENDS = sorted((REPO / "interp" / "tree").glob("*.py")) + [REPO / "interp" / "vm" / "compiler.py"]

PROG = """DEF prog()
  DECL INT i
  DECL REAL v
  DECL E6POS p
  SIGNAL Sens $ANIN[2]
  SIGNAL Out1 $ANOUT[1]
  INTERRUPT DECL 3 WHEN $IN[1] DO BRAKE F
  INTERRUPT DECL 4 WHEN $IN[2] DO helper()
  $CYCFLAG[2] = $IN[3] AND $IN[4]
  $FLAG[2] = TRUE
  ANIN ON v = 2.0 * Sens
  ANIN OFF Sens
  ANOUT ON Out1 = 0.5 * v
  ANOUT OFF Out1
  p = {E6POS: X 1.0}
  IF i == 0 THEN
    GOTO done
  ENDIF
  i = ABS(-3) + count
  helper()
  tech_call()
done:
  i = 1
END

DEF helper()
  GOTO nowhere
END
"""
DAT = "DEFDAT prog\n  DECL INT count = 2\nENDDAT\n"


def _checked():
    ws = check_texts({"/p/prog.src": PROG, "/p/prog.dat": DAT})
    r = ws.modules["PROG"].routines[0]
    return ws, r, list(r.walk())


def test_every_fact_of_the_resolver():
    ws, r, nodes = _checked()
    assert isinstance(r.ann.layout, Layout) and [s.name for s in r.ann.layout.slots][:3] == ["i", "v", "p"]
    count = next(n for n in nodes if isinstance(n, N.Name) and n.name == "count").ann.place
    assert isinstance(count, Storage) and count.kind == MODULE and count.slot == 0
    calls = {n.name: n.ann.callee for n in nodes if isinstance(n, N.Call)}
    assert all(isinstance(c, Callee) for c in calls.values())
    assert calls["helper"].kind == ROUTINE and calls["helper"].routine is ws.modules["PROG"].routines[1]
    assert calls["ABS"].kind == NATIVE and calls["ABS"].native is None     # a check alone links no implementation
    assert calls["tech_call"].kind == STUB
    stmts = [n for n in nodes if isinstance(n, N.Stmt)]
    cyc, flag = [s for s in stmts if isinstance(s, N.Assign)][:2]
    assert cyc.ann.cyclic is True and flag.ann.cyclic is False
    brake, handler = [s for s in stmts if isinstance(s, N.InterruptDecl)]
    assert brake.brake is not None and brake.brake.fast and handler.brake is None
    anin_on, anin_off, anout_on, anout_off = [s for s in stmts if isinstance(s, (N.AninOn, N.AninOff, N.AnoutOn,
                                                                                   N.AnoutOff))]
    assert anin_on.ann.channel.name == "Sens" and anin_on.ann.channel.key == anin_off.ann.channel.key
    assert anout_on.ann.channel.key == anout_off.ann.channel.key != anin_on.ann.channel.key
    agg = next(n for n in nodes if isinstance(n, N.Aggregate))
    assert isinstance(agg.ann.struc, T.Struc) and agg.ann.struc.name == "E6POS"
    goto = next(s for s in stmts if isinstance(s, N.Goto))
    label = next(s for s in stmts if isinstance(s, N.Label))
    assert goto.ann.target is label
    nowhere = next(n for n in ws.modules["PROG"].routines[1].walk() if isinstance(n, N.Goto))
    assert nowhere.ann.target is None
    in1 = next(n for n in nodes if isinstance(n, N.Name) and n.name == "$IN").ann.place
    assert in1.kind == SYSTEM


def test_the_back_ends_spell_no_krl_name():
    """No string constant of the tree interpreter or the compiler is a KRL name of the tables
    (a system variable, a built-in routine) or BRAKE's handler names: meaning comes from the
    facts above."""
    tables = load_builtins()
    names = {n.upper() for n in tables.sysvars} | {n.upper() for n in tables.routines} | {"BRAKE", "BRAKE_F"}
    found = []
    for path in BACK_ENDS:
        tree = ast.parse(path.read_text(encoding="utf-8"))
        opcodes = {id(c.args[0]) for c in ast.walk(tree) if isinstance(c, ast.Call) and c.args
                   and isinstance(c.func, ast.Attribute) and c.func.attr == "emit"}   # the VM's opcode names
        for node in ast.walk(tree):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in opcodes \
                    and (node.value.upper() in names or node.value.upper().startswith("$")):
                found.append(f"{path.name}:{node.lineno}: {node.value!r}")
    assert not found, found
