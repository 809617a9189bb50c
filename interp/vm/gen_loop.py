"""Generate interp/vm/loop.py, the VM's dispatch loop, from its source, ``VM.run`` in vm.py.

``VM.run`` is where every opcode's handler is written, once, as the branches of one chain
``if op == OP.X: ... elif op == OP.Y: ...`` in the order of their measured frequency. That
chain is runnable (``VM(rt, loop="source")``) but costs one test per opcode ahead of the
one that runs. This generator writes the same loop with the chain turned into a binary
search, ``if op < k:``, shaped as a Huffman tree over the opcodes with Zipf weights by rank
in the chain (weight 1/rank): the hottest opcode is found after two tests, the tenth after
six, the 100th after nine (at most ten). The generated loop dispatches on its own numbering
of the opcodes, the leaves of that tree from left to right (``DISPATCH[opcode number]``,
which ``vm.link`` writes into the executed form), every ``OP.NAME`` becomes that number,
the runtime functions of ``vm.HELPERS``, which the source calls as ``_name``, are module
names of the generated loop, ``x.__class__`` is spelled ``type(x)`` and ``push``/``pop``
``stack.append``/``stack.pop`` (as fast in CPython; C in Cython). ``run`` is a module-level
function, so that Cython can compile it with the C types of interp/vm/loop.pxd
(interp/vm/build.py); ``VM_SOURCE`` (the sha256 of vm.py) tells vm.py whether a compiled
module is current.

The output is a checked-in file, as CPython generates ``generated_cases.c.h`` from
``bytecodes.c``: nothing is compiled from rewritten source at import, and
tests/vm/test_generated_loop.py fails when loop.py is not what this generator makes from the
current vm.py. Regenerate with ``python -m interp.vm.gen_loop``.
"""

from __future__ import annotations

import ast
import builtins
import copy
import hashlib
import heapq
import itertools
import sys
from pathlib import Path

from interp.runtime.convert import INT_MAX, INT_MIN
from interp.vm import opcodes as OP

_LITERALS = {"INT_MIN": INT_MIN, "INT_MAX": INT_MAX}

HERE = Path(__file__).resolve().parent
SOURCE = HERE / "vm.py"
TARGET = HERE / "loop.py"


def _chain_ops(test) -> list | None:
    """The opcode names of a dispatch test ``op == OP.X [or op == OP.Y ...]``, else None."""
    parts = test.values if isinstance(test, ast.BoolOp) and isinstance(test.op, ast.Or) else [test]
    out = []
    for p in parts:
        if not (isinstance(p, ast.Compare) and isinstance(p.left, ast.Name) and p.left.id == "op"
                and len(p.ops) == 1 and isinstance(p.ops[0], ast.Eq)):
            return None
        c = p.comparators[0]
        if not (isinstance(c, ast.Attribute) and isinstance(c.value, ast.Name) and c.value.id == "OP"):
            return None
        out.append(c.attr)
    return out


def _huffman(weight: dict):
    """A Huffman tree over the opcode names: a name (leaf) or a pair (left, right)."""
    tie = itertools.count()
    heap = [(w, next(tie), name) for name, w in sorted(weight.items())]
    heapq.heapify(heap)
    while len(heap) > 1:
        wa, _, a = heapq.heappop(heap)
        wb, _, b = heapq.heappop(heap)
        heapq.heappush(heap, (wa + wb, next(tie), (a, b)))
    return heap[0][2]


def _leaves(node, out: list) -> None:
    if isinstance(node, tuple):
        _leaves(node[0], out)
        _leaves(node[1], out)
    else:
        out.append(node)


def _search(node, body_of: dict, number: dict, used: set):
    """The statements that dispatch ``op`` within the subtree ``node`` (``used``: the
    branch bodies already placed)."""
    if not isinstance(node, tuple):
        body = body_of[node]
        if id(body) in used:           # a branch of several opcodes: one copy per leaf
            return copy.deepcopy(body)
        used.add(id(body))
        return body
    right = []
    _leaves(node[1], right)
    lo = _search(node[0], body_of, number, used)
    hi = _search(node[1], body_of, number, used)
    test = ast.Compare(ast.Name("op", ast.Load()), [ast.Lt()], [ast.Constant(number[right[0]])])
    return [ast.If(test, lo, hi)]


def _replace(tree, old, new) -> None:
    for parent in ast.walk(tree):
        for _, value in ast.iter_fields(parent):
            if isinstance(value, list) and old in value:
                value[value.index(old)] = new
                return
    raise AssertionError("dispatch chain not found")


class _OpNumbers(ast.NodeTransformer):
    """``OP.NAME`` -> the loop's number of the opcode."""

    def __init__(self, number: dict) -> None:
        self.number = number

    def visit_Attribute(self, node):
        if isinstance(node.value, ast.Name) and node.value.id == "OP" and node.attr in self.number:
            return ast.copy_location(ast.Constant(self.number[node.attr]), node)
        return self.generic_visit(node)


def _free_names(func: ast.FunctionDef) -> set[str]:
    """Names the function reads that it does not bind (module globals and builtins)."""
    bound = set()
    for n in ast.walk(func):
        if isinstance(n, ast.Name) and isinstance(n.ctx, (ast.Store, ast.Del)):
            bound.add(n.id)
        elif isinstance(n, ast.ExceptHandler) and n.name:
            bound.add(n.name)
        elif isinstance(n, ast.arg):
            bound.add(n.arg)
        elif isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            bound.add(n.name)
        elif isinstance(n, (ast.Import, ast.ImportFrom)):
            bound.update((a.asname or a.name).split(".")[0] for a in n.names)
    return {n.id for n in ast.walk(func) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)} - bound


class _Plain(ast.NodeTransformer):
    """Spellings that run as fast in CPython and compile to C in Cython: ``x.__class__`` ->
    ``type(x)`` (a pointer comparison when compiled), ``push(v)`` / ``pop()`` (the source's
    bound-method aliases) -> ``stack.append(v)`` / ``stack.pop()``, the INT range's bounds
    ``INT_MIN`` / ``INT_MAX`` -> their literal values (Cython compares a Python int with a literal
    in C)."""

    def visit_Name(self, node):
        if node.id in _LITERALS and isinstance(node.ctx, ast.Load):
            return ast.copy_location(ast.Constant(_LITERALS[node.id]), node)
        return node

    def visit_Attribute(self, node):
        self.generic_visit(node)
        if node.attr == "__class__" and isinstance(node.ctx, ast.Load):
            return ast.copy_location(ast.Call(ast.Name("type", ast.Load()), [node.value], []), node)
        return node

    def visit_Call(self, node):
        self.generic_visit(node)
        if isinstance(node.func, ast.Name) and node.func.id in ("push", "pop"):
            method = "append" if node.func.id == "push" else "pop"
            node.func = ast.Attribute(ast.Name("stack", ast.Load()), method, ast.Load())
        return node


def _is_stack_alias(st) -> bool:
    """``push = stack.append`` / ``pop = stack.pop`` (the source loop's aliases)."""
    return (isinstance(st, ast.Assign) and len(st.targets) == 1 and isinstance(st.targets[0], ast.Name)
            and st.targets[0].id in ("push", "pop"))


def _imports(module: ast.Module, names: list[str]) -> list[str]:
    """The import statements that give the loop `names`, each from where vm.py imports it (so
    that the loop does not import vm.py, which imports the loop: no import cycle). Raises
    AssertionError for a name vm.py defines itself."""
    where: dict[str, tuple[str | None, str]] = {}
    for n in module.body:
        if isinstance(n, ast.ImportFrom) and n.level == 0 and n.module:
            for a in n.names:
                where[a.asname or a.name] = (n.module, a.name)
        elif isinstance(n, ast.Import):
            for a in n.names:
                where[a.asname or a.name.split(".")[0]] = (None, a.name)
    missing = [x for x in names if x not in where]
    if missing:
        raise AssertionError(f"the loop needs names vm.py does not import: {missing}")
    by_module: dict[str | None, list[str]] = {}
    for x in names:
        mod, orig = where[x]
        by_module.setdefault(mod, []).append(orig if orig == x else f"{orig} as {x}")
    lines = [f"import {name}" for name in sorted(by_module.pop(None, []))]
    lines += [f"from {mod} import ({', '.join(sorted(items))})" for mod, items in sorted(by_module.items())]
    return lines


def generate(source: str | None = None) -> str:
    """The text of loop.py for the vm.py source `source` (default: the file)."""
    text = SOURCE.read_text(encoding="utf-8") if source is None else source
    module = ast.parse(text)
    helpers = next(ast.literal_eval(n.value) for n in module.body if isinstance(n, ast.Assign)
                   and any(isinstance(t, ast.Name) and t.id == "HELPERS" for t in n.targets))
    cls = next(n for n in module.body if isinstance(n, ast.ClassDef) and n.name == "VM")
    func = next(n for n in cls.body if isinstance(n, ast.FunctionDef) and n.name == "run")
    func = copy.deepcopy(func)
    func.decorator_list = []
    chain = next(n for n in ast.walk(func) if isinstance(n, ast.If) and _chain_ops(n.test))
    branches = []
    node = chain
    while True:
        branches.append((_chain_ops(node.test), node.body))
        if len(node.orelse) == 1 and isinstance(node.orelse[0], ast.If) and _chain_ops(node.orelse[0].test):
            node = node.orelse[0]
            continue
        break
    body_of, weight = {}, {}
    for rank, (names, body) in enumerate(branches, 1):
        for name in names:
            body_of.setdefault(name, body)
            weight.setdefault(name, 1.0 / rank / len(names))
    missing = set(OP.BY_NAME) - set(body_of)
    if missing:
        raise AssertionError(f"opcodes without a branch in the dispatch loop: {sorted(missing)}")
    root = _huffman(weight)
    order: list = []
    _leaves(root, order)
    number = {name: i for i, name in enumerate(order)}
    search = _search(root, body_of, number, set())
    _replace(func, chain, search if isinstance(search, ast.If) else search[0])
    func = _OpNumbers(number).visit(func)
    func = _Plain().visit(func)
    for a in func.args.args:          # the C types are loop.pxd's
        a.annotation = None
    func.body = [st for st in func.body if not _is_stack_alias(st)]
    ast.fix_missing_locations(func)
    closure = {"_" + n for n in helpers}
    free = sorted(n for n in _free_names(func) if not hasattr(builtins, n) and n not in closure)
    imports = _imports(module, sorted(set(free) | set(helpers)))
    dispatch = [number[o.name] for o in OP.OPS]
    digest = hashlib.sha256(text.encode("utf-8")).hexdigest()
    head = ['"""GENERATED by `python -m interp.vm.gen_loop` from VM.run in interp/vm/vm.py (the source',
            "of every opcode handler): the same loop with its opcode chain turned into a Huffman-shaped",
            "binary search (interp/vm/gen_loop.py says how). Do not edit: change vm.py and regenerate;",
            "tests/vm/test_generated_loop.py fails when this file is stale. `make` compiles it with",
            "Cython (interp/vm/build.py; the C types of its locals are in loop.pxd) when a compiler is",
            'there; vm.py runs the compiled module only when its VM_SOURCE matches vm.py."""',
            "# ruff: noqa",
            "",
            *imports,
            "",
            "# sha256 of the vm.py this file was generated from",
            f"VM_SOURCE = {digest!r}",
            "",
            "# opcode number (interp/vm/opcodes.py) -> this loop's number of the opcode",
            f"DISPATCH = {dispatch!r}",
            "",
            "# the runtime functions of vm.HELPERS under the names the handlers call"]
    head += [f"_{n} = {n}" for n in helpers]
    return "\n".join(head) + "\n\n\n" + ast.unparse(func) + "\n"


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    out = generate()
    if argv == ["--check"]:
        if TARGET.read_text(encoding="utf-8") != out:
            print(f"{TARGET} is stale: run python -m interp.vm.gen_loop", file=sys.stderr)
            return 1
        return 0
    TARGET.write_text(out, encoding="utf-8")
    print(f"wrote {TARGET}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
