"""Generate the VM's dispatch loop, its opcode table and its C types from the instruction
definitions, interp/vm/instructions.py (as CPython's Tools/cases_generator does from
Python/bytecodes.c).

It reads the definitions as text (``ast``; they are never imported to run) and writes, checked in:

* interp/vm/loop.py: ``run``, the skeleton of instructions.py with ``DISPATCH()`` replaced by a
  binary search ``if op < k:`` over the hot instructions' handlers, shaped as a Huffman tree
  weighted by their measured frequency (``freq``), so that the commonest instruction is found
  after one or two tests; the cold instructions are one leaf (``COLD_DISPATCH``, the right-most)
  and one function each (``_cold_NAME``, in the table ``COLD``). The opcodes are numbered in
  the order of the tree's leaves, so the executed form dispatches on them directly.
  ``x.__class__`` is spelled ``type(x)`` (as fast in CPython; a pointer comparison in Cython).
  ``SOURCE``, its last line, is the sha256 of the text above it: vm.py runs a compiled loop
  only when it was built from this very file.
* interp/vm/opcodes.py: the opcode table (number, operand kinds and names, stack effect,
  cold, a superinstruction's parts, doc), the stack effect of every instruction as a function
  of its operands, and the superinstructions by their parts (the compiler's peephole).
* interp/vm/loop.pxd: the C types of ``run``'s locals and arguments (declarations.py
  ``C_LOCALS``, ``C_ARGS``; the integer operands' ``x1``, ``x2``, ...) and its module names as
  C globals, for the Cython build (interp/vm/build.py).

A handler is made from its definition: the operands bound (an integer kind to a C integer
``xN``; a field ``stmt.line`` read from the executed tuple), the inputs popped (the deepest one
read in place when the handler pushes a result: ``stack[-1]``), the ``@inline`` helpers
spliced in, the body, the outputs pushed (an output the body only assigns is pushed where it
is assigned), then ``ip += 1`` unless the body jumps or leaves. A superinstruction's handler is
its parts' in a row: a value one part pushes and a later part pops stays in a local
(``_s1``, ...). tests/vm/test_generated_loop.py fails when a generated file is stale;
regenerate with ``python -m interp.vm.gen_loop`` (``--check``: only compare).
"""

from __future__ import annotations

import ast
import builtins
import copy
import hashlib
import heapq
import itertools
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

from interp.runtime.convert import INT_MAX, INT_MIN

HERE = Path(__file__).resolve().parent
DEFINITIONS = HERE / "instructions.py"
#: the operand kinds and the loop's C types (KINDS, INT_KINDS, C_LOCALS, C_ARGS)
DECLARATIONS = HERE / "declarations.py"
LOOP = HERE / "loop.py"
TABLE = HERE / "opcodes.py"
PXD = HERE / "loop.pxd"

_LITERALS = {"INT_MIN": INT_MIN, "INT_MAX": INT_MAX}
_ITEM = re.compile(r"\s*(\w+)\s*(?:\[(.+)\])?\s*(?:\bif\b\s+(.+))?\s*\Z")
_RESERVED = re.compile(r"(x|p|_s)\d+\Z")
COLD_LEAF = "COLD_DISPATCH"
# added to every hot instruction's frequency (per 10 000): one the benchmark does not run (a
# LOAD_GLOBAL, a CALL of a real program) is still found within about ten tests
FREQ_FLOOR = 10.0
# the names a cold instruction's function receives
COLD_ARGS = ("self", "ins", "code", "frame", "temps", "stack", "ip")


class DefinitionError(Exception):
    """A definition the generator cannot make a handler of (names the definition and why)."""


@dataclass
class Item:
    """One stack item of an effect: ``name``; ``size`` (an expression over the operands) for
    ``name[size]``; ``cond`` for ``name if cond``."""
    name: str
    size: ast.expr | None = None
    cond: ast.expr | None = None
    text: str = ""

    @property
    def plain(self) -> bool:
        return self.size is None and self.cond is None


@dataclass
class Inst:
    name: str
    operands: list              # [(name, kind)]
    inputs: list                # [Item], bottom to top
    outputs: list               # [Item]
    body: list                  # ast statements (a plain instruction)
    freq: float = 0
    cold: bool = False
    doc: str = ""
    parts: list = field(default_factory=list)     # a macro's direct parts (Inst)
    errors_from: int | None = None
    effect_text: str = ""
    replaces: tuple = ()        # a specialized instruction's sequence (``@inst(replaces=...)``)

    def flat(self) -> list:
        """The plain instructions a macro expands to (itself for a plain one)."""
        if not self.parts:
            return [self]
        return [leaf for p in self.parts for leaf in p.flat()]


@dataclass
class Definitions:
    module: ast.Module
    insts: list                 # Inst, in the file's order
    inlines: dict               # name -> FunctionDef
    skeleton: ast.FunctionDef
    kinds: dict
    int_kinds: str
    c_locals: dict
    c_args: dict


# ---------------------------------------------------------------------------- reading
def _literal(module: ast.Module, name: str):
    for n in module.body:
        if isinstance(n, ast.Assign) and any(isinstance(t, ast.Name) and t.id == name for t in n.targets):
            return ast.literal_eval(n.value)
    raise DefinitionError(f"declarations.py defines no {name}")


def _items(text: str, operands: set, where: str) -> list:
    out = []
    for part in [p for p in text.split(",") if p.strip()]:
        m = _ITEM.match(part)
        if m is None:
            raise DefinitionError(f"{where}: bad stack item {part.strip()!r}")
        name, size, cond = m.groups()
        item = Item(name, text=part.strip())
        for attr, expr in (("size", size), ("cond", cond)):
            if expr is not None:
                tree = ast.parse(expr.strip(), mode="eval").body
                free = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)} - operands
                if free:
                    raise DefinitionError(f"{where}: {part.strip()!r} reads {sorted(free)}, not operands")
                setattr(item, attr, tree)
        out.append(item)
    return out


def _effect(text: str, operands: set, where: str) -> tuple[list, list]:
    if not text.strip():
        return [], []
    if "--" not in text:
        raise DefinitionError(f"{where}: a stack effect is written 'inputs -- outputs'")
    ins, outs = text.split("--")
    return _items(ins, operands, where), _items(outs, operands, where)


def _keywords(call: ast.Call) -> dict:
    return {k.arg: ast.literal_eval(k.value) for k in call.keywords}


def _body(fn: ast.FunctionDef) -> list:
    body = fn.body
    if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
            and isinstance(body[0].value.value, str):
        body = body[1:]
    return body


def read(text: str | None = None) -> Definitions:
    """The definitions of instructions.py (its text: `text`, default the file)."""
    text = DEFINITIONS.read_text(encoding="utf-8") if text is None else text
    module = ast.parse(text)
    decl = ast.parse(DECLARATIONS.read_text(encoding="utf-8"))
    kinds = {k: tuple(v) for k, v in _literal(decl, "KINDS").items()}
    insts: list = []
    by_name: dict = {}
    inlines: dict = {}
    skeleton = None
    for n in module.body:
        if isinstance(n, ast.FunctionDef):
            deco = n.decorator_list[0] if n.decorator_list else None
            dname = (deco.func.id if isinstance(deco, ast.Call) else deco.id) if deco is not None else None
            if dname == "inline":
                inlines[n.name] = n
            elif dname == "inst":
                where = f"instructions.py:{n.lineno}: {n.name}"
                operands = []
                for a in n.args.args:
                    if not (isinstance(a.annotation, ast.Constant) and a.annotation.value in kinds):
                        raise DefinitionError(f"{where}: operand {a.arg} has no kind of KINDS")
                    operands.append((a.arg, a.annotation.value))
                names = {o for o, _ in operands}
                effect = ast.literal_eval(deco.args[0]) if deco.args else ""
                inputs, outputs = _effect(effect, names, where)
                kw = _keywords(deco)
                doc = ast.get_docstring(n) or ""
                if not doc:
                    raise DefinitionError(f"{where}: no docstring (the one line `krl asm` readers go by)")
                inst = Inst(n.name, operands, inputs, outputs, _body(n), kw.get("freq", 0), kw.get("cold", False),
                            " ".join(doc.split()), effect_text=effect)
                if kw.get("replaces"):
                    inst.replaces = _replaces(inst, kw["replaces"], by_name, where)
                insts.append(inst)
                by_name[n.name] = inst
            elif n.name == "run" and deco is None:
                skeleton = n
        elif isinstance(n, ast.Assign) and isinstance(n.value, ast.Call) and isinstance(n.value.func, ast.Name) \
                and n.value.func.id == "macro":
            name = n.targets[0].id
            where = f"instructions.py:{n.lineno}: {name}"
            parts = []
            for p in n.value.args:
                if not (isinstance(p, ast.Name) and p.id in by_name):
                    raise DefinitionError(f"{where}: part {ast.unparse(p)} is not an instruction defined above")
                parts.append(by_name[p.id])
            kw = _keywords(n.value)
            inst = Inst(name, [o for p in parts for o in p.operands], [], [], [], kw.get("freq", 0),
                        False, "", parts=parts, errors_from=kw.get("errors_from"))
            inst.inputs, inst.outputs = _macro_effect(inst, where)
            inst.doc = ", ".join(p.name for p in parts) if not kw.get("doc") else \
                f"{kw['doc']} ({', '.join(p.name for p in parts)})"
            insts.append(inst)
            by_name[name] = inst
    if skeleton is None:
        raise DefinitionError("instructions.py has no loop skeleton `def run(...)`")
    return Definitions(module, insts, inlines, skeleton, kinds, _literal(decl, "INT_KINDS"),
                       _literal(decl, "C_LOCALS"), _literal(decl, "C_ARGS"))


def _replaces(inst: Inst, names, by_name: dict, where: str) -> tuple:
    """The sequence a specialized instruction (``@inst(replaces=(PART, ...))``: its own handler)
    replaces: its parts, defined above, whose operands concatenated are its own and whose net
    stack effect is its own (checked here)."""
    parts = []
    for p in names:
        if p not in by_name:
            raise DefinitionError(f"{where}: replaces {p}, not an instruction defined above")
        parts.append(by_name[p])
    if [k for p in parts for _, k in p.operands] != [k for _, k in inst.operands]:
        raise DefinitionError(f"{where}: its operands are not those of {', '.join(names)} concatenated")
    seq = Inst(inst.name, inst.operands, [], [], [], parts=parts)
    ins, outs = _macro_effect(seq, where)
    if not (all(i.plain for i in inst.inputs + inst.outputs)
            and (len(ins), len(outs)) == (len(inst.inputs), len(inst.outputs))):
        raise DefinitionError(f"{where}: its stack effect is not that of {', '.join(names)}")
    return tuple(names)


def _macro_effect(inst: Inst, where: str) -> tuple[list, list]:
    """The inputs and outputs of a macro on the real stack: its parts' items that no other
    part gives or takes."""
    sym: list = []
    real_in: list = []
    for k, part in enumerate(inst.flat()):
        if part.cold:
            raise DefinitionError(f"{where}: part {part.name} is cold")
        for item in reversed(part.inputs):
            if sym and item.plain:
                sym.pop()
                continue
            if sym or not item.plain:
                raise DefinitionError(f"{where}: part {part.name} takes {item.text} from below a value of an earlier part")
            real_in.append(Item(f"{item.name}{k}", text=f"{item.name}{k}"))
        for item in part.outputs:
            if not item.plain:
                raise DefinitionError(f"{where}: part {part.name} pushes {item.text} (not a plain item)")
            sym.append(Item(f"{item.name}{k}", text=f"{item.name}{k}"))
    return list(reversed(real_in)), sym


# ---------------------------------------------------------------------------- AST helpers
def _name(n: str, store: bool = False) -> ast.Name:
    return ast.Name(n, ast.Store() if store else ast.Load())


def _sub(base: str, index: int) -> ast.Subscript:
    return ast.Subscript(_name(base), ast.Constant(index), ast.Load())


def _stmt(text: str) -> ast.stmt:
    return ast.parse(text).body[0]


def _call(fn: str, *args) -> ast.Call:
    return ast.Call(_name(fn), list(args), [])


class _Replace(ast.NodeTransformer):
    """Names (loaded or stored) and attribute reads ``name.field`` replaced by expressions."""

    def __init__(self, names: dict, fields: dict | None = None) -> None:
        self.names = names
        self.fields = fields or {}

    def visit_Attribute(self, node):
        if isinstance(node.value, ast.Name) and (node.value.id, node.attr) in self.fields \
                and isinstance(node.ctx, ast.Load):
            return copy.deepcopy(self.fields[(node.value.id, node.attr)])
        return self.generic_visit(node)

    def visit_Name(self, node):
        got = self.names.get(node.id)
        if got is None:
            return node
        if isinstance(got, str):
            return ast.copy_location(_name(got, not isinstance(node.ctx, ast.Load)), node)
        if not isinstance(node.ctx, ast.Load):
            raise DefinitionError(f"an operand is assigned: {node.id}")
        return copy.deepcopy(got)


def _expand(stmts: list, inlines: dict, depth: int = 0) -> list:
    """``stmts`` with every ``@inline`` helper spliced in (statements; a helper whose body is
    one ``return`` as an expression)."""
    if depth > 8:
        raise DefinitionError("inline helpers nest too deeply")

    def args_of(call, fn):
        params = [a.arg for a in fn.args.args]
        if len(call.args) != len(params) or call.keywords:
            raise DefinitionError(f"{fn.name} takes {len(params)} arguments")
        return dict(zip(params, call.args))

    class Exprs(ast.NodeTransformer):
        def visit_Call(self, node):
            self.generic_visit(node)
            fn = inlines.get(node.func.id) if isinstance(node.func, ast.Name) else None
            if fn is None:
                return node
            body = _body(fn)
            if not (len(body) == 1 and isinstance(body[0], ast.Return)):
                raise DefinitionError(f"{fn.name} is a statement helper, used as an expression")
            return _Replace(args_of(node, fn)).visit(copy.deepcopy(body[0].value))

    out = []
    for st in stmts:
        if isinstance(st, ast.Expr) and isinstance(st.value, ast.Call) and isinstance(st.value.func, ast.Name) \
                and st.value.func.id in inlines:
            fn = inlines[st.value.func.id]
            body = _body(fn)
            if len(body) == 1 and isinstance(body[0], ast.Return):
                raise DefinitionError(f"{fn.name} is an expression helper, used as a statement")
            params = args_of(st.value, fn)
            repl = _Replace({k: (v.id if isinstance(v, ast.Name) else v) for k, v in params.items()})
            spliced = [repl.visit(copy.deepcopy(s)) for s in body]
            out += _expand(spliced, inlines, depth + 1)
            continue
        for fld in ("body", "orelse", "finalbody"):
            if isinstance(getattr(st, fld, None), list) and not isinstance(st, (ast.FunctionDef, ast.Lambda)):
                setattr(st, fld, _expand(getattr(st, fld), inlines, depth))
        if isinstance(st, ast.Try):
            for h in st.handlers:
                h.body = _expand(h.body, inlines, depth)
        out.append(Exprs().visit(st))
    return out


def _assigned(stmts: list) -> set:
    return {n.id for s in stmts for n in ast.walk(s) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}


def _loaded(stmts: list) -> set:
    return {n.id for s in stmts for n in ast.walk(s) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}


def _ends(stmts: list) -> bool:
    return bool(stmts) and isinstance(stmts[-1], (ast.Return, ast.Raise))


def _assigns_once(stmts: list, name: str) -> tuple[int, int]:
    """(least, most) plain assignments ``name = ...`` on a path through ``stmts``; (9, 9) where
    it is assigned otherwise (a loop, a walrus, a tuple)."""
    lo = hi = 0
    for st in stmts:
        if isinstance(st, ast.Assign) and len(st.targets) == 1 and isinstance(st.targets[0], ast.Name) \
                and st.targets[0].id == name:
            lo, hi = lo + 1, hi + 1
        elif isinstance(st, ast.If):
            a = _assigns_once(st.body, name)
            b = _assigns_once(st.orelse, name)
            lo, hi = lo + min(a[0], b[0]), hi + max(a[1], b[1])
        elif name in _assigned([st]):
            return 9, 9
    return lo, hi


def _push_at_assignments(stmts: list, name: str, marker) -> list:
    out = []
    for st in stmts:
        if isinstance(st, ast.Assign) and len(st.targets) == 1 and isinstance(st.targets[0], ast.Name) \
                and st.targets[0].id == name:
            out.append(ast.copy_location(ast.Expr(marker(st.value)), st))
        elif isinstance(st, ast.If):
            st.body = _push_at_assignments(st.body, name, marker)
            st.orelse = _push_at_assignments(st.orelse, name, marker)
            out.append(st)
        else:
            out.append(st)
    return out


# ---------------------------------------------------------------------------- handlers
_PUSH, _POP = "__push__", "__pop__"


class _Handler:
    """The statements of one instruction's handler (all its parts in a row)."""

    def __init__(self, defs: Definitions, inst: Inst, cold: bool) -> None:
        self.defs = defs
        self.inst = inst
        self.cold = cold
        self.nx = self.np = self.ns = 0
        self.index = 1              # the executed tuple's item of the next operand
        self.stmts: list = []
        self.pushes = 0             # pushes so far (push markers carry their number)

    def bind_operands(self, part: Inst, stmts: list) -> list:
        """``stmts`` with the part's operands read from ``ins``; the bindings first."""
        pre, names, fields = [], {}, {}
        kinds = self.defs.kinds
        for oname, kind in part.operands:
            base = self.index
            self.index += 1 + len(kinds[kind])
            for j, f in enumerate(kinds[kind]):
                fields[(oname, f)] = _sub("ins", base + 1 + j)
            bare = self.uses(stmts, oname, () if self.cold else kinds[kind])
            if not bare:
                continue
            if self.cold:
                local = oname
            elif kind in self.defs.int_kinds:
                self.nx += 1
                local = f"x{self.nx}"
            elif bare > 1:
                self.np += 1
                local = f"p{self.np}"
            else:
                names[oname] = _sub("ins", base)
                continue
            pre.append(ast.Assign([_name(local, True)], _sub("ins", base)))
            names[oname] = local
        if self.cold:
            fields = {}             # the linked object's attributes: the same values
        replace = _Replace(names, fields)
        return pre + [replace.visit(s) for s in stmts]

    @staticmethod
    def uses(stmts: list, oname: str, fields: tuple) -> int:
        """How often ``stmts`` read operand ``oname`` itself (not through one of its linked fields)."""
        through = {id(n.value) for s in stmts for n in ast.walk(s)
                   if isinstance(n, ast.Attribute) and isinstance(n.value, ast.Name) and n.attr in fields}
        return sum(1 for s in stmts for n in ast.walk(s) if isinstance(n, ast.Name) and n.id == oname
                   and isinstance(n.ctx, ast.Load) and id(n) not in through)

    def pop(self, item: Item) -> list:
        target = _name(item.name, True)
        if item.size is not None:
            cut = ast.Slice(ast.BinOp(_call("len", _name("stack")), ast.Sub(), copy.deepcopy(item.size)), None)
            return [ast.Assign([target], ast.Subscript(_name("stack"), cut, ast.Load())),
                    ast.Delete([ast.Subscript(_name("stack"), copy.deepcopy(cut), ast.Del())])]   # (not in place)
        value = _call(_POP)
        if item.cond is not None:
            value = ast.IfExp(copy.deepcopy(item.cond), _call("__popif__"), ast.Constant(None))
        return [ast.Assign([target], value)]

    def marker(self, value: ast.expr) -> ast.Call:
        return _call(_PUSH, value, ast.Constant(self.pushes))

    def build(self) -> list:
        parts = self.inst.flat()
        where = f"instructions.py: {self.inst.name}"
        sym: list = []               # locals holding the values parts pushed and later parts pop
        jumps = False
        for k, part in enumerate(parts):
            body = _expand(copy.deepcopy(part.body), self.defs.inlines)
            for n in _assigned(body) | _loaded(body):
                if _RESERVED.match(n):
                    raise DefinitionError(f"{where}: {part.name} uses {n}, a name the generator gives")
            loop_locals = _assigned(self.defs.skeleton.body) | {a.arg for a in self.defs.skeleton.args.args}
            clash = {i.name for i in part.inputs + part.outputs} & (loop_locals | set(COLD_ARGS))
            if clash:
                raise DefinitionError(f"{where}: stack item {sorted(clash)} is a name of the loop")
            operand_names = {o for o, _ in part.operands}
            clash = operand_names & (set(COLD_ARGS) | {"rt"})
            if clash:
                raise DefinitionError(f"{where}: operand {sorted(clash)} is a name of the loop")
            if "ip" in _assigned(body):
                if k != len(parts) - 1:
                    raise DefinitionError(f"{where}: part {part.name} jumps and is not the last part")
                jumps = True
            rename: dict = {}
            pops: list = []
            for item in reversed(part.inputs):
                if sym and item.plain:
                    rename[item.name] = sym.pop()
                    continue
                if sym:
                    raise DefinitionError(f"{where}: part {part.name} pops {item.text} from below a part's value")
                pops += self.pop(item)
            later_pops = any(p.inputs for p in parts[k + 1:])
            pre_pushes: list = []
            post: list = []
            out_names = [o.name for o in part.outputs]
            if later_pops:
                for o in part.outputs:
                    self.ns += 1
                    rename[o.name] = f"_s{self.ns}"
                    sym.append(f"_s{self.ns}")
            else:
                for s in sym:                # the values still held go first (deeper)
                    pre_pushes.append(ast.Expr(self.marker(_name(s))))
                    self.pushes += 1
                sym = []
                only = part.outputs[0] if len(part.outputs) == 1 else None
                if only is not None and only.plain and only.name not in {i.name for i in part.inputs} \
                        and only.name not in _loaded(body) and _assigns_once(body, only.name) == (1, 1):
                    body = _push_at_assignments(body, only.name, self.marker)
                    self.pushes += 1
                else:
                    for o in part.outputs:
                        push = ast.Expr(self.marker(_name(o.name)))
                        post.append(ast.If(copy.deepcopy(o.cond), [push], []) if o.cond is not None else push)
                        self.pushes += 1
                    if any(o not in _assigned(body) and o not in {i.name for i in part.inputs} for o in out_names):
                        raise DefinitionError(f"{where}: {part.name} does not assign its outputs {out_names}")
            code = pops + pre_pushes + body + post
            code = [_Replace(rename).visit(s) for s in code]
            self.stmts += self.bind_operands(part, code)
        if sym:
            raise DefinitionError(f"{where}: values left between parts")
        out = self.finish(self.stmts)
        if self.cold:
            if jumps:
                out.append(_stmt("return ip"))
            elif not _ends(out):
                out.append(_stmt("return ip + 1"))
        elif not jumps and not _ends(parts[-1].body):
            out.append(_stmt("ip += 1"))
        return out

    def finish(self, stmts: list) -> list:
        """Push and pop markers as stack operations; the deepest popped input read in place
        (``stack[-1]``) and the first pushed output written there when both are plain."""
        last_pop = None              # the deepest input: the last pop (pops are top-level statements)
        first_push = False
        for s in stmts:
            if isinstance(s, ast.Delete):
                last_pop = None      # an array popped below it
            elif isinstance(s, ast.Assign) and isinstance(s.value, ast.Call) and isinstance(s.value.func, ast.Name) \
                    and s.value.func.id == _POP:
                last_pop = s.value
            elif isinstance(s, ast.Assign) and isinstance(s.value, ast.IfExp):
                if any(isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id == "__popif__"
                       for n in ast.walk(s.value)):
                    last_pop = None
            for n in ast.walk(s):
                if isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id == _PUSH \
                        and n.args[1].value == 0:
                    first_push = True
        inplace = last_pop is not None and first_push and not self.cold

        class Ops(ast.NodeTransformer):
            def visit_Expr(self, node):
                self.generic_visit(node)
                c = node.value
                if isinstance(c, ast.Call) and isinstance(c.func, ast.Name) and c.func.id == _PUSH:
                    if inplace and c.args[1].value == 0:
                        return ast.copy_location(ast.Assign([ast.Subscript(_name("stack"), ast.Constant(-1), ast.Store())],
                                                            c.args[0]), node)
                    return ast.copy_location(ast.Expr(ast.Call(ast.Attribute(_name("stack"), "append", ast.Load()),
                                                               [c.args[0]], [])), node)
                return node

            def visit_Call(self, node):
                self.generic_visit(node)
                if isinstance(node.func, ast.Name) and node.func.id in (_POP, "__popif__"):
                    if inplace and node is last_pop:
                        return ast.Subscript(_name("stack"), ast.Constant(-1), ast.Load())
                    return ast.Call(ast.Attribute(_name("stack"), "pop", ast.Load()), [], [])
                return node

        return [Ops().visit(s) for s in stmts]


# ---------------------------------------------------------------------------- numbering and search
def _huffman(weights: dict):
    """A Huffman tree over the names: a name (leaf) or a pair (left, right)."""
    tie = itertools.count()
    heap = [(w, next(tie), name) for name, w in weights.items()]
    heapq.heapify(heap)
    while len(heap) > 1:
        wa, _, a = heapq.heappop(heap)
        wb, _, b = heapq.heappop(heap)
        heapq.heappush(heap, (wa + wb, next(tie), (a, b)))
    return heap[0][2]


def _has(node, leaf) -> bool:
    return node == leaf if not isinstance(node, tuple) else _has(node[0], leaf) or _has(node[1], leaf)


def _cold_right(node):
    """The same tree with the cold leaf the right-most (depths unchanged), so that the cold
    instructions are numbered last, one range."""
    if not isinstance(node, tuple):
        return node
    a, b = _cold_right(node[0]), _cold_right(node[1])
    return (b, a) if _has(a, COLD_LEAF) else (a, b)


def _leaves(node, out: list) -> list:
    if isinstance(node, tuple):
        _leaves(node[0], out)
        _leaves(node[1], out)
    else:
        out.append(node)
    return out


def numbering(defs: Definitions) -> tuple:
    """(the dispatch tree, opcode number by name, the first cold number)."""
    hot = {i.name: float(i.freq) + FREQ_FLOOR for i in defs.insts if not i.cold}
    hot[COLD_LEAF] = FREQ_FLOOR
    tree = _cold_right(_huffman(hot))
    order = [n for n in _leaves(tree, []) if n != COLD_LEAF]
    number = {n: k for k, n in enumerate(order)}
    first_cold = len(order)
    for i in defs.insts:
        if i.cold:
            number[i.name] = len(number)
    return tree, number, first_cold


def _search(node, leaf_body, number: dict, first_cold: int) -> list:
    if not isinstance(node, tuple):
        return leaf_body(node)
    right = _leaves(node[1], [])
    bound = first_cold if right[0] == COLD_LEAF else number[right[0]]
    test = ast.Compare(_name("op"), [ast.Lt()], [ast.Constant(bound)])
    return [ast.If(test, _search(node[0], leaf_body, number, first_cold),
                   _search(node[1], leaf_body, number, first_cold))]


class _Plain(ast.NodeTransformer):
    """``x.__class__`` -> ``type(x)``; ``INT_MIN``/``INT_MAX`` -> their values (Cython compares a
    Python int with a literal in C)."""

    def visit_Name(self, node):
        if node.id in _LITERALS and isinstance(node.ctx, ast.Load):
            return ast.copy_location(ast.Constant(_LITERALS[node.id]), node)
        return node

    def visit_Attribute(self, node):
        self.generic_visit(node)
        if node.attr == "__class__" and isinstance(node.ctx, ast.Load):
            return ast.copy_location(ast.Call(_name("type"), [node.value], []), node)
        return node


def _replace_dispatch(func: ast.FunctionDef, search: list) -> None:
    for parent in ast.walk(func):
        for _, value in ast.iter_fields(parent):
            if isinstance(value, list):
                for k, st in enumerate(value):
                    if isinstance(st, ast.Expr) and isinstance(st.value, ast.Call) \
                            and isinstance(st.value.func, ast.Name) and st.value.func.id == "DISPATCH":
                        value[k:k + 1] = search
                        return
    raise DefinitionError("the loop skeleton has no DISPATCH()")


def _free(func: ast.FunctionDef) -> set:
    bound = set()
    for n in ast.walk(func):
        if isinstance(n, ast.Name) and isinstance(n.ctx, (ast.Store, ast.Del)):
            bound.add(n.id)
        elif isinstance(n, ast.ExceptHandler) and n.name:
            bound.add(n.name)
        elif isinstance(n, ast.arg):
            bound.add(n.arg)
        elif isinstance(n, (ast.FunctionDef, ast.Lambda)) and n is not func:
            if isinstance(n, ast.FunctionDef):
                bound.add(n.name)
        elif isinstance(n, ast.comprehension):
            bound |= {t.id for t in ast.walk(n.target) if isinstance(t, ast.Name)}
    loaded = {n.id for n in ast.walk(func) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
    return {n for n in loaded - bound if not hasattr(builtins, n)}


def _imports(module: ast.Module, names: set) -> tuple[list, set]:
    """The import lines that give `names`, as instructions.py imports them; and the names
    imported by ``from`` (C globals of the compiled loop)."""
    where: dict = {}
    for n in module.body:
        if isinstance(n, ast.ImportFrom) and n.level == 0 and n.module:
            for a in n.names:
                where[a.asname or a.name] = (n.module, a.name)
        elif isinstance(n, ast.Import):
            for a in n.names:
                where[a.asname or a.name.split(".")[0]] = (None, a.name)
    missing = sorted(x for x in names if x not in where)
    if missing:
        raise DefinitionError(f"the handlers read names instructions.py does not import: {missing}")
    by_module: dict = {}
    for x in sorted(names):
        mod, orig = where[x]
        by_module.setdefault(mod, []).append(orig if orig == x else f"{orig} as {x}")
    lines = [f"import {name}" for name in sorted(by_module.pop(None, []))]
    lines += [f"from {mod} import ({', '.join(items)})" for mod, items in sorted(by_module.items())]
    return lines, {x for x in names if where[x][0] is not None}


# ---------------------------------------------------------------------------- the three files
@dataclass
class Generated:
    loop: str
    table: str
    pxd: str


def generate(text: str | None = None) -> Generated:
    """The texts of loop.py, opcodes.py and loop.pxd for the definitions `text` (default: the
    file). Raises DefinitionError for a definition it cannot make a handler of."""
    defs = read(text)
    tree, number, first_cold = numbering(defs)
    by_name = {i.name: i for i in defs.insts}
    nx = 0

    def leaf(name):
        nonlocal nx
        if name == COLD_LEAF:
            return _expand([ast.Expr(_call(COLD_LEAF))], defs.inlines)
        h = _Handler(defs, by_name[name], cold=False)
        stmts = h.build()
        nx = max(nx, h.nx)
        return stmts

    func = copy.deepcopy(defs.skeleton)
    _replace_dispatch(func, _search(tree, leaf, number, first_cold))
    func.body = _expand(func.body, defs.inlines)
    func = _Plain().visit(func)
    ast.fix_missing_locations(func)

    colds = []
    for inst in defs.insts:
        if inst.cold:
            body = _Handler(defs, inst, cold=True).build()
            if "rt" in _loaded(body):
                body.insert(0, _stmt("rt = self.rt"))
            fn = ast.FunctionDef(f"_cold_{inst.name}", ast.arguments([], [ast.arg(a) for a in COLD_ARGS], None, [],
                                                                      [], None, []),
                                 [ast.Expr(ast.Constant(inst.doc))] + body, [], None, type_params=[])
            fn = _Plain().visit(fn)
            ast.fix_missing_locations(fn)
            colds.append(fn)

    free = _free(func) - {"COLD", "DISPATCH"}
    for fn in colds:
        free |= _free(fn)
    imports, c_globals = _imports(defs.module, free)
    table = ["None"] * len(number)
    for inst in defs.insts:
        if inst.cold:
            table[number[inst.name]] = f"_cold_{inst.name}"
    loop = ['"""GENERATED by `python -m interp.vm.gen_loop` from interp/vm/instructions.py (every',
            "instruction's definition and the loop's skeleton): the dispatch loop, a Huffman-shaped binary",
            "search over the hot instructions' handlers (interp/vm/gen_loop.py says how), and the cold",
            "instructions' functions. Do not edit: change instructions.py and regenerate;",
            "tests/vm/test_generated_loop.py fails when this file is stale. `make` compiles it with Cython",
            "(interp/vm/build.py; the C types are in loop.pxd); vm.py runs the compiled module only when",
            'its SOURCE is this file\'s."""',
            "# ruff: noqa",
            "",
            *imports,
            "",
            ""]
    for fn in colds:
        loop += [ast.unparse(fn), "", ""]
    loop += ["# the cold instructions' functions by opcode number (None: a hot one)",
             f"COLD = [{', '.join(table)}]", "", "", ast.unparse(func), "", ""]
    body = "\n".join(loop)
    loop_text = body + f"SOURCE = {hashlib.sha256(body.encode('utf-8')).hexdigest()!r}\n"
    return Generated(loop_text, _table(defs, number, first_cold), _pxd(defs, func, nx, c_globals | {"COLD"}))


def _effect_code(inst: Inst) -> tuple[str, str | None]:
    """(the stack effect as an int literal or a function's name, that function's text)."""
    if all(i.plain for i in inst.inputs + inst.outputs):
        return str(len(inst.outputs) - len(inst.inputs)), None

    def count(item: Item) -> str:
        n = f"({ast.unparse(item.size)})" if item.size is not None else "1"
        return f"({n} if {ast.unparse(item.cond)} else 0)" if item.cond is not None else n

    terms = [f"- {count(i)}" for i in inst.inputs] + [f"+ {count(o)}" for o in inst.outputs]
    expr = " ".join(terms).lstrip("+ ") if terms else "0"
    args = ", ".join(o for o, _ in inst.operands)
    return f"_effect_{inst.name}", f"def _effect_{inst.name}({args}):\n    return {expr}\n"


def _table(defs: Definitions, number: dict, first_cold: int) -> str:
    insts = sorted(defs.insts, key=lambda i: number[i.name])
    funcs, rows = [], []
    for i in insts:
        effect, fn = _effect_code(i)
        if fn:
            funcs.append(fn)
        parts = tuple(p.name for p in i.parts) or i.replaces
        names = tuple(o for o, _ in i.operands)
        kinds = "".join(k for _, k in i.operands)
        rows.append(f"    OpInfo({i.name!r}, {number[i.name]}, {kinds!r}, {names!r}, {effect}, "
                    f"{i.effect_text or _macro_text(i)!r}, {i.cold}, {parts!r}, {i.errors_from!r}, {i.doc!r}),")
    macros = {tuple(p.name for p in i.parts) or i.replaces: i.name for i in defs.insts if i.parts or i.replaces}
    out = ['"""GENERATED by `python -m interp.vm.gen_loop` from interp/vm/instructions.py: THE opcode table',
           "of the KRL VM (one source of truth, like CPython's generated opcode metadata). The compiler,",
           "the assembler and `krl asm`, the VM's linker and the tests read it. Do not edit: an",
           "instruction is defined in instructions.py (its operands, stack effect, frequency, handler);",
           "tests/vm/test_generated_loop.py fails when this file is stale.",
           "",
           "Numbers are the dispatch loop's (interp/vm/loop.py: hot instructions in the order of its",
           "search tree's leaves, then the cold ones). Operand kinds, one letter each, are listed in",
           'instructions.py (KINDS) and docs/architecture.md ("Opcodes: where to add one")."""',
           "",
           "from __future__ import annotations",
           "",
           "from dataclasses import dataclass",
           "",
           "",
           "@dataclass(frozen=True, slots=True)",
           "class OpInfo:",
           '    """One instruction: ``effect`` is the net change of the operand stack\'s depth, an int or a',
           "    function of the operand values (:func:`stack_effect`); ``stack`` the effect as written",
           "    (inputs -- outputs); ``parts`` a superinstruction's instructions in order (its operands are",
           '    theirs, concatenated); ``errors_from`` the one part of it that can raise, if declared."""',
           "    name: str",
           "    number: int",
           "    operands: str",
           "    names: tuple",
           "    effect: object",
           "    stack: str",
           "    cold: bool",
           "    parts: tuple",
           "    errors_from: int | None",
           "    doc: str",
           "",
           ""]
    out += [f + "\n" for f in funcs]
    out += ["", "OPS: list[OpInfo] = ["] + rows + ["]", "BY_NAME: dict[str, OpInfo] = {o.name: o for o in OPS}",
            f"FIRST_COLD = {first_cold}",
            f"KINDS = {dict(defs.kinds)!r}",
            f"OPERAND_KINDS = {''.join(defs.kinds)!r}",
            "# a superinstruction by its parts (the compiler's peephole pass)",
            "MACROS: dict[tuple, str] = {"]
    out += [f"    {k!r}: {v!r}," for k, v in macros.items()] + ["}", "", "# the opcode numbers"]
    out += [f"{i.name} = {number[i.name]}" for i in insts]
    out += ["", "",
            "def stack_effect(name: str, operands: list) -> int:",
            '    """The net stack effect of instruction `name` with the operand values `operands`."""',
            "    e = BY_NAME[name].effect",
            "    return e if type(e) is int else e(*operands)",
            "",
            "",
            "def size(op: int) -> int:",
            '    """Length of an instruction in code words (the opcode and its operands)."""',
            "    return 1 + len(OPS[op].operands)",
            "",
            "",
            "def instruction_starts(words: list) -> list[int]:",
            '    """The address of each instruction in the code words, in order."""',
            "    starts = []",
            "    pc = 0",
            "    while pc < len(words):",
            "        starts.append(pc)",
            "        pc += size(words[pc])",
            "    return starts",
            ""]
    return "\n".join(out)


def _macro_text(i: Inst) -> str:
    return ", ".join(x.name for x in i.inputs) + " -- " + ", ".join(x.name for x in i.outputs)


def _pxd(defs: Definitions, func: ast.FunctionDef, nx: int, c_globals: set) -> str:
    assigned = {n.id for n in ast.walk(func) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
    types = {"list": "list", "tuple": "tuple", "bytes": "bytes"}
    local = [(n, t) for n, t in defs.c_locals.items() if n in assigned]
    local += [(f"x{k}", "Py_ssize_t") for k in range(1, nx + 1)]
    decl = ", ".join(f"{n}={types.get(t, 'cython.' + t)}" for n, t in local)
    args = []
    for a in func.args.args:
        t = defs.c_args.get(a.arg, "object")
        args.append(f"{t} {a.arg}" + ("=*" if a in func.args.args[len(func.args.args) - len(func.args.defaults):] else ""))
    lines = ["# GENERATED by `python -m interp.vm.gen_loop` from interp/vm/instructions.py (C_LOCALS, C_ARGS):",
             "# the C types of the dispatch loop's locals for its Cython build (interp/vm/build.py; loop.py",
             "# itself stays plain Python, the fallback). x1, x2, ...: the integer operands; the module",
             "# names the handlers read are C globals (no dictionary lookup per use). Do not edit.",
             "import cython",
             "",
             f"@cython.locals({decl})",
             f"cpdef object run({', '.join(args)})",
             ""]
    names = sorted(c_globals)
    for k in range(0, len(names), 8):
        lines.append("cdef object " + ", ".join(names[k:k + 8]))
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        out = generate()
    except DefinitionError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    files = ((LOOP, out.loop), (TABLE, out.table), (PXD, out.pxd))
    if argv == ["--check"]:
        stale = [p.name for p, text in files if not p.exists() or p.read_text(encoding="utf-8") != text]
        if stale:
            print(f"stale: {', '.join(stale)}: run python -m interp.vm.gen_loop", file=sys.stderr)
            return 1
        return 0
    for p, text in files:
        p.write_text(text, encoding="utf-8")
        print(f"wrote {p}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
