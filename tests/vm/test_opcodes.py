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
