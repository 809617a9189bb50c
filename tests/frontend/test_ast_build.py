"""AST shapes per construct (reference sections in the test names' docstrings)."""

from __future__ import annotations

from krl.ast import nodes as N
from krl.ast.build import Builder, build_module
from krl.diagnostics import DiagnosticSink
from krl.syntax.parse import parse_text
from krl.workspace import check_texts

from .helpers import ast_of, body_of


def test_routine_header_params_and_decls():
    """2.2-2.3: parameters with modes and open array dims; declaration section."""
    m = ast_of("GLOBAL DEF Move(t :IN, ok :OUT, buf[] :OUT)\n  DECL E6POS t\n  BOOL ok\n"
               "  DECL CHAR buf[]\n  ok = TRUE\nEND\n")
    r = m.routines[0]
    assert (r.kind, r.name, r.is_global) == ("DEF", "Move", True)
    assert [(p.name, p.mode, p.dims) for p in r.params] == [("t", "IN", 0), ("ok", "OUT", 0), ("buf", "OUT", 1)]
    assert [d.type.name for d in r.decls] == ["E6POS", "BOOL", "CHAR"]
    assert r.decls[2].names[0].dims == [0]
    assert isinstance(r.body[0], N.Assign)
    assert r.span.line == 1 and r.body[0].span.line == 5


def test_function_return_type():
    """2.4: DEFFCT with a CHAR[n] return type."""
    r = ast_of("DEFFCT CHAR[12] Name()\n  RETURN \"ab\"\nENDFCT\n").routines[0]
    assert r.kind == "DEFFCT" and r.return_type == N.TypeRef("CHAR", 12)
    assert r.body == [N.Return(N.StrLit("ab"))]


def test_expression_precedence_and_literals():
    """4.1: comparisons bind weaker than AND; unary binds tightest; literal kinds (1.5)."""
    [s] = body_of("x = a == 1 AND b")
    assert s.value == N.Binary("==", N.Name("a"), N.Binary("AND", N.IntLit(1), N.Name("b")))
    [s] = body_of("x = -'H1F' + 'B101' * 2.5E1")
    assert s.value == N.Binary("+", N.Unary("-", N.IntLit(31, 16)),
                               N.Binary("*", N.IntLit(5, 2), N.RealLit(25.0)))
    [s] = body_of("x = NOT TRUE OR #ON == #OFF")
    assert s.value.op == "==" and isinstance(s.value.left, N.Binary)


def test_geometric_operator_and_aggregates():
    """4.3 and 1.5: ':' chains, typed and untyped aggregates, CHAR-array components."""
    [s] = body_of("p = a : b : {X 1, Y -2}")
    assert s.value == N.Binary(":", N.Binary(":", N.Name("a"), N.Name("b")),
                               N.Aggregate(None, [N.AggItem("X", N.IntLit(1)),
                                                  N.AggItem("Y", N.Unary("-", N.IntLit(2)))]))
    [s] = body_of('m = {KRLMSG_T: MODUL[] "x", NR 3}')
    assert s.value.type_name == "KRLMSG_T" and s.value.items[0].array


def test_variables_selectors_and_calls():
    """4.2: indices, omitted indices, fields, calls with omitted arguments."""
    [a, b, c] = body_of("s[] = \"abc\"\nt[2,] = \"x\"\nF(a, , b[], p.X)")
    assert a.target == N.Index(N.Name("s"), [None])
    assert b.target == N.Index(N.Name("t"), [N.IntLit(2), None])
    assert c.call.args == [N.Name("a"), None, N.Index(N.Name("b"), [None]), N.Field(N.Name("p"), "X")]


def test_control_flow():
    """5.2-5.6: IF/ELSE, SWITCH, FOR STEP, WHILE, REPEAT, LOOP, EXIT, GOTO/labels."""
    body = body_of("IF a THEN\n  b = 1\nELSE\nENDIF\nSWITCH n\nCASE 1, 2\n  x = 1\nDEFAULT\nENDSWITCH\n"
                   "FOR i = 1 TO 9 STEP 2\nENDFOR\nWHILE a\nENDWHILE\nREPEAT\nUNTIL a\n"
                   "LOOP\n  EXIT\nENDLOOP\nlab:\nGOTO lab")
    kinds = [type(s).__name__ for s in body]
    assert kinds == ["If", "Switch", "For", "While", "Repeat", "Loop", "Label", "Goto"]
    assert body[0].orelse == [] and body[1].cases[0].values == [N.IntLit(1), N.IntLit(2)]
    assert body[1].default == [] and body[2].step == N.IntLit(2)
    assert body[5].body == [N.Exit()]


def test_wait_interrupts_triggers():
    """5.8, 5.16-5.18."""
    body = body_of("WAIT FOR $IN[1]\nWAIT SEC 0.5\nGLOBAL INTERRUPT DECL 3 WHEN $STOPMESS==TRUE DO IR_STOPM()\n"
                   "INTERRUPT ON 3\nINTERRUPT OFF\nBRAKE F\nRESUME\n"
                   "TRIGGER WHEN DISTANCE=1 DELAY=20 DO $OUT[2]=TRUE PRIO=-1\n"
                   "TRIGGER WHEN PATH=-5 ONSTART DELAY=0 DO Act(1)")
    assert body[2] == N.InterruptDecl(N.IntLit(3), N.Binary("==", N.Name("$STOPMESS"), N.BoolLit(True)),
                                      N.Call("IR_STOPM", []), True)
    assert body[3] == N.InterruptCtl("ON", N.IntLit(3)) and body[4] == N.InterruptCtl("OFF", None)
    assert body[5] == N.Brake(True)
    t1, t2 = body[7], body[8]
    assert (t1.kind, t1.at, t1.prio) == ("DISTANCE", N.IntLit(1), N.Unary("-", N.IntLit(1)))
    assert isinstance(t1.action, N.Assign)
    assert (t2.kind, t2.onstart, t2.prio) == ("PATH", True, None) and isinstance(t2.action, N.CallStmt)


def test_motions():
    """6.1: approximation, CIRC with CA, relative frame, WITH clause."""
    a, b, c, d = body_of("PTP XP1 C_PTP C_DIS\nCIRC A1, B1, CA 90 C_ORI\nLIN_REL {X 10} C_DIS #TOOL\n"
                         "SPTP XP1 WITH $VEL_AXIS[1] = SVEL_JOINT(100), $TOOL = STOOL2(FP1) C_SPL")
    assert a == N.Motion("PTP", N.Name("XP1"), approx=["C_PTP", "C_DIS"])
    assert b == N.Motion("CIRC", N.Name("B1"), N.Name("A1"), N.IntLit(90), ["C_ORI"])
    assert c.frame == "#TOOL" and c.kind == "LIN_REL"
    assert [w.target for w in d.with_] == [N.Index(N.Name("$VEL_AXIS"), [N.IntLit(1)]), N.Name("$TOOL")]
    assert d.approx == ["C_SPL"]


def test_spline_block():
    """6.2: SPLINE ... ENDSPLINE with segments, a trigger and WITH."""
    [blk] = body_of("SPLINE WITH $VEL.CP = 0.2\n  SPL P1\n  TRIGGER WHEN PATH=-1 DELAY=0 DO f()\n"
                    "  SLIN P2\n  SCIRC P3, P4\nENDSPLINE C_SPL")
    assert blk.kind == "SPLINE" and blk.approx == "C_SPL" and len(blk.with_) == 1
    assert [type(s).__name__ for s in blk.body] == ["Motion", "Trigger", "Motion", "Motion"]
    assert [getattr(s, "kind", "") for s in blk.body] == ["SPL", "PATH", "SLIN", "SCIRC"]


def test_data_list_items():
    """2.5, 3.5, 3.6, 3.8, 2.6: data list declarations."""
    m = ast_of("DEFDAT t PUBLIC\n  DECL GLOBAL INT n = 3\n  DECL CONST REAL pi = 3.14\n"
               "  E6AXIS xh = {A1 0, A2 -90}\n  DECL FRAME fr[4]\n  fr[2] = {X 1}\n  CHAR nm[8]\n"
               "  nm[] = \"ab\"\n  GLOBAL STRUC S INT a, b, REAL c[3]\n  GLOBAL ENUM E ON, OFF, X\n"
               "  SIGNAL go $OUT[3] TO $OUT[10]\n  EXT Foo(INT :IN, REAL[] :OUT)\n"
               "  EXTFCTP INT STRLEN(CHAR STRVAR[2047] :IN)\nENDDAT\n", "t.dat")
    d = m.data
    assert (d.name, d.public, m.kind) == ("t", True, "dat")
    items = d.items
    assert items[0].is_global and items[0].init == N.IntLit(3)
    assert items[1].is_const
    assert items[2].decl_keyword is False and items[2].type.name == "E6AXIS"
    assert items[4] == N.ArrayInit("fr", [2], N.Aggregate(None, [N.AggItem("X", N.IntLit(1))]))
    assert items[6] == N.ArrayInit("nm", [None], N.StrLit("ab"))
    assert [(c.type_name, c.name, c.dims) for c in items[7].components] == [
        ("INT", "a", []), ("INT", "b", []), ("REAL", "c", [3])]
    assert items[8].values == ["ON", "OFF", "X"]
    assert items[9].end == N.SignalRef("$OUT", 10)
    assert [p.type_size for p in items[10].params] == [None, 0]
    assert items[11].params[0].name_size == 2047 and items[11].return_type.name == "INT"


def test_unknown_context_degrades_to_unsupported():
    """The builder never raises: an unmapped statement becomes Unsupported + W003."""
    result = parse_text("DEF t()\n  x = 1\nEND\n", "t.src")
    sink = DiagnosticSink()
    b = Builder("t.src", sink, list(type(result.tree.parser).symbolicNames), recovered=False)
    stmt_ctx = result.tree.routine(0).getChild(0).routineBody().statementList().statementLine(0).statement()

    class FancyStatementContext(type(stmt_ctx)):  # a label the builder has never seen
        pass

    stmt_ctx.__class__ = FancyStatementContext
    assert isinstance(b.statement(stmt_ctx), N.Assign)   # a wrapper around an assignment
    goto = parse_text("DEF t()\n  GOTO m\nEND\n", "t.src").tree
    g_ctx = goto.routine(0).getChild(0).routineBody().statementList().statementLine(0).statement()

    class WarpStatementContext(type(g_ctx)):
        pass

    g_ctx.__class__ = WarpStatementContext
    assert b.statement(g_ctx) == N.Unsupported("warpStatement", "GOTO m")
    assert [d.code for d in sink.items] == ["W003"]
    # a tree of a failed parse: no exception, just fewer nodes
    bad = parse_text("DEF t()\n  x = = 1\n  IF THEN\nEND\n", "b.src")
    assert not bad.ok
    assert isinstance(build_module(bad), N.Module)


def test_build_module_without_tree():
    class R:  # a ParseResult-like object that lost its tree
        path, ok, tree = "x.src", False, None
    assert build_module(R()) == N.Module("x.src", "src")


def test_newer_grammar_constructs():
    """Constructs added while the grammar grew: routine constants, CONFIRM, ASYPTP, MOVE_EMI,
    unwired system signals."""
    r = ast_of("DEF t()\n  DECL CONST INT MAX = 12\n  CONFIRM 3\n  ASYPTP {E1 90}\n"
               "  MOVE_EMI dev[] \"a.emily\" FLT 0\nEND\n").routines[0]
    assert r.decls == [N.VarDecl(N.TypeRef("INT"), [N.VarName("MAX")], N.IntLit(12), is_const=True)]
    assert r.body[0] == N.KeywordStmt(["CONFIRM"], [N.IntLit(3)])
    assert r.body[1].words == ["ASYPTP"] and isinstance(r.body[1].args[0], N.Aggregate)
    assert r.body[2] == N.MoveEmi(N.Index(N.Name("dev"), [None]), "a.emily", "FLT", N.IntLit(0))
    m = ast_of("DEFDAT $MACHINE PUBLIC\n  SIGNAL $MODE_TEST FALSE\nENDDAT\n", "m.dat")
    assert m.data.items == [N.SignalDecl("$MODE_TEST", None)]


def test_interrupt_brake_action():
    a, b = body_of("INTERRUPT DECL 5 WHEN $IN[1] DO BRAKE\nGLOBAL INTERRUPT DECL 6 WHEN $IN[2] DO BRAKE F")
    assert a == N.InterruptDecl(N.IntLit(5), N.Index(N.Name("$IN"), [N.IntLit(1)]), N.Call("BRAKE", []),
                                False, N.Brake(False))
    assert b.brake == N.Brake(True) and b.is_global and b.call == N.Call("BRAKE_F", [])


def test_workspace_routine_lookup():
    ws = check_texts({"a.src": "DEF a()\n  b()\nEND\nDEF b()\nEND\n"})
    sym = ws.lookup_routine("A")
    assert sym.decl is ws.units[0].routines[0] and ws.lookup_routine("b") is None
    assert ws.lookup_routine("SQRT").signature.returns is not None
