"""AST -> KRL text (pretty-printer).

``print_module(module)`` returns KRL source such that parsing it and building the AST
again gives an equal AST (spans and annotations excluded). Comments and folds are not
in the AST and are not printed. Parentheses are inserted from operator precedence
(reference 4.1): unary > ':' > '*' '/' > '+' '-' > AND > EXOR > OR > comparisons; binary
operators associate to the left.
"""

from __future__ import annotations

import sys

from krl.ast import nodes as N
from krl.ast.visit import EXPRESSIONS, STATEMENTS, handlers

PREC = {
    "==": 1, "<>": 1, "<": 1, ">": 1, "<=": 1, ">=": 1,
    "OR": 2, "B_OR": 2,
    "EXOR": 3, "B_EXOR": 3,
    "AND": 4, "B_AND": 4,
    "+": 5, "-": 5,
    "*": 6, "/": 6,
    ":": 7,
}
UNARY_PREC = 8
ATOM_PREC = 9
INDENT = "  "


def _prec(e: N.Expr) -> int:
    if isinstance(e, N.Binary):
        return PREC.get(e.op, 0)
    if isinstance(e, N.Unary):
        return UNARY_PREC
    return ATOM_PREC


def fmt_real(value: float) -> str:
    text = repr(float(value))
    if text in ("inf", "-inf", "nan"):
        return "0.0"
    return text.upper() if "e" in text else text


def expr(e: N.Expr | None) -> str:
    """One expression as KRL text."""
    if e is None:
        return ""
    fn = _EXPR.get(e.__class__)
    if fn is None:
        raise TypeError(f"not an expression: {type(e).__name__}")
    return fn(e)


def _e_IntLit(e: N.Expr):
    if e.base == 16:
        return f"'H{e.value:X}'"
    if e.base == 2:
        return f"'B{e.value:b}'"
    return str(e.value)


def _e_RealLit(e: N.Expr):
    return fmt_real(e.value)


def _e_BoolLit(e: N.Expr):
    return "TRUE" if e.value else "FALSE"


def _e_StrLit(e: N.Expr):
    return f'"{e.value}"'


def _e_EnumLit(e: N.Expr):
    return f"#{e.name}"


def _e_ChannelName(e: N.Expr):
    return f":{e.name}"


def _e_Name(e: N.Expr):
    return e.name


def _e_Index(e: N.Expr):
    return f"{expr(e.base)}[{','.join(expr(i) for i in e.indices)}]"


def _e_Field(e: N.Expr):
    return f"{expr(e.base)}.{e.name}"


def _e_Call(e: N.Expr):
    return f"{e.name}({', '.join(expr(a) for a in e.args)})"


def _e_Aggregate(e: N.Expr):
    head = f"{e.type_name}: " if e.type_name else ""
    items = ", ".join(f"{i.name}{'[]' if i.array else ''} {expr(i.value)}" for i in e.items)
    return "{" + head + items + "}"


def _e_Unary(e: N.Expr):
    inner = expr(e.operand)
    if _prec(e.operand) < UNARY_PREC:
        inner = f"({inner})"
    if e.op in ("NOT", "B_NOT"):
        return f"{e.op} {inner}"
    return f"{e.op}{inner}"


def _e_Binary(e: N.Expr):
    # a left-associative chain (up to MAX_EXPRESSION_TERMS terms) in a loop, not recursively
    left, chain = N.left_chain(e)
    text, inner = expr(left), left
    for b in chain:
        p = PREC.get(b.op, 0)
        right = expr(b.right)
        if _prec(inner) < p:
            text = f"({text})"
        if _prec(b.right) <= p:
            right = f"({right})"
        text, inner = f"{text} {b.op} {right}", b
    return text



def _with(items: list[N.WithAssign]) -> str:
    if not items:
        return ""
    return " WITH " + ", ".join(f"{expr(w.target)} = {expr(w.value)}" for w in items)


def _dims(dims: list[int]) -> str:
    return f"[{','.join(str(d) if d else '' for d in dims)}]" if dims else ""


def _size(size: int | None) -> str:
    if size is None:
        return ""
    return "[]" if size == 0 else f"[{size}]"


def decl(d: N.Decl) -> str:
    """One declaration line (without newline)."""
    if isinstance(d, N.VarDecl):
        parts = []
        if d.decl_keyword:
            parts.append("DECL")
        if d.is_global:
            parts.append("GLOBAL")
        if d.is_const:
            parts.append("CONST")
        parts.append(d.type.name)
        parts.append(", ".join(v.name + _dims(v.dims) for v in d.names))
        text = " ".join(parts)
        if d.init is not None:
            text += " = " + expr(d.init)
        return text
    if isinstance(d, N.ArrayInit):
        idx = ",".join("" if i is None else str(i) for i in d.indices)
        return f"{d.name}[{idx}] = {expr(d.value)}"
    if isinstance(d, N.StrucDecl):
        comps = []
        prev = None
        for c in d.components:
            comps.append((f"{c.type_name} " if c.type_name != prev else "") + c.name + _dims(c.dims))
            prev = c.type_name
        return ("GLOBAL " if d.is_global else "") + f"STRUC {d.name} " + ", ".join(comps)
    if isinstance(d, N.EnumDecl):
        return ("GLOBAL " if d.is_global else "") + f"ENUM {d.name} " + ", ".join(d.values)
    if isinstance(d, N.SignalDecl) and d.start is None:
        return ("GLOBAL " if d.is_global else "") + f"SIGNAL {d.name} FALSE"
    if isinstance(d, N.SignalDecl):
        text = ("GLOBAL " if d.is_global else "") + f"SIGNAL {d.name} {d.start.sysvar}[{d.start.index}]"
        if d.end is not None:
            text += f" TO {d.end.sysvar}[{d.end.index}]"
        return text
    if isinstance(d, N.ExtDecl):
        ps = []
        for p in d.params:
            t = p.type_name + _size(p.type_size)
            if p.name:
                t += f" {p.name}{_size(p.name_size)}"
            if p.mode:
                t += f" :{p.mode}"
            ps.append(t)
        rt = f"{d.return_type.name}{_size(d.return_type.size)} " if d.return_type else ""
        return f"{d.kind} {rt}{d.name}({', '.join(ps)})"
    if isinstance(d, N.ImportDecl):
        parts = list(d.path) + ["", "", ""]
        return f"IMPORT {d.type_name} {d.name} IS /{parts[0]}/{parts[1]}..{parts[2]}"
    if isinstance(d, N.ChannelDecl):
        return f"CHANNEL :{d.name} :{d.device} {d.param}"
    if isinstance(d, N.Unparsed):
        return d.text
    raise TypeError(f"not a declaration: {type(d).__name__}")


def _motion(m: N.Motion) -> str:
    text = m.kind + " "
    if m.aux is not None:
        text += expr(m.aux) + ", "
    text += expr(m.target)
    if m.ca is not None:
        text += ", CA " + expr(m.ca)
    text += _with(m.with_)
    if m.approx:
        text += " " + " ".join(m.approx)
    if m.frame:
        text += " " + m.frame
    return text


def _trigger_action(s: N.Stmt) -> str:
    if isinstance(s, N.Assign):
        return f"{expr(s.target)} = {expr(s.value)}"
    if isinstance(s, N.CallStmt):
        return expr(s.call)
    return "".join(stmt(s, 0))


def stmt(s: N.Stmt, level: int = 1) -> list[str]:
    """A statement as indented lines."""
    fn = _STMT.get(s.__class__)
    if fn is None:
        raise TypeError(f"not a statement: {type(s).__name__}")
    return fn(s, INDENT * level, level)


def _s_Assign(s, ind: str, level: int):
    return [f"{ind}{expr(s.target)} = {expr(s.value)}"]


def _s_CallStmt(s, ind: str, level: int):
    return [ind + expr(s.call)]


def _s_If(s, ind: str, level: int):
    out = [f"{ind}IF {expr(s.cond)} THEN"] + block(s.then, level + 1)
    if s.orelse is not None:
        out += [f"{ind}ELSE"] + block(s.orelse, level + 1)
    return out + [f"{ind}ENDIF"]


def _s_Switch(s, ind: str, level: int):
    out = [f"{ind}SWITCH {expr(s.selector)}"]
    for c in s.cases:
        out += [f"{ind}CASE {', '.join(expr(v) for v in c.values)}"] + block(c.body, level + 1)
    if s.default is not None:
        out += [f"{ind}DEFAULT"] + block(s.default, level + 1)
    return out + [f"{ind}ENDSWITCH"]


def _s_For(s, ind: str, level: int):
    step = f" STEP {expr(s.step)}" if s.step is not None else ""
    return ([f"{ind}FOR {s.var.name} = {expr(s.start)} TO {expr(s.end)}{step}"]
            + block(s.body, level + 1) + [f"{ind}ENDFOR"])


def _s_While(s, ind: str, level: int):
    return [f"{ind}WHILE {expr(s.cond)}"] + block(s.body, level + 1) + [f"{ind}ENDWHILE"]


def _s_Repeat(s, ind: str, level: int):
    return [f"{ind}REPEAT"] + block(s.body, level + 1) + [f"{ind}UNTIL {expr(s.cond)}"]


def _s_Loop(s, ind: str, level: int):
    return [f"{ind}LOOP"] + block(s.body, level + 1) + [f"{ind}ENDLOOP"]


def _s_Exit(s, ind: str, level: int):
    return [ind + "EXIT"]


def _s_Goto(s, ind: str, level: int):
    return [f"{ind}GOTO {s.label}"]


def _s_Label(s, ind: str, level: int):
    return [f"{ind}{s.name}:"]


def _s_Halt(s, ind: str, level: int):
    return [ind + "HALT"]


def _s_WaitFor(s, ind: str, level: int):
    return [f"{ind}WAIT FOR {expr(s.cond)}"]


def _s_WaitSec(s, ind: str, level: int):
    return [f"{ind}WAIT SEC {expr(s.time)}"]


def _s_Continue(s, ind: str, level: int):
    return [ind + "CONTINUE"]


def _s_Return(s, ind: str, level: int):
    return [ind + "RETURN" + (f" {expr(s.value)}" if s.value is not None else "")]


def _s_OnErrorProceed(s, ind: str, level: int):
    return [ind + "ON_ERROR_PROCEED"]


def _s_InterruptDecl(s, ind: str, level: int):
    g = "GLOBAL " if s.is_global else ""
    action = ("BRAKE F" if s.brake.fast else "BRAKE") if s.brake is not None else expr(s.call)
    return [f"{ind}{g}INTERRUPT DECL {expr(s.prio)} WHEN {expr(s.when)} DO {action}"]


def _s_InterruptCtl(s, ind: str, level: int):
    return [f"{ind}INTERRUPT {s.action}" + (f" {expr(s.prio)}" if s.prio is not None else "")]


def _s_Brake(s, ind: str, level: int):
    return [ind + ("BRAKE F" if s.fast else "BRAKE")]


def _s_Resume(s, ind: str, level: int):
    return [ind + "RESUME"]


def _s_Trigger(s, ind: str, level: int):
    at = f"{s.kind} = {expr(s.at)}" + (" ONSTART" if s.onstart else "")
    text = f"{ind}TRIGGER WHEN {at} DELAY = {expr(s.delay)} DO {_trigger_action(s.action)}"
    if s.prio is not None:
        text += f" PRIO = {expr(s.prio)}"
    return [text]


def _s_AninOn(s, ind: str, level: int):
    return [f"{ind}ANIN ON {expr(s.target)} = {expr(s.value)}"]


def _s_AninOff(s, ind: str, level: int):
    return [f"{ind}ANIN OFF {s.name}"]


def _s_AnoutOn(s, ind: str, level: int):
    text = f"{ind}ANOUT ON {s.name} = {expr(s.value)}"
    for key, v in (("DELAY", s.delay), ("MINIMUM", s.minimum), ("MAXIMUM", s.maximum)):
        if v is not None:
            text += f" {key} = {expr(v)}"
    return [text]


def _s_AnoutOff(s, ind: str, level: int):
    return [f"{ind}ANOUT OFF {s.name}"]


def _s_Motion(s, ind: str, level: int):
    return [ind + _motion(s)]


def _s_SplineBlock(s, ind: str, level: int):
    out = [f"{ind}{s.kind}{_with(s.with_)}"] + block(s.body, level + 1)
    return out + [f"{ind}ENDSPLINE" + (f" {s.approx}" if s.approx else "")]


def _s_KeywordStmt(s, ind: str, level: int):
    return [ind + " ".join(s.words + ([", ".join(expr(a) for a in s.args)] if s.args else []))]


def _s_MoveEmi(s, ind: str, level: int):
    tail = f" {s.key} {expr(s.value)}" if s.key is not None else ""
    return [f'{ind}MOVE_EMI {expr(s.target)} "{s.file}"{tail}']


def _s_DeclStmt(s, ind: str, level: int):
    return [ind + decl(s.decl)]


def _s_Unsupported(s, ind: str, level: int):
    return [ind + line for line in s.text.splitlines()] or [ind]


def _s_ConditionalStop(s, ind: str, level: int):
    return [f"{ind}STOP WHEN PATH = {expr(s.path)}{' ONSTART' if s.onstart else ''} IF {expr(s.cond)}"]


def _s_Unparsed(s, ind: str, level: int):
    return [ind + s.text]



def block(stmts: list[N.Stmt], level: int) -> list[str]:
    """Statements as lines indented to `level`."""
    out: list[str] = []
    for s in stmts:
        out.extend(stmt(s, level))
    return out


def routine(r: N.Routine) -> list[str]:
    """A routine as lines, from its DEF/DEFFCT header to END/ENDFCT (2.2-2.4)."""
    params = ", ".join(p.name + (f"[{',' * (p.dims - 1)}]" if p.dims else "")
                       + (f" :{p.mode}" if p.mode else "") for p in r.params)
    g = "GLOBAL " if r.is_global else ""
    if r.kind == "DEFFCT":
        rt = r.return_type.name + _size(r.return_type.size) if r.return_type else "INT"
        head = f"{g}DEFFCT {rt} {r.name}({params})"
        end = "ENDFCT"
    else:
        head = f"{g}DEF {r.name}({params})"
        end = "END"
    return [head] + [INDENT + decl(d) for d in r.decls] + block(r.body, 1) + [end]


def print_module(m: N.Module) -> str:
    """The whole file as KRL text, lines ending in '\\n'."""
    lines = list(m.headers)
    if m.data is not None:
        lines.append(f"DEFDAT {m.data.name}" + (" PUBLIC" if m.data.public else ""))
        lines += [INDENT + decl(d) for d in m.data.items]
        lines.append("ENDDAT")
    for i, r in enumerate(m.routines):
        if i:
            lines.append("")
        lines += routine(r)
    return "\n".join(lines) + "\n"


# one function per expression and statement kind (krl/ast/visit.py: a kind the AST gains fails here)
_EXPR = handlers(sys.modules[__name__], "_e_", EXPRESSIONS)
_STMT = handlers(sys.modules[__name__], "_s_", STATEMENTS)
