"""The VM's fast paths against the tree interpreter, with and without a trace.

* Store variables (operand kind ``v``) and the inline int/float paths of the arithmetic
  and compare-jump opcodes: every case leaves its fast path (UNSET values, conversions,
  INT overflow, bad indices, BOOL/CHAR/ENUM operands) and must give the tree
  interpreter's values and error messages (programs/fast/fp_errors.src, fp_values.src).
* Quiet steps (Runtime.quiet_limit): a run without a trace counts most steps without the
  statement hook. Every conformance case, corpus program and mixed.src is run untraced on
  the VM and compared with a traced VM run and an untraced tree run; targeted programs
  (interrupts switched on mid-loop, CONTINUE, ON_ERROR_PROCEED in a loop, a submit
  program, the step limit inside a loop) check the same on all four runs.
* The generated dispatch loop: the executed form in its opcode numbering, and its line
  numbers.

Expected values are derived from the KRL reference (§3.9 conversions, §5.4 FOR, §5.9
CONTINUE, §5.16 interrupts, §5.19 ON_ERROR_PROCEED, §8.2 errors), not copied from a run.
"""

from __future__ import annotations

import ast
import math
import random
import re
import traceback
from dataclasses import dataclass
from pathlib import Path

import pytest
from click.testing import CliRunner

from interp.asm import asm, program_assembly
from interp.realprograms import submit_of
from interp.run import make_runtime, run_spec, RunSinks
from interp.runtime.errors import KrlRuntimeError
from interp.runtime.values import UNSET, Arr, EnumValue, Struct
from interp.vm import gen_loop, opcodes as OP
from interp.vm.compiler import compile_routine
from robot.trace import TraceWriter

from .differential import CASES, CORPUS, case_options, real_programs

HERE = Path(__file__).parent / "programs"
REPO = Path(__file__).resolve().parents[2]
FAST = HERE / "fast"
INT_MAX = 2 ** 31 - 1
INT_MIN = -(2 ** 31)
RUNS = (("tree", False), ("tree", True), ("vm", False), ("vm", True))


# ---------------------------------------------------------------------------- helpers
def plain(v):
    """A runtime value as plain Python: Struct -> dict, Arr -> list, EnumValue -> name."""
    if isinstance(v, Struct):
        return {k: plain(x) for k, x in v.f.items()}
    if isinstance(v, Arr):
        return [plain(x) for x in v.data]
    if isinstance(v, EnumValue):
        return "#" + v.name
    if v is UNSET:
        return "<unset>"
    if isinstance(v, float) and math.isnan(v):
        return "nan"
    return v


@dataclass
class Outcome:
    reason: str
    file: str | None
    line: int | None
    text: str
    number: int | None
    steps: int
    sim_time: float
    data: dict

    def key(self) -> tuple:
        return (self.reason, self.file, self.line, self.text, self.number, self.steps, self.sim_time)


def run_one(program: Path, interp: str, traced: bool, *, inputs=None, submit=(), max_steps=2_000_000,
            max_sim_time=30.0, set_vars: dict | None = None) -> Outcome:
    tw = TraceWriter(keep=True) if traced else None
    rt, _ = make_runtime(run_spec(program, inputs=inputs, max_sim_time=max_sim_time, max_steps=max_steps,
                         mujoco=False, submit=list(submit), interp=interp, check=False), RunSinks(trace=tw))
    mod = rt.program.module(program.stem)
    for name, value in (set_vars or {}).items():
        mod.data[name.upper()].set(value)
    res = rt.run()
    if tw is not None:
        tw.close()
    data = {}
    if mod is not None:
        for name, ref in mod.data.items():
            try:
                data[name] = plain(ref.get())
            except Exception as e:     # noqa: BLE001 - a value that cannot be read is compared as its error
                data[name] = f"<{type(e).__name__}: {e}>"
    err = res.error
    return Outcome(res.reason, res.file, res.line, res.text, err.number if err is not None else None,
                   res.steps, res.sim_time, data)


def run_all(program: Path, runs=RUNS, **kw) -> Outcome:
    """Run ``program`` on both interpreters, untraced and traced; all outcomes (result and
    the main module's data list) must be equal. Returns the first."""
    outs = [(interp, traced, run_one(program, interp, traced, **kw)) for interp, traced in runs]
    first = outs[0][2]
    for interp, traced, o in outs[1:]:
        where = f"{interp} {'traced' if traced else 'untraced'} vs {outs[0][0]} {'traced' if outs[0][1] else 'untraced'}"
        assert o.key() == first.key(), f"{program.name}: {where}\n {o.key()}\n {first.key()}"
        assert o.data == first.data, f"{program.name}: data list differs ({where})\n" + "\n".join(
            f" {k}: {o.data.get(k)!r} != {first.data.get(k)!r}" for k in first.data if o.data.get(k) != first.data.get(k))
    return first


def opcodes_of(program: Path) -> set:
    ops = set()
    for ln in program_assembly(program).splitlines():
        s = ln.strip()
        if s and not s.startswith((";", ".")) and not s.endswith(":"):
            ops.add(s.split()[0])
    return ops


def marker_line(program: Path, marker: str) -> int:
    """The source line that ends with the comment ``; <marker>``."""
    for n, ln in enumerate(program.read_text().splitlines(), 1):
        if re.search(rf";\s*{re.escape(marker)}\s*$", ln):
            return n
    raise AssertionError(f"no line marked {marker} in {program.name}")


# ---------------------------------------------------------------------------- a. slow paths: errors
ERRORS = FAST / "fp_errors.src"

VI = 1422     # "value invalid" (reference §8.2)


def _overflow(v: int) -> str:
    return f"INT overflow ({v} outside {INT_MIN}..{INT_MAX})"


# case -> (parts of the message, KSS number or None, expected RES)
ERROR_CASES = {
    1: (["value invalid", "i"], VI, 0),            # ADDC_FAST, unset source
    2: (["value invalid", "i"], VI, 0),            # LOAD_FAST, unset
    3: (["value invalid", "a[3]"], VI, 0),         # LOAD_ELEM1, unset element
    4: (["value invalid", "a[3]"], VI, 0),         # LOAD_ELEM1 (computed index), unset element
    5: (["value invalid", "a[3]"], VI, 0),         # LOAD_ELEM1_V, unset element
    6: ([_overflow(INT_MAX + 1)], None, 0),         # ADDC_FAST overflow
    7: ([_overflow(INT_MAX + 1)], None, 0),         # LOAD_FAST2 + ADD overflow
    8: ([_overflow(INT_MAX + 1)], None, 0),         # i = i + 1 overflow
    9: ([_overflow(2 * INT_MAX)], None, 0),         # MUL_CONST overflow
    10: ([_overflow(INT_MIN - 1)], None, 0),        # SUBC_FAST overflow
    11: (["cannot assign", "INT"], None, 0),        # BOOL into INT (STORE_FAST)
    12: (["array index", "a[0]", "1..3"], None, 0),   # index 0 (LOAD_ELEM1_V)
    13: (["array index", "a[4]", "1..3"], None, 0),   # past the end (STORE_ELEM1_V)
    14: (["array index", "a[4]", "1..3"], None, 0),   # past the end (STORE_ELEM1)
    15: (["array index", "INT"], None, 0),          # REAL index (LOAD_ELEM1_V)
    16: (["array index", "INT"], None, 0),          # REAL index (STORE_ELEM1_V)
    17: (["array index", "m[3,1]", "1..2"], None, 0),  # LOAD_ELEM2_VV, first index
    18: (["array index", "m[2,4]", "1..3"], None, 0),  # LOAD_ELEM2, second index
    19: (["value invalid", "m[1,2]"], VI, 0),      # LOAD_ELEM2, unset element (m[1,1] was set)
    20: (["array index", "m[1,4]", "1..3"], None, 0),  # STORE_ELEM2
    21: (["value invalid", "s[1]"], VI, 0),        # CHAR array, unset element
    22: (["array index", "s[5]", "1..4"], None, 0),   # CHAR array, past the end
    23: (["cannot compare"], None, 0),              # BOOL has no order (IF_NOT_VC)
    24: (["value invalid", "i"], VI, 0),           # IF_NOT_VC, unset
    25: (["value invalid", "k"], VI, 0),           # WHILE with IF_NOT_VV, unset
    26: (["cannot assign", "BOOL"], None, 0),       # INT into a BOOL element
    27: (["cannot assign", "BOOL"], None, 0),       # INT into BOOL (STORE_FAST)
    28: ([_overflow(INT_MAX + 1)], None, 2),        # FOR counter past 2147483647 (§5.4: end + 1)
    29: ([_overflow(INT_MIN - 1)], None, 2),        # FOR STEP -1 counter below -2147483648
    30: (["value invalid", "i"], VI, 0),           # IF_NOT_VV, unset first operand
    31: (["value invalid", "ba[1]"], VI, 0),       # BOOL array, unset element
    32: ([_overflow(INT_MAX + 1)], None, 0),        # REAL 2147483648.0 into INT
    33: (["value invalid", "m[2,1]"], VI, 0),      # LOAD_ELEM2_VV, unset element
    34: (["value invalid", "a[3]"], VI, 0),        # LOAD_ELEM1 + ADD
    35: (["value invalid", "q"], VI, 0),           # omitted :IN parameter (§2.3)
    36: (["value invalid", "u"], VI, 0),           # unset INT into REAL
    37: ([_overflow(10 + INT_MAX)], None, 0),       # ADD_CONST overflow
    38: ([_overflow(10 - INT_MAX - INT_MAX)], None, 0),   # SUB_CONST overflow
    39: ([_overflow(20 * INT_MAX)], None, 0),       # MUL overflow
    40: (["cannot compare"], None, 0),              # IF_NOT < INT vs BOOL
    41: (["value invalid", "i"], VI, 0),           # SUBC_FAST, unset
    42: (["value invalid", "i"], VI, 0),           # FAST_ADD_CONST, unset
    43: (["value invalid", "i"], VI, 0),           # FAST_SUB_CONST, unset
    44: (["value invalid", "i"], VI, 0),           # LOAD_FAST2, unset second
    45: (["value invalid", "i"], VI, 0),           # IF_NOT_VV, unset second
    46: (["cannot assign", "INT"], None, 0),        # BOOL into an INT element (STORE_ELEM2)
    47: (["array index", "INT"], None, 0),          # REAL index (LOAD_ELEM2)
    48: (["cannot compare"], None, 0),              # CHAR == BOOL
    49: (["enum", "order"], None, 0),               # ENUM has no order (§3.6)
    50: (["BOOL"], None, 0),                        # BOOL * INT (MUL_CONST)
    51: (["value invalid", "i"], VI, 0),           # STORE_ELEM1_V, unset index
    52: (["BOOL"], None, 0),                        # INT - BOOL (SUB)
    53: ([_overflow(INT_MAX + 1)], None, 2 ** 30),  # i = i * 2 in REPEAT: 2^30 then overflow
    54: (["cannot assign", "REAL"], None, 0),       # BOOL into REAL (STORE_FAST)
    55: (["value invalid", "a[3]"], VI, 0),        # IF_NOT_EV, unset element
    56: (["value invalid", "k"], VI, 0),           # IF_NOT_EV, unset right operand
    57: (["array index", "a[4]", "1..3"], None, 0),   # IF_NOT_EV, past the end
    58: (["cannot compare"], None, 0),              # IF_NOT_EV, INT == BOOL
    59: (["value invalid", "a[3]"], VI, 0),        # MOVE_ELEM1, unset source element
    60: ([_overflow(INT_MAX + 1)], None, 0),        # MOVE_ELEM1, target index overflows
    61: (["array index", "a[4]", "1..3"], None, 0),   # MOVE_ELEM1, target past the end
    62: (["cannot assign", "BOOL"], None, 0),       # MOVE_ELEM1, INT into a BOOL element
    63: ([_overflow(INT_MAX + 1)], None, 0),        # INT_MIN / -1 (BINOP /)
    64: (["value invalid", "i"], VI, 0),           # INT / unset INT
    65: (["division by zero"], None, 0),            # INT / 0
    66: (["array index", "a[4]", "1..3"], None, 0),   # past the end (STORE_ELEM1_V)
    67: (["value invalid", "i"], VI, 0),           # ADD_FAST, unset second operand
    68: (["cannot assign", "BOOL"], None, 0),       # ADD_FAST, INT into BOOL
    69: (["cannot assign", "BOOL"], None, 0),       # STORE_ELEM1_VC, INT into a BOOL element
}


def test_error_cases_cover_every_marker():
    text = ERRORS.read_text()
    assert sorted(int(n) for n in re.findall(r";\s*E(\d+)\s*$", text, re.M)) == sorted(ERROR_CASES)


@pytest.mark.parametrize("case", sorted(ERROR_CASES))
def test_slow_path_error(case):
    parts, number, res = ERROR_CASES[case]
    out = run_all(ERRORS, set_vars={"SEL": case}, max_steps=100_000, max_sim_time=10.0)
    assert out.reason == "error", out
    for p in parts:
        assert p.lower() in out.text.lower(), (p, out.text)
    assert out.number == number
    assert out.file is not None and Path(out.file).name.lower() == "fp_errors.src"
    line = marker_line(ERRORS, f"E{case}")
    if case in (28, 29):
        # the counter overflows at the end of the last iteration; the error lies in the
        # FOR statement (FOR .. ENDFOR), whose body ran twice
        src = ERRORS.read_text().splitlines()
        first = max(n for n in range(1, line) if src[n - 1].strip().upper().startswith("FOR "))
        assert first <= out.line <= line
    else:
        assert out.line == line
    assert out.data["DONE"] == 0
    assert out.data["RES"] == res
    assert out.data["SEL"] == case


# ---------------------------------------------------------------------------- a. slow paths: values
VALUES = FAST / "fp_values.src"


@pytest.fixture(scope="module")
def values():
    return run_all(VALUES, max_steps=100_000, max_sim_time=10.0)


def test_values_program_completes(values):
    assert values.reason == "completed"
    assert values.data["V_DONE"] == 1


def test_real_to_int_rounds_half_away(values):
    # §3.9: INT <- REAL nearest, ties away from zero: 5 + 10.6 = 15.6 -> 16, 2.5 -> 3,
    # -2.5 -> -3, 3.0 - 0.5 -> 3, 2.4 -> 2, -0.6 -> -1
    assert values.data["V_ROUND"] == [16, 3, -3, 3, 2, -1]


def test_int_to_real_is_exact(values):
    # §3.9: REAL <- INT exact; i = 5, x = -0.6
    got = values.data["V_REAL"]
    assert all(type(v) is float for v in got)
    assert got[:3] == [6.0, 5.0, 10.0] and got[4] == -2.0
    assert got[3] == pytest.approx(4.4) and got[5] == pytest.approx(5.6)


def test_char_as_code(values):
    # §3.4/§3.9: CHAR <-> INT by code: "A" = 65; 5 * 65 = 325; 325 - 260 = 65 -> "A";
    # s[1] = "K" = 75
    assert values.data["V_CHR"] == [66, 65, 325, 64, 76, 74, 150]
    assert values.data["V_S"] == ["K", "A", "A", "Z"]


def test_two_dimensional_arrays(values):
    assert values.data["V_M"] == [11, 12, 13, 21, 22, 23]
    assert values.data["V_MSUM"] == 11 + 12 + 13 + 21 + 22 + 23
    # rm[2,1] = 2 (INT into a REAL element); rm[1,2] + rm[2,2] = 7.0 + 2.5; INT k = 2.5 -> 3
    assert values.data["V_RM"] == [2.0, 9.5, 3.0]


def test_elements_with_conversion(values):
    # a[1] = 2.5 -> 3, a[2] = -2.5 -> -3, ra[1] = 7 -> 7.0, a[3] = 3 + 7.0 -> 10, 7.0 * 2 -> 14
    assert values.data["V_ELEM"] == [3, -3, 10, 14]


def test_for_loops(values):
    # §5.4: STEP -2 from 10 to 1: 10+8+6+4+2, counter ends at 0 (first value failing the
    # test); STEP 3 from 1 to 10: 4 passes, counter 13; 5 TO 4: no pass, counter = start
    assert values.data["V_FOR"] == [30, 0, 4, 13, 0, 5]
    # a REAL counter 0.5 TO 2.0 STEP 0.5: 0.5 + 1.0 + 1.5 + 2.0, ends at 2.5
    assert values.data["V_RFOR"] == [5.0, 2.5]


def test_division(values):
    # §4.1: INT / INT is an INT division that truncates toward zero; a REAL operand divides
    assert values.data["V_DIV"] == [3, -3, -3, 3, 0]
    assert values.data["V_RDIV"] == [3.5, 3.5, -1.75]


def test_element_compare_and_move(values):
    # a = [3, 1, 2]: 3 > 2, so a[2] = a[1]; then a[2] = 3 >= 4 is false; ra[3] = a[2] as REAL
    assert values.data["V_SHIFT"] == [3, 3, 2]
    assert values.data["V_RSHIFT"] == 3.0


def test_comparisons_of_bool_char_enum(values):
    assert values.data["V_CMP"] == [
        False,   # TRUE == FALSE
        True,    # TRUE <> FALSE
        True,    # b1 == TRUE
        True,    # "a" < "b"
        True,    # "a" (97) > "Z" (90)
        True,    # s[1] == "K"
        True,    # "a" - 1 == 96
        True,    # #green == #green
        True,    # #green <> #blue
        True,    # 2 == 2.0
        False,   # 2 >= 2.5
        False,   # "b" <= "a"
        True,    # s[1] ("K") >= "A"
        True,    # "a" + 0 < "b" + 0
        True,    # TRUE <> ("a" == "b")
        True,    # 2.0 > 2 - 1
        True,    # "K" (75) <= "a" (97)
        False,   # 75 > 76
    ]
    # WHILE on a BOOL (3 passes), on a CHAR ("a", "c": 2 passes), on an ENUM (red, green)
    assert values.data["V_WHILE"] == [3, 2, 2]


def test_on_error_proceed_around_fast_statements(values):
    # §5.19: the failing statement is aborted ($ERR set), execution goes on after it
    err = values.data["V_ERR"]
    assert err[0] == 1422                    # k = u + 1, u unset
    assert err[1] > 0 and err[2] > 0         # index out of range; INT overflow
    assert err[3] == 2                       # a[4], a[5] out of range in FOR i = 1 TO 5
    assert err[4] == 1422                    # omitted :IN parameter read in the callee
    assert err[5] == 0                       # after ERR_CLEAR
    # k kept its value (7, 2147483647); the function took its $ERR branch: 3 + 100
    assert values.data["V_AFTER"] == [7, INT_MAX, 103]


FAST_OPS = {"LOAD_FAST", "LOAD_FAST2", "FAST_ADD_CONST", "FAST_SUB_CONST", "STORE_FAST", "LOAD_ELEM1",
            "LOAD_ELEM2", "STORE_ELEM1", "STORE_ELEM2", "LOAD_ELEM1_V", "STORE_ELEM1_V", "LOAD_ELEM2_VV",
            "FOR_NEXT_FAST", "ADDC_FAST", "SUBC_FAST", "IF_NOT_VV", "IF_NOT_VC", "IF_NOT_EV", "MOVE_ELEM1",
            "ADD_FAST", "STORE_ELEM1_VC"}
INLINE_OPS = {"ADD", "SUB", "MUL", "ADD_CONST", "SUB_CONST", "MUL_CONST", "IF_NOT"}


def test_programs_use_the_fast_opcodes():
    ops_err = opcodes_of(ERRORS)
    ops_val = opcodes_of(VALUES)
    # the error cases alone reach every store-variable opcode but the FAST_*_CONST pair on
    # its own, and both programs together every inline arithmetic/compare opcode
    assert FAST_OPS - {"FAST_ADD_CONST", "FAST_SUB_CONST"} <= ops_err, sorted(FAST_OPS - ops_err)
    assert FAST_OPS <= ops_val | ops_err, sorted(FAST_OPS - ops_val - ops_err)
    assert INLINE_OPS <= ops_val | ops_err, sorted(INLINE_OPS - ops_val - ops_err)
    assert {"FOR_NEXT_FAST", "STORE_ELEM2", "LOAD_ELEM2_VV", "IF_NOT_VV", "IF_NOT_VC", "STORE_ELEM1_V"} <= ops_val
    # IF_NOT (COMPARE, JUMP_IF_FALSE) is reached with each of the six comparisons (its operand)
    cmps = set()
    for program in (ERRORS, VALUES):
        cmps |= set(re.findall(r"^\s+IF_NOT (\S+) ", program_assembly(program), re.M))
    assert cmps == {"<", "<=", ">", ">=", "==", "<>"}, sorted(cmps)


def test_krl_asm_command_lists_fast_opcodes():
    res = CliRunner().invoke(asm, [str(VALUES)])
    assert res.exit_code == 0, res.output
    assert re.search(r"^\s+ADDC_FAST i 10\.6 k I$", res.output, re.M), "k = i + 10.6"
    assert re.search(r"^\s+FOR_NEXT_FAST i \d+ ", res.output, re.M)


# ---------------------------------------------------------------------------- b. quiet steps: sweep
MIXED = HERE / "mixed.src"


def _sweep_programs():
    out = [pytest.param(p, case_options(p), id=p.parent.name) for p in CASES]
    out += [pytest.param(p, {}, id=p.name) for p in CORPUS]
    out.append(pytest.param(MIXED, {"inputs": HERE / "mixed.yaml"}, id="mixed.src"))
    return out


SWEEP = _sweep_programs()
QUIET_RUNS = (("vm", False), ("vm", True), ("tree", False))


@pytest.mark.parametrize(("program", "options"), SWEEP)
def test_quiet_steps_sweep(program, options):
    """Untraced VM (quiet steps) = traced VM = untraced tree: result and data list."""
    kw = dict(options)
    kw.setdefault("max_sim_time", 30.0)
    run_all(program, runs=QUIET_RUNS, **kw)


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    """The corpus's real programs are listed only when the slow sweep is selected (``make
    nightly``; listing them reads every candidate module: 2 s of CPU in each pytest worker)."""
    if metafunc.definition.name == "test_quiet_steps_real_programs":
        progs = real_programs() if "not slow" not in metafunc.config.getoption("markexpr") else []
        metafunc.parametrize("program", progs, ids=lambda p: "/".join(p.parts[-3:]))


@pytest.mark.slow
@pytest.mark.corpus
def test_quiet_steps_real_programs(program):
    run_all(program, runs=QUIET_RUNS, max_sim_time=20.0, max_steps=100_000, submit=submit_of(program))


@pytest.mark.slow
@pytest.mark.parametrize("max_steps", [1, 2, 5, 37, 999, 1000, 1001, 1999, 2000, 2001])
@pytest.mark.parametrize(("program", "options"), SWEEP)
def test_quiet_steps_sweep_step_limits(program, options, max_steps):
    """The step limit reached at many points of every program: same step, same line."""
    kw = dict(options)
    kw.setdefault("max_sim_time", 30.0)
    run_all(program, runs=QUIET_RUNS, max_steps=max_steps, **kw)


# ---------------------------------------------------------------------------- c. quiet steps: targeted
def test_interrupt_declared_and_switched_on_mid_loop():
    prog = FAST / "fp_irq.src"
    out = run_all(prog, inputs=FAST / "fp_irq.yaml", max_sim_time=30.0)
    assert out.reason == "completed"
    d = out.data
    assert d["TOTAL"] == 4000 and d["CUR"] == 4000
    # §5.16: $FLAG[7] set by the statement at i = 1000 fires interrupt 5 (ON since 800)
    # at the next statement boundary, within the same pass (the handler resets the flag);
    # OFF at 3500, ON again at 3800, the flag set again at 3900: the second hit sees 3900
    assert d["FLAG_HITS"] == 2 and d["FLAG_AT"] == 3900
    # $IN[3] rises at t = 0.25 s, after ON 6 at i = 1500 (about 10 steps per pass, 1000
    # steps per 12 ms cycle: i = 1500 is at about 0.18 s, i = 3500 at about 0.42 s); the
    # handler switches interrupt 6 OFF
    assert d["IN_HITS"] == 1 and 1500 < d["IN_AT"] < 3500


@pytest.mark.parametrize("max_steps", [10_000, 15_001, 30_000])
def test_interrupt_program_with_step_limit(max_steps):
    out = run_all(FAST / "fp_irq.src", inputs=FAST / "fp_irq.yaml", max_sim_time=30.0, max_steps=max_steps)
    assert out.reason == "max_steps"
    assert out.steps == max_steps + 1
    assert out.text == f"step limit {max_steps} reached"


def test_continue_in_a_long_loop():
    out = run_all(FAST / "fp_continue.src", max_sim_time=30.0)
    assert out.reason == "completed"
    d = out.data
    assert d["N_DONE"] == 4000
    # §5.9: with CONTINUE the output (and the timer read) runs when the advance run
    # reaches it, while the robot still moves (pass 1000: a few IPO cycles after the
    # start); $OUT[3] without CONTINUE stops the advance run until the PTP has ended
    assert 0 <= d["T_CONT"] < 150
    assert d["T_STOP"] >= 200 and d["T_STOP"] > d["T_CONT"] + 100


def test_on_error_proceed_in_a_long_loop():
    out = run_all(FAST / "fp_proceed.src", max_sim_time=30.0)
    assert out.reason == "completed"
    d = out.data
    # j runs 1..12 100 times: 1,3,5,7,9 set (a[j] + 1 = 2+4+6+8+10), 2,4,6,8,10 unset
    # (value invalid, 1422), 11, 12 outside a[10]
    assert (d["N_OK"], d["N_INVALID"], d["N_INDEX"]) == (500, 500, 200)
    assert d["SUM"] == 100 * 30


def test_submit_program_alongside():
    out = run_all(FAST / "fp_submit.src", submit=[FAST / "fp_sub.sub"], max_sim_time=30.0)
    assert out.reason == "completed"
    d = out.data
    assert d["N_DONE"] == 8000
    # the submit loop saw $FLAG[3] (set by the robot at i = 5000) and answered with $OUT[7]
    assert d["SUB_SEEN"] > 1 and d["SUB_PASSES"] >= d["SUB_SEEN"]


MAXSTEPS = FAST / "fp_maxsteps.src"


@pytest.mark.parametrize("max_steps", [998, 999, 1000, 1001, 1002, 10_000, 10_001, 20_001])
@pytest.mark.parametrize("sel", [1, 2, 3, 4])
def test_step_limit_inside_a_loop(sel, max_steps):
    out = run_all(MAXSTEPS, set_vars={"SEL": sel}, max_steps=max_steps, max_sim_time=600.0)
    assert out.reason == "max_steps"
    assert out.text == f"step limit {max_steps} reached"
    # the step that exceeds the limit is the (max_steps + 1)-th: a body statement or a
    # loop iteration; either way the last statement that ran is the body's
    assert out.steps == max_steps + 1
    assert out.line == marker_line(MAXSTEPS, f"B{sel}")
    if sel == 1:
        # steps: SWITCH 1, FOR 2, first iteration 3, body k at 2 + 2k, iteration k + 1 at
        # 3 + 2k; the body that would run at step max_steps + 1 has not run
        m = max_steps
        assert out.data["COUNT"] == ((m - 3) // 2 if m % 2 else (m - 2) // 2)


# ---------------------------------------------------------------------------- d. dispatch
def test_linked_code_uses_the_loop_numbering():
    """The executed form is the listing, instruction for instruction, each opcode in the
    loop's numbering (what `krl asm` prints is what runs)."""
    rt, vm = make_runtime(run_spec(VALUES, mujoco=False, interp="vm", check=False))
    rt.run()
    seen = set()
    for code in vm.codes.values():
        lst = compile_routine(code.routine)
        assert len(code.prog) == len(lst.instrs)
        assert code.ops == bytes(ins[0] for ins in code.prog)
        for ins, (name, _ops, _reg) in zip(code.prog, lst.instrs):
            assert ins[0] == OP.BY_NAME[name].number
            seen.add(name)
    assert FAST_OPS - {"FAST_ADD_CONST", "FAST_SUB_CONST"} <= seen


def _loop_lines():
    """(path of interp/vm/loop.py, first line, last line) of the generated ``run`` (the
    compiled loop's frames name loop.py's lines too: Cython keeps them)."""
    path = gen_loop.LOOP.resolve()
    tree = ast.parse(path.read_text())
    run = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "run")
    return path, run.lineno, run.end_lineno


def test_error_traceback_points_into_the_loop():
    """A run-time error raised by a slow path inside the loop: its traceback has a frame
    in interp/vm/loop.py on a line of the generated loop, a real source line."""
    path, lo, hi = _loop_lines()
    rt, _ = make_runtime(run_spec(ERRORS, mujoco=False, interp="vm", max_steps=10_000, check=False))
    rt.program.module("fp_errors").data["SEL"].set(6)      # k = big + 1: INT overflow
    res = rt.run()
    assert res.reason == "error"
    err = res.error
    assert isinstance(err, KrlRuntimeError) and err.__traceback__ is not None
    frames = traceback.extract_tb(err.__traceback__)
    # the compiled loop names its file relative to the repository and its function by its
    # qualified name
    inside = [f for f in frames if (REPO / f.filename).resolve() == path
              and f.name in ("run", "interp.vm.loop.run")]
    assert inside, [(f.filename, f.name, f.lineno) for f in frames]
    for f in inside:
        assert lo <= f.lineno <= hi, (f.lineno, lo, hi)
        assert f.line and f.line.strip(), f     # a real source line of the loop
    # the innermost frame of the loop is the line of ADDC_FAST's slow path, which calls
    # the runtime's add (the overflow is raised there)
    assert "_add(" in inside[-1].line, inside[-1].line


def test_trigger_and_brake_resume_during_a_compute_loop():
    out = run_all(FAST / "fp_trigger.src", max_sim_time=30.0)
    assert out.reason == "completed"
    d = out.data
    # the TRIGGER action (start of the PTP + 20 ms) runs once while the advance run is in
    # the loop (CONTINUE before INTERRUPT ON: no advance-run stop); the loop sees it,
    # sets $FLAG[9]; interrupt 9 fires at the next statement of the same pass, BRAKE,
    # RESUME ends worker() (§5.17): the main routine goes on with CUR unchanged
    assert d["TRIG_N"] == 1
    assert 1 < d["TRIG_AT"] < 30000
    assert d["IRQ_AT"] == d["TRIG_AT"] == d["AFTER_RESUME"] == d["CUR"]


def count_hooks(vm) -> list:
    """Count the VM's calls of the full statement and loop hooks (Runtime.before_statement,
    loop_tick) from now on: the one-element list returned holds the count."""
    calls = [0]
    before, tick, take, quiet, *call_protocol = vm.hooks    # (run_routine, exec_routine)

    def counted(fn):
        def hook(*a):
            calls[0] += 1
            return fn(*a)
        return hook

    vm.hooks = (counted(before), counted(tick), take, quiet, *call_protocol)
    return calls


@pytest.mark.parametrize("traced", [False, True])
def test_quiet_path_is_taken_only_without_a_trace(traced):
    """The sweeps above compare something: untraced, most steps skip the statement hooks
    (one full hook per time slice here); traced, every step takes them."""
    tw = TraceWriter(keep=True) if traced else None
    rt, vm = make_runtime(run_spec(MAXSTEPS, mujoco=False, interp="vm", max_steps=20_000, max_sim_time=600.0,
                          check=False), RunSinks(trace=tw))
    rt.program.module("fp_maxsteps").data["SEL"].set(2)
    calls = count_hooks(vm)
    res = rt.run()
    assert res.reason == "max_steps" and res.steps == 20_001
    if traced:
        assert calls[0] == res.steps
    else:
        assert calls[0] < res.steps // 100, calls[0]


# ---------------------------------------------------------------------------- random programs
# Straight-line code over store variables (INT, REAL, BOOL, CHAR scalars, 1-D and 2-D
# arrays, some elements unset) mixing types, out-of-range and REAL indices, overflowing
# constants; most statements under ON_ERROR_PROCEED so one run passes many slow paths.
_NAMES = {"I": ["i", "j", "k"], "R": ["x", "y"], "B": ["b"], "C": ["c"]}
_CONSTS = ["0", "1", "2", "-1", "3", "2147483647", "-2147483647", "1.5", "2.5", "-0.5", "TRUE", "FALSE",
           '"A"', '"z"']


class _Gen:
    def __init__(self, seed: int) -> None:
        self.r = random.Random(seed)

    def scalar(self) -> str:
        return self.r.choice(sum(_NAMES.values(), []))

    def index(self, extra) -> str:
        return self.r.choice(_NAMES["I"] + extra)

    def atom(self) -> str:
        p = self.r.random()
        if p < 0.45:
            return self.scalar()
        if p < 0.65:
            return self.r.choice(["a", "a", "ra", "s"]) + f"[{self.index(['1', '2', '3', '4', '0', 'x'])}]"
        if p < 0.75:
            return f"m[{self.index(['1', '2'])}, {self.index(['1', '3', '4'])}]"
        return self.r.choice(_CONSTS)

    def expr(self, depth: int = 0) -> str:
        if depth > 1 or self.r.random() < 0.4:
            return self.atom()
        return f"{self.expr(depth + 1)} {self.r.choice('+-*+-')} {self.expr(depth + 1)}"

    def cond(self) -> str:
        return f"{self.expr(1)} {self.r.choice(['<', '<=', '>', '>=', '==', '<>'])} {self.expr(1)}"

    def target(self) -> str:
        p = self.r.random()
        if p < 0.6:
            return self.scalar()
        if p < 0.85:
            return self.r.choice(["a", "ra", "s"]) + f"[{self.index(['1', '2', '3', '4'])}]"
        return f"m[{self.index(['1', '2'])}, {self.index(['1', '3'])}]"

    def block(self, n: int, depth: int = 0) -> list:
        out = []
        ind = "  " * (depth + 1)
        for _ in range(n):
            p = self.r.random()
            if p < 0.05 and depth < 2:
                out += [f"{ind}IF {self.cond()} THEN", *self.block(2, depth + 1), f"{ind}ENDIF"]
            elif p < 0.1 and depth < 2:
                v = self.r.choice(_NAMES["I"])
                start = self.r.choice(["1", "3", "-2", "2147483645"])
                end = self.r.choice(["3", "1", "2147483647", "5"])
                step = self.r.choice(["1", "2", "-1", "-2"])
                out += [f"{ind}FOR {v} = {start} TO {end} STEP {step}", *self.block(2, depth + 1), f"{ind}ENDFOR"]
            elif p < 0.97:
                out += [f"{ind}ON_ERROR_PROCEED", f"{ind}{self.target()} = {self.expr()}",
                        f"{ind}ERRS = ERRS + $ERR.NUMBER", f"{ind}ERR_CLEAR($ERR)"]
            else:
                out.append(f"{ind}{self.target()} = {self.expr()}")
        return out


def _random_program(tmp: Path, seed: int) -> Path:
    g = _Gen(seed)
    init = ["i = 1", "j = 2", "x = 0.5", "b = TRUE", 'c = "B"', "k = 3", "y = -1.5", "a[1] = 5", "a[2] = -7",
            "ra[1] = 0.25", "ra[3] = 4.0", 's[1] = "q"', 's[2] = "R"', "m[1, 1] = 1", "m[2, 3] = 9", "m[1, 3] = 4"]
    outs = ["OI = i", "OJ = j", "OK = k", "OX = x", "OY = y", "OB = b", "OC = c"]
    src = ["DEF fz()", "  DECL INT i, j, k, a[3], m[2,3]", "  DECL REAL x, y, ra[3]", "  DECL BOOL b",
           "  DECL CHAR c, s[4]"]
    src += ["  " + s for s in init] + g.block(40)
    for s in outs:
        src += ["  ON_ERROR_PROCEED", "  " + s]
    src += ["  FOR i = 1 TO 3", "    ON_ERROR_PROCEED", "    OA[i] = a[i]", "    ON_ERROR_PROCEED",
            "    ORA[i] = ra[i]", "  ENDFOR", "END"]
    (tmp / "fz.src").write_text("\n".join(src) + "\n")
    (tmp / "fz.dat").write_text("DEFDAT fz\n  DECL INT ERRS = 0\n  DECL INT OI, OJ, OK, OA[3]\n"
                                "  DECL REAL OX, OY, ORA[3]\n  DECL BOOL OB\n  DECL CHAR OC\nENDDAT\n")
    return tmp / "fz.src"


#: the seeds of make test's random programs; make nightly runs the rest up to 400
#: (test_random_programs_many). 12 until 2026-11-28: seeds 6-11 were 2.1 of the 3.5 s of CPU
#: the twelve took in that day's profile of make test (seeds 6, 8 and 9 the dearest)
RANDOM_SEEDS_IN_MAKE_TEST = 6


@pytest.mark.parametrize("seed", range(RANDOM_SEEDS_IN_MAKE_TEST))
def test_random_programs(tmp_path, seed):
    run_all(_random_program(tmp_path, seed), max_steps=5000, max_sim_time=5.0)


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(RANDOM_SEEDS_IN_MAKE_TEST, 400))
def test_random_programs_many(tmp_path, seed):
    run_all(_random_program(tmp_path, seed), max_steps=5000, max_sim_time=5.0)


# ---------------------------------------------------------------------------- ON_ERROR_PROCEED before a loop
# §5.19: ON_ERROR_PROCEED covers the *next statement*: if it fails, it is aborted, $ERR is
# filled and execution goes on after it. Every statement takes the flag; for a loop the
# covered part is its header: FOR's counter, limits and first assignment, WHILE's first
# evaluation of the condition (an error there skips the loop); RETURN's value (after an
# error the next statement runs). Decision recorded in docs/architecture.md, "Choices on
# the reference's open points". Both interpreters agree (the four runs are equal).
def test_on_error_proceed_before_if():
    out = run_all(FAST / "fp_oep_if.src", max_steps=1000, max_sim_time=5.0)
    assert out.reason == "completed"
    assert out.data["R1"] == 1422 and out.data["R2"] == -1     # neither branch ran


def test_on_error_proceed_before_while_condition():
    out = run_all(FAST / "fp_oep_while.src", max_steps=1000, max_sim_time=5.0)
    assert out.reason == "completed", (out.reason, out.line, out.text)
    assert out.data["R1"] == 1422


def test_on_error_proceed_before_for_limits():
    out = run_all(FAST / "fp_oep_for.src", max_steps=1000, max_sim_time=5.0)
    assert out.reason == "completed", (out.reason, out.line, out.text)
    assert out.data["R1"] == 1422


def test_on_error_proceed_before_while_does_not_cover_the_body():
    prog = FAST / "fp_oep_carry.src"
    out = run_all(prog, max_steps=1000, max_sim_time=5.0)
    assert out.reason == "error", (out.reason, out.data)
    assert out.text.startswith("value invalid") and out.number == 1422
    assert out.line == 8
    assert out.data["R1"] == -1


def test_on_error_proceed_before_return_covers_its_value():
    out = run_all(FAST / "fp_oep_return.src", max_steps=1000, max_sim_time=5.0)
    assert out.reason == "completed", (out.reason, out.line, out.text)
    assert out.data["R1"] == 1422      # $ERR from the failed RETURN u + 1
    assert out.data["R2"] == 7         # the function went on to RETURN 7


def test_on_error_proceed_before_repeat_is_taken_by_it():
    prog = FAST / "fp_oep_repeat.src"
    out = run_all(prog, max_steps=1000, max_sim_time=5.0)
    assert out.reason == "error", (out.reason, out.data)
    assert out.number == 1422 and out.line == marker_line(prog, "E")
    assert out.data["R1"] == -1


# ---------------------------------------------------------------------------- issue 39: UNOP, conditions, fields
UNOP = FAST / "fp_unop.src"

# case -> parts of the message (reference §4.1 operators, §3.9 conversions, §8.2)
UNOP_ERRORS = {
    1: ["NOT needs a BOOL operand"],          # NOT on a REAL: out of UNOP's inline path
    2: ["not BOOL"],                          # IF on an INT: JUMP_IF_FALSE's way out
    3: ["cannot assign", "REAL"],             # BOOL into a REAL field (STORE_FIELD_L)
    4: [_overflow(INT_MAX + 1)],              # REAL into an INT field, out of range
    5: ["cannot assign", "BOOL"],             # INT into a BOOL field
    6: ["not BOOL"],                          # NOT on an INT is an INT: not a condition
    7: [_overflow(INT_MAX + 1)],              # -(-2147483648): UNOP on an INT
}


def test_unop_conditions_and_fields_values():
    out = run_all(UNOP, max_steps=100_000, max_sim_time=10.0)
    assert out.reason == "completed", out
    d = out.data
    assert d["DONE"] == 1
    assert d["V_NOT"] == [False, True, False, False]
    assert d["V_INOT"] == [~5, ~-1]                 # NOT on an INT: the bitwise complement
    assert d["V_NEG"] == [-2.25, -4.5]
    assert d["V_INEG"] == [-5, 7]
    assert d["V_IF"] == [2, 2, 0]
    assert d["V_REP"] == 4
    assert d["V_FX"] == [1.5, 3.0, 11.0]            # INT 3 into the REAL field: 3.0; 3.0 * 2.0 + 5
    assert d["V_FN"] == [7, 3, -3]                  # REAL into INT: nearest, ties away from zero
    assert d["V_FB"] == [False, True]
    ops = opcodes_of(UNOP)
    assert {"UNOP", "JUMP_IF_FALSE", "STORE_FIELD_L"} <= ops, sorted(ops)


def test_unop_error_cases_cover_every_marker():
    assert sorted(int(n) for n in re.findall(r";\s*E(\d+)\s*$", UNOP.read_text(), re.M)) == sorted(UNOP_ERRORS)


@pytest.mark.parametrize("case", sorted(UNOP_ERRORS))
def test_unop_conditions_and_fields_errors(case):
    out = run_all(UNOP, set_vars={"SEL": case}, max_steps=100_000, max_sim_time=10.0)
    assert out.reason == "error", out
    for p in UNOP_ERRORS[case]:
        assert p.lower() in out.text.lower(), (p, out.text)
    assert Path(out.file).name.lower() == "fp_unop.src"
    assert out.line == marker_line(UNOP, f"E{case}")
    assert out.data["DONE"] == 0


# ---------------------------------------------------------------------------- advance-run stops
CALM_PROG = """
DEF calm()
  INT i
  FOR i = 1 TO 3000
    $OUT[4] = FALSE
  ENDFOR
  PTP {A1 20, A2 -90, A3 90, A4 0, A5 30, A6 0}
  i = 0
  $OUT[5] = TRUE
END
"""

CALM_SPS = """
DEF calm_sps()
  LOOP
    $OUT[6] = FALSE
  ENDLOOP
END
"""


def _counted_run(tmp_path, interp: str):
    prog = tmp_path / "calm.src"
    prog.write_text(CALM_PROG)
    sub = tmp_path / "calm_sps.sub"
    sub.write_text(CALM_SPS)
    # the submit program is a spin: parked, it would be woken (a task switch, the full hook for
    # the robot program's next statement) by each of the robot program's steps; unparked, the
    # quiet path alone decides
    rt, vm = make_runtime(run_spec(prog, mujoco=False, interp=interp, max_sim_time=30.0, check=False,
                          submit=[sub], spins="off"))
    calls = count_hooks(vm) if interp == "vm" else [0]
    res = rt.run()
    return rt, res, calls[0]


def test_advance_run_stops_that_stop_nothing_are_quiet_steps(tmp_path):
    """An output write stops the advance run (its StmtInfo ``stops``), in the robot
    interpreter only, and only while the main run has motions (Runtime.before_statement,
    wait_main_run). So the submit program's writes, and the robot program's while the robot
    stands, are quiet steps in the VM (Runtime.quiet_limit, ``Task.calm``): about one full hook
    per task per IPO cycle, where every such write took one until 2026-11-26. The write after
    the PTP (and a statement that does not stop, whose full hook sees the main run busy) still
    waits for the main run: $OUT[5] rises when the motion has ended (0.348 s), at the time the
    tree interpreter (which takes every hook) gives, not after the loop's 6 000 steps (6 IPO
    cycles: 0.072 s, where it rises if the queued motion or the busy main run is overlooked)."""
    rt, res, hooks = _counted_run(tmp_path, "vm")
    tree_rt, tree_res, _ = _counted_run(tmp_path, "tree")
    assert res.reason == tree_res.reason == "completed"
    assert rt.controller.io.log == tree_rt.controller.io.log
    assert (res.steps, res.sim_time) == (tree_res.steps, tree_res.sim_time)
    rises = [t for t, name, v, _s in rt.controller.io.log if name == "$OUT[5]" and v]
    assert len(rises) == 1
    # the PTP of 20 degrees of A1 takes many IPO cycles: the write waited for its end
    assert rises[0] > 0.072 + 0.1, rises
    cycles = round(res.sim_time / rt.controller.dt)
    assert hooks <= 3 * cycles + 20, (hooks, cycles, res.steps)
