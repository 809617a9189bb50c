"""Assembler and disassembler: text -> code -> text is the identity."""

from __future__ import annotations

import pytest

from interp.vm.assembler import AsmError, assemble, disassemble, parse_const, fmt_const
from interp.asm import program_assembly
from interp.bench import PROGRAM
from interp.realprograms import DEFAULT_CORPUS, find_backups, programs_of
from interp.run import make_runtime, run_spec
from interp.runtime.values import EnumValue
from interp.vm.compiler import compile_module

from .differential import CASES, CORPUS, FIRST_BACKUP

PROGRAMS = CORPUS + CASES[::4]


@pytest.mark.parametrize("program", PROGRAMS, ids=lambda p: p.parent.name if p.name == "program.src" else p.name)
def test_round_trip(program):
    text = program_assembly(program, all_modules=False)
    blocks = [line for line in text.splitlines() if line.startswith(".routine ")]
    codes = assemble(text)
    assert codes or "syntax errors" in text
    again = "".join(disassemble(c) for c in codes)
    body = "".join(line + "\n" for line in text.splitlines() if not line.startswith("; module") and line)
    assert again.replace("\n\n", "\n") == body.replace("\n\n", "\n")
    assert len(codes) == len(blocks)


HAND = """\
.routine DEMO DEF
.file ""
.locals I
.temps 3
    .at -
    ; 3
    STMT 3/S
    .at 3 G L2
    CONST 0
    STORE_LOCAL I
L1:
    .at -
    LOAD_LOCAL I
    ADD_CONST 1
    STORE_LOCAL I
    LOAD_MOD N
    LOAD_GLOBAL $OV_PRO
    BINOP :
    CONST "a \\"quoted\\" text"
    CONST #ENUM_V
    CONST 2.5
    CONST NONE
    CONST TRUE
    IF_NOT < L1
L2:
    END
.end
"""


def test_hand_written_text_round_trips():
    (code,) = assemble(HAND)
    assert disassemble(code) == HAND
    assert code.lnames == ["I"] and code.mnames == ["N"] and code.gnames == ["$OV_PRO"]
    assert code.infos[0].line == 3 and code.infos[0].stops and not code.infos[0].cond_stops
    assert len(code.regions) == len(code.words)


@pytest.mark.parametrize("bad", ["FOO 1", "CONST", "JUMP L9", "STORE_LOCAL X", "CONST 1x"])
def test_bad_text_is_an_error(bad):
    with pytest.raises(AsmError):
        assemble(".routine X DEF\n.file \"\"\n.locals I\n    " + bad + "\n    END\n.end\n")


@pytest.mark.parametrize("v", [0, -7, 2147483647, 1.5, -0.25, 1e30, "", "x y", '"', True, False, None])
def test_constants(v):
    assert parse_const(fmt_const(v)) == v
    assert type(parse_const(fmt_const(v))) is type(v)


def test_enum_constant():
    assert parse_const(fmt_const(EnumValue("c_dis"))) == EnumValue("C_DIS")


#: the corpus's four backups, by position in find_backups' order: make test round-trips the first
#: (HugoDanielson__ChinaMilling/KRC: 98 modules with routines, 275 routines, KUKA's system modules
#: among them), make nightly all four (a backup's load and round trip 0.5-1.2 s of CPU in a warm
#: process, the four 9.5 s in a worker of make test, 2026-11-27)
BACKUPS_IN_MAKE_TEST = (0,)


@pytest.mark.corpus
@pytest.mark.parametrize("position", [pytest.param(k, marks=FIRST_BACKUP if k in BACKUPS_IN_MAKE_TEST else pytest.mark.slow)
                                      for k in range(4)])
def test_every_routine_of_the_shared_corpus_compiles_and_round_trips(position):
    if not DEFAULT_CORPUS.is_dir():
        pytest.skip("../shared/krl-corpus absent")
    backups = [b for b in find_backups(DEFAULT_CORPUS) if programs_of(b)]
    assert len(backups) == 4, f"{len(backups)} backups with programs (4 expected: is ../shared/krl-corpus complete?)"
    n = 0
    rt, _ = make_runtime(run_spec(programs_of(backups[position])[0], mujoco=False, interp="vm", check=False))
    for m in rt.program.modules:            # every module of the backup, as loaded
        if m.syntax_errors or not m.routines:
            continue
        text = compile_module(m.routines.values())
        codes = assemble(text)
        assert "\n".join(disassemble(c) for c in codes) == text, m.name
        n += len(codes)
    assert n > 0


def test_benchmark_round_trips_with_its_superinstructions():
    """The compute benchmark uses the store-variable and register-style opcodes (operand
    kinds v, y, o, k); its assembly round-trips like any other."""
    text = program_assembly(PROGRAM, all_modules=False)
    codes = assemble(text)
    again = "".join(disassemble(c) for c in codes)
    body = "".join(line + "\n" for line in text.splitlines() if not line.startswith("; module") and line)
    assert again.replace("\n\n", "\n") == body.replace("\n\n", "\n")
    ops = {ln.split()[0] for ln in text.splitlines()
           if ln.startswith("    ") and not ln.strip().startswith((";", "."))}
    assert {"LOAD_FAST", "LOAD_FAST2", "STORE_FAST", "LOAD_ELEM1_V", "STORE_ELEM1_VC", "ADD_FAST", "LOAD_ELEM2_VV",
            "STORE_ELEM2", "FOR_NEXT_FAST", "ADDC_FAST", "SUBC_FAST", "IF_NOT_VV", "IF_NOT_VC",
            "LOAD_FIELD_L", "STORE_FIELD_L"} <= ops
    # the counter of `FOR i = 1 TO n` in SIEVE is an INT store variable: `i` appears as
    # written, and `count = count + 1` is one instruction with the INT type letter
    assert "    ADDC_FAST count 1 count I" in text.splitlines()
