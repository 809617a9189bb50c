"""The opcode table is the one source of truth: numbers, operands, the VM and the compiler."""

from __future__ import annotations

import re
from pathlib import Path

from interp.vm import opcodes as O

VM_SRC = (Path(O.__file__).parent / "vm.py").read_text()
COMPILER_SRC = (Path(O.__file__).parent / "compiler.py").read_text()


def test_numbers_are_dense_and_unique():
    assert [o.number for o in O.OPS] == list(range(len(O.OPS)))
    assert len(O.BY_NAME) == len(O.OPS)


def test_operand_kinds_are_known():
    for o in O.OPS:
        assert set(o.operands) <= set(O.OPERAND_KINDS), o


def test_module_constants_match_the_table():
    for o in O.OPS:
        assert getattr(O, o.name) == o.number


def test_every_opcode_is_dispatched_once_by_the_vm():
    used = re.findall(r"op == OP\.([A-Z_0-9]+)", VM_SRC)
    assert sorted(set(used)) == sorted(o.name for o in O.OPS)
    assert len(used) == len(set(used)) + 2     # LOAD/REF/STORE_GLOBAL share one branch


def test_size_is_one_plus_operands():
    for o in O.OPS:
        assert O.size(o.number) == 1 + len(o.operands)


def test_compiler_emits_only_table_opcodes():
    names = set(re.findall(r'emit\("([A-Z_0-9]+)"[,)]', COMPILER_SRC))
    names |= set(re.findall(r'"([A-Z][A-Z_0-9]+)"', COMPILER_SRC)) & set(O.BY_NAME)
    assert names <= set(O.BY_NAME)


# ---------------------------------------------------------------------------- stack effects
def effect(name: str, ops: list) -> int:
    """Stack effect of one instruction (the table's, or computed from the operands where the
    table says None)."""
    info = O.BY_NAME[name]
    if info.effect is not None:
        return info.effect
    if name in ("INDEX", "LOAD_INDEX"):
        return -ops[0]
    if name == "STORE_INDEX":
        return -ops[0] - 2
    if name == "AGG":
        return 1 - (len(ops[1].split(",")) if ops[1] else 0)
    if name == "CALL":
        return -ops[1] + (1 if ops[2] == "E" else 0)
    if name == "TRIG_PACK":
        return -ops[0]
    if name == "TRIGGER":
        return -3 - ("P" in ops[1])
    if name == "MOTION":
        return -1 - ("A" in ops[3]) - ("C" in ops[3]) - 2 * ops[4]
    if name == "SPL_SEG":
        return -1 - ("A" in ops[1]) - ("C" in ops[1]) - 2 * ops[2]
    if name == "SPLINE":
        return -2 * ops[2]
    if name == "INT_CTL":
        return -("P" in ops[1])
    if name == "ANOUT_ON":
        return -1 - ("L" in ops[1]) - ("H" in ops[1])
    raise AssertionError(f"no stack effect for {name}")


ENDS = {"JUMP", "RETURN", "RETURN_VAL", "END", "END_THUNK", "EXIT_SIGNAL", "GOTO_FAIL", "RAISE"}


def check_stack(lst) -> None:
    """Depth never negative, equal on every path into an instruction, statements start at
    depth 0, thunks end with at most one value."""
    from interp.vm.assembler import Listing  # noqa: F401

    n = len(lst.instrs)
    depth: dict = {0: 0}
    entries = [0]
    # thunk entries: targets of WAIT_FOR/INT_DECL/TRIGGER/CYCLIC_ASSIGN/ANOUT_ON/ANIN_ON
    for name, ops, _ in lst.instrs:
        kinds = O.BY_NAME[name].operands
        for k, v in zip(kinds, ops):
            if k == "l" and name in ("WAIT_FOR", "INT_DECL", "TRIGGER", "CYCLIC_ASSIGN", "ANOUT_ON", "ANIN_ON"):
                pos = lst.labels[v]
                depth[pos] = 1 if name == "TRIGGER" else 0
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
            if k == "l" and name not in ("WAIT_FOR", "INT_DECL", "TRIGGER", "CYCLIC_ASSIGN", "ANOUT_ON", "ANIN_ON"):
                t = lst.labels[v]
                td = nd - 1 if name == "JUMP_IF_NONE" else nd
                succ.append((t, td))
        if name not in ENDS:
            succ.append((i + 1, nd))
        for t, td in succ:
            if t in depth:
                assert depth[t] == td, (lst.name, i, name, t, depth[t], td)
            else:
                depth[t] = td
            todo.append(t)


def test_stack_effects_of_compiled_programs():
    from interp.vm.assembler import parse_listings
    from interp.asm import program_assembly

    from .differential import CASES, CORPUS

    here = Path(__file__).parent / "programs"
    for program in CORPUS + CASES + [here / "mixed.src"]:
        for lst in parse_listings(program_assembly(program)):
            check_stack(lst)
