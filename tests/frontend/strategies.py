"""Hypothesis strategies that generate KRL ASTs which the grammar can express."""

from __future__ import annotations

from hypothesis import strategies as st

from krl.ast import nodes as N

NAMES = ["a", "b1", "Count", "x_y", "P1", "gVal", "Tool_Nr", "speed"]
SYSNAMES = ["$OUT", "$VEL", "$TOOL", "$VEL_AXIS", "$APO"]
FIELDS = ["X", "Y", "CP", "A1", "NAME"]
TYPES = [None, "FRAME", "E6POS", "MyStruc"]
BINOPS = [":", "*", "/", "+", "-", "AND", "B_AND", "EXOR", "B_EXOR", "OR", "B_OR",
          "==", "<>", "<", ">", "<=", ">="]
UNOPS = ["-", "+", "NOT", "B_NOT"]

names = st.sampled_from(NAMES)
ints = st.builds(N.IntLit, st.integers(0, 2**31 - 1), st.sampled_from([10, 16, 2]))
dec_ints = st.builds(N.IntLit, st.integers(0, 200))
reals = st.builds(N.RealLit, st.floats(0, 1e30, allow_nan=False, allow_infinity=False))
strings = st.builds(N.StrLit, st.text(st.characters(min_codepoint=32, max_codepoint=126,
                                                   blacklist_characters='"'), max_size=8))
literals = st.one_of(ints, reals, st.builds(N.BoolLit, st.booleans()), strings,
                     st.builds(N.EnumLit, names))


def _lvalue(base):
    return st.recursive(base, lambda inner: st.one_of(
        st.builds(N.Field, inner, st.sampled_from(FIELDS)),
        st.builds(N.Index, inner, st.lists(st.one_of(st.none(), ints), min_size=1, max_size=3))),
        max_leaves=3)


lvalues = _lvalue(st.builds(N.Name, st.sampled_from(NAMES + SYSNAMES)))
sys_lvalues = _lvalue(st.builds(N.Name, st.sampled_from(SYSNAMES)))


def _args(inner):
    return st.lists(st.one_of(st.none(), inner), max_size=3).filter(lambda a: a != [None])


def _exprs():
    base = st.one_of(literals, lvalues)

    def extend(inner):
        return st.one_of(
            st.builds(N.Binary, st.sampled_from(BINOPS), inner, inner),
            st.builds(N.Unary, st.sampled_from(UNOPS), inner),
            st.builds(N.Call, names, _args(inner)),
            st.builds(N.Aggregate, st.sampled_from(TYPES),
                      st.lists(st.builds(N.AggItem, st.sampled_from(FIELDS), inner, st.booleans()),
                               min_size=1, max_size=3)),
        )
    return st.recursive(base, extend, max_leaves=5)


exprs = _exprs()
calls = st.builds(N.Call, names, _args(exprs))
assigns = st.builds(N.Assign, lvalues, exprs)
with_clauses = st.lists(st.builds(N.WithAssign, sys_lvalues, exprs), max_size=2)
approx = st.lists(st.sampled_from(["C_PTP", "C_DIS", "C_VEL", "C_ORI"]), max_size=2)
spl_approx = st.lists(st.sampled_from(["C_SPL", "C_DIS", "C_PTP"]), max_size=1)


def _motion():
    return st.one_of(
        st.builds(N.Motion, st.sampled_from(["PTP", "LIN"]), exprs, approx=approx),
        st.builds(N.Motion, st.sampled_from(["PTP_REL", "LIN_REL"]), exprs, approx=approx,
                  frame=st.sampled_from([None, "#BASE", "#TOOL"])),
        st.builds(N.Motion, st.just("CIRC"), exprs, exprs, st.one_of(st.none(), exprs), approx),
        st.builds(N.Motion, st.sampled_from(["SPTP", "SLIN"]), exprs, approx=spl_approx,
                  with_=with_clauses),
        st.builds(N.Motion, st.just("SCIRC"), exprs, exprs, st.one_of(st.none(), exprs),
                  st.lists(st.just("C_SPL"), max_size=1), with_clauses),
    )


simple_stmts = st.one_of(
    assigns,
    st.builds(N.CallStmt, calls),
    st.builds(N.Halt), st.builds(N.Continue), st.builds(N.OnErrorProceed), st.builds(N.Resume),
    st.builds(N.Brake, st.booleans()),
    st.builds(N.WaitFor, exprs), st.builds(N.WaitSec, exprs),
    st.builds(N.Return, st.one_of(st.none(), exprs)),
    st.builds(N.Goto, names), st.builds(N.Label, names),
    st.builds(N.InterruptDecl, st.one_of(dec_ints, st.builds(N.Name, names)), exprs, calls, st.booleans()),
    st.builds(lambda p, w, g, fast: N.InterruptDecl(p, w, N.Call("BRAKE_F" if fast else "BRAKE", []), g,
                                                    N.Brake(fast)),
              st.one_of(dec_ints, st.builds(N.Name, names)), exprs, st.booleans(), st.booleans()),
    st.builds(N.InterruptCtl, st.sampled_from(["ON", "OFF", "ENABLE", "DISABLE"]),
              st.one_of(st.none(), dec_ints, st.builds(N.Name, names))),
    st.builds(N.Trigger, st.just("DISTANCE"), st.builds(N.IntLit, st.integers(0, 1)), exprs,
              st.one_of(assigns, st.builds(N.CallStmt, calls)), st.one_of(st.none(), exprs)),
    st.builds(N.Trigger, st.just("PATH"), exprs, exprs, st.one_of(assigns, st.builds(N.CallStmt, calls)),
              st.one_of(st.none(), exprs), st.booleans()),
    _motion(),
)


def _stmts():
    def extend(inner):
        body = st.lists(inner, max_size=3)
        return st.one_of(
            st.builds(N.If, exprs, body, st.one_of(st.none(), body)),
            st.builds(N.While, exprs, body),
            st.builds(N.Repeat, body, exprs),
            st.builds(N.Loop, body),
            st.builds(N.For, st.builds(N.Name, names), exprs, exprs, st.one_of(st.none(), exprs), body),
            st.builds(N.Switch, exprs, st.lists(st.builds(N.Case, st.lists(exprs, min_size=1, max_size=2), body),
                                                 min_size=1, max_size=2), st.one_of(st.none(), body)),
        )
    return st.recursive(simple_stmts, extend, max_leaves=4)


stmts = _stmts()
var_decls = st.builds(N.VarDecl, st.builds(N.TypeRef, st.sampled_from(["INT", "REAL", "FRAME", "MyStruc"])),
                      st.lists(st.builds(N.VarName, names, st.lists(st.integers(1, 99), max_size=3)),
                               min_size=1, max_size=2)).map(_fix_decl := lambda d: d)


def _fix(d: N.VarDecl) -> N.VarDecl:
    d.decl_keyword = True
    return d


routines = st.builds(
    N.Routine, st.sampled_from(["DEF"]), names,
    st.lists(st.builds(N.Param, names, st.sampled_from([None, "IN", "OUT"]), st.integers(0, 2)), max_size=3),
    st.lists(var_decls.map(_fix), max_size=2), st.lists(stmts, max_size=3),
    is_global=st.booleans())
functions = st.builds(
    N.Routine, st.just("DEFFCT"), names, st.just([]), st.just([]), st.lists(stmts, max_size=3),
    st.builds(N.TypeRef, st.sampled_from(["INT", "E6POS", "CHAR"]), st.sampled_from([None, 12])))
modules = st.builds(N.Module, st.just("gen.src"), st.just("src"), st.just([]),
                    st.lists(st.one_of(routines, functions), min_size=1, max_size=2))

