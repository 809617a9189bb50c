"""The instructions are defined once (interp/vm/instructions.py) and everything else is generated
from them (interp/vm/gen_loop.py): the opcode table, the dispatch loop, the stack effects. These
tests are the completeness check: every opcode of the table has exactly one handler in the loop
(a leaf of its search, or its cold function) and a stack effect, the compiler emits only opcodes
of the table, and the generator refuses a definition it cannot make a handler or an effect of."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from interp.asm import program_assembly
from interp.vm import gen_loop
from interp.vm import opcodes as O

from .differential import CASES, CORPUS
from interp.vm.assembler import Listing, parse_listings

COMPILER_SRC = (Path(O.__file__).parent / "compiler.py").read_text()


def test_numbers_are_dense_and_unique():
    assert [o.number for o in O.OPS] == list(range(len(O.OPS)))
    assert len(O.BY_NAME) == len(O.OPS)


def test_operand_kinds_are_known():
    for o in O.OPS:
        assert set(o.operands) <= set(O.OPERAND_KINDS), o
        assert len(o.names) == len(o.operands), o


def test_module_constants_match_the_table():
    for o in O.OPS:
        assert getattr(O, o.name) == o.number


def _dispatch(loop_text: str) -> dict:
    """{opcode number: its handler's statements} read from the text of a generated loop.py:
    the leaves of ``run``'s search ``if op < k:`` over the hot opcodes (one number each), and
    the entries of ``COLD`` (a function ``_cold_NAME`` each) for the cold ones."""
    tree = ast.parse(loop_text)
    run = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "run")
    search = next(n for n in ast.walk(run) if isinstance(n, ast.Assign)
                  and any(isinstance(t, ast.Name) and t.id == "op" for t in n.targets))
    # the statement list that holds `op = ops[ip]` holds the search right after it
    holder = next(body for n in ast.walk(run) for body in (getattr(n, "body", None),)
                  if isinstance(body, list) and search in body)
    top = holder[holder.index(search) + 1:]
    out: dict = {}

    def walk(stmts, lo, hi):
        if len(stmts) == 1 and isinstance(stmts[0], ast.If):
            t = stmts[0].test
            if isinstance(t, ast.Compare) and isinstance(t.left, ast.Name) and t.left.id == "op" \
                    and isinstance(t.ops[0], ast.Lt) and isinstance(t.comparators[0], ast.Constant):
                k = t.comparators[0].value
                assert lo < k < hi, (lo, k, hi)
                walk(stmts[0].body, lo, k)
                walk(stmts[0].orelse, k, hi)
                return
        if hi - lo == 1:
            out[lo] = stmts
        else:                   # the cold leaf: every number from FIRST_COLD on
            assert lo == O.FIRST_COLD and hi == len(O.OPS), (lo, hi)
            assert "cold[op]" in "".join(ast.unparse(s) for s in stmts)
            cold = next(n for n in tree.body if isinstance(n, ast.Assign) and n.targets[0].id == "COLD")
            for n, fn in enumerate(cold.value.elts[lo:hi], lo):
                assert isinstance(fn, ast.Name) and fn.id == f"_cold_{O.OPS[n].name}", (n, ast.unparse(fn))
                out[n] = next(f for f in tree.body if isinstance(f, ast.FunctionDef) and f.name == fn.id).body

    walk(top, 0, len(O.OPS))
    return out


def test_every_opcode_has_one_handler_in_the_loop():
    handlers = _dispatch(gen_loop.LOOP.read_text(encoding="utf-8"))
    assert sorted(handlers) == [o.number for o in O.OPS]
    for n, body in handlers.items():
        assert body, O.OPS[n].name
        assert (n >= O.FIRST_COLD) == O.OPS[n].cold, O.OPS[n].name


def test_the_handler_check_fails_without_a_handler():
    """The check above can fail: a loop whose leaf for one opcode is gone (its test folded into
    the one above) or whose cold table misses an entry is rejected."""
    text = gen_loop.LOOP.read_text(encoding="utf-8")
    cut = text.replace("_cold_SPL_SEG]", "None]")
    with pytest.raises(AssertionError):
        _dispatch(cut)
    # drop the first leaf: `if op < 1: <STMT_G> elif ...` becomes `if False: ... elif ...`
    cut = text.replace("if op < 1:", "if op < 0:", 1)
    with pytest.raises(AssertionError):
        _dispatch(cut)


def test_every_opcode_has_a_stack_effect():
    for o in O.OPS:
        assert "--" in o.stack or o.stack.strip() == "", o.name
        e = o.effect
        assert type(e) is int or (callable(e) and e.__code__.co_argcount == len(o.operands)), o.name


def test_size_is_one_plus_operands():
    for o in O.OPS:
        assert O.size(o.number) == 1 + len(o.operands)


def test_compiler_emits_only_table_opcodes():
    names = set(re.findall(r'emit\("([A-Z_0-9]+)"[,)]', COMPILER_SRC))
    names |= set(re.findall(r'"([A-Z][A-Z_0-9]+)"', COMPILER_SRC)) & set(O.BY_NAME)
    assert names and names <= set(O.BY_NAME)


def test_superinstructions_are_their_parts():
    """A superinstruction's operands are its parts', concatenated, and its stack effect their
    sum (for every one the peephole pass fuses)."""
    for parts, name in O.MACROS.items():
        info = O.BY_NAME[name]
        assert info.parts == parts
        assert info.operands == "".join(O.BY_NAME[p].operands for p in parts), name
        assert info.effect == sum(O.BY_NAME[p].effect for p in parts), name


DEFS = gen_loop.DEFINITIONS.read_text(encoding="utf-8")


@pytest.mark.parametrize("change, message", [
    # an operand without a kind
    (("def POP():", "def POP(x):"), "operand x has no kind"),
    # a stack item sized by a name that is not an operand
    (('"values[count] -- value"', '"values[n] -- value"'), "not operands"),
    # a stack effect without its separator
    (('@inst("value --")\ndef POP', '@inst("value")\ndef POP'), "inputs -- outputs"),
    # a superinstruction of an instruction that is not defined
    (("macro(TICK, JUMP,", "macro(TICK, JUMPX,"), "not an instruction defined above"),
    # an instruction without its one line of documentation
    (('"""push a constant"""', ""), "no docstring"),
    # a specialized instruction whose operands are not its sequence's
    (('replaces=("REF_LOCAL", "LOAD_FIELD")', 'replaces=("REF_LOCAL", "LOAD_FAST")'), "concatenated"),
])
def test_the_generator_refuses_an_incomplete_definition(change, message):
    old, new = change
    assert DEFS.count(old) == 1, old
    with pytest.raises(gen_loop.DefinitionError, match=message):
        gen_loop.generate(DEFS.replace(old, new))


# ---------------------------------------------------------------------------- stack effects
def effect(name: str, ops: list) -> int:
    """Stack effect of one instruction with its operands (the table's)."""
    return O.stack_effect(name, ops)


ENDS = {"JUMP", "RETURN", "RETURN_VAL", "END", "END_THUNK", "EXIT_SIGNAL", "GOTO_FAIL", "RAISE"}


def ends(name: str) -> bool:
    """The instruction never goes on at the next one (a superinstruction: its last part)."""
    parts = O.BY_NAME[name].parts
    return name in ENDS or (bool(parts) and ends(parts[-1]))


def check_stack(lst) -> None:
    """Depth never negative, equal on every path into an instruction, statements start at
    depth 0, thunks end with at most one value."""
    n = len(lst.instrs)
    depth: dict = {0: 0}
    entries = [0]
    # thunk entries: the targets of operands of kind h (THUNK: its stack starts with nargs values)
    for name, ops, _ in lst.instrs:
        kinds = O.BY_NAME[name].operands
        for k, v in zip(kinds, ops):
            if k == "h":        # a thunk's entry (operand kind h)
                pos = lst.labels[v]
                depth[pos] = ops[1] if name == "THUNK" else 0
                entries.append(pos)
    todo = list(entries)
    seen = set()
    while todo:
        i = todo.pop()
        if i in seen or i >= n:
            continue
        seen.add(i)
        name, ops, _ = lst.instrs[i]
        d = depth[i]
        if name in ("STMT", "STMT_G") and not any(i == e for e in entries):
            assert d == 0, (lst.name, i, name, d)
        nd = d + effect(name, ops)
        assert nd >= 0, (lst.name, i, name, d)
        if name == "END_THUNK":
            assert nd <= 1, (lst.name, i, nd)
        succ = []
        kinds = O.BY_NAME[name].operands
        for k, v in zip(kinds, ops):
            if k == "l":
                t = lst.labels[v]
                td = nd - 1 if name == "JUMP_IF_NONE" else nd
                succ.append((t, td))
        if not ends(name):
            succ.append((i + 1, nd))
        for t, td in succ:
            if t in depth:
                assert depth[t] == td, (lst.name, i, name, t, depth[t], td)
            else:
                depth[t] = td
            todo.append(t)


# the corpus's programs and mixed.src one xdist group: sent with the groups at the start, not
# among the suite's last single tests (in two whole runs of fresh clones, 2026-11-26, loads 5-14,
# the one test of all programs ran last: 12.8 and 17.5 s, the other workers done 3.7 and 2.7 s
# before it); each conformance case in its case's group (tests/conftest.py), so that the worker
# that runs its other tests loads its program once (the one test loaded all 111 again: 64
# checked workspaces in a whole make test of 2026-11-28)
STACK_PROGRAMS = [*(pytest.param(p, marks=pytest.mark.xdist_group("vm-stack-effects"), id=p.name)
                    for p in CORPUS + [Path(__file__).parent / "programs" / "mixed.src"]),
                  *(pytest.param(p, id=p.parent.name) for p in CASES)]


@pytest.mark.parametrize("program", STACK_PROGRAMS)
def test_stack_effects_of_compiled_programs(program):
    for lst in parse_listings(program_assembly(program)):
        check_stack(lst)
