"""Run-time resources end as KRL run-time errors with their line, the same on both
interpreters (issue 12, "Depth and size are limits with a message, not crashes").

Each program runs on the tree interpreter and on the VM: the traces must be identical event
for event and the end (reason, message, file, line) the same. The expected lines are counted
by hand from the program texts below (line 1 is ``DEF prog()``); the expected limits come
from krl/limits.py, the one home of every limit.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
from click.testing import CliRunner
from hypothesis import given, settings
from hypothesis import strategies as st

from interp.run import make_runtime, run_spec, RunSinks
from interp.runtime.convert import trunc_int
from interp.runtime.errors import KrlRuntimeError
from interp.runtime.natives.swrite import sread_values, swrite_text
from interp.runtime.values import is_char_array
from app import main
from krl.limits import MAX_DATA_ELEMENTS, MAX_EXPRESSION_TERMS, MAX_NESTING
from robot.trace import TraceWriter
from tests.budget import examples

from .differential import first_difference, run_trace


def run_both(tmp_path: Path, src: str, dat: str | None = None, **kw):
    """Run prog.src (and prog.dat) on both interpreters; assert identical traces and ends.
    Returns (result, trace events, var) with ``var(name)`` a data-list variable's value
    (the same on both; a CHAR array as its text, a structure as a dict)."""
    (tmp_path / "prog.src").write_text(src)
    if dat is not None:
        (tmp_path / "prog.dat").write_text(dat)
    rts = {}
    results = {}
    for kind in ("tree", "vm"):
        results[kind] = run_trace(tmp_path / "prog.src", kind, before=lambda rt, k=kind: rts.__setitem__(k, rt),
                                  **kw)
    (tree, tree_ev), (vm, vm_ev) = results["tree"], results["vm"]
    diff = first_difference(tree_ev, vm_ev)
    assert diff is None, f"first difference at event {diff[0]}:\n tree {diff[1]}\n vm   {diff[2]}"
    assert (tree.reason, tree.text, tree.file, tree.line) == (vm.reason, vm.text, vm.file, vm.line)

    def plain(v):
        if is_char_array(v):
            return v.text()
        if hasattr(v, "f"):
            return {k: plain(x) for k, x in v.f.items()}
        if hasattr(v, "data"):
            return [plain(x) for x in v.data]
        return getattr(v, "name", v)     # an ENUM value as its name

    def var(name: str):
        vals = [plain(rts[kind].program.module("prog").data[name.upper()].peek()) for kind in ("tree", "vm")]
        assert vals[0] == vals[1], (name, vals)
        return vals[0]
    return vm, vm_ev, var


def assert_error(res, pattern: str, line: int, file: str = "prog.src") -> None:
    assert res.reason == "error", (res.reason, res.text)
    assert re.search(pattern, res.text), res.text
    assert (Path(res.file).name, res.line) == (file, line), (res.file, res.line, res.text)
    assert "internal" not in res.text


# ---------------------------------------------------------------- data memory (MAX_DATA_ELEMENTS)
HUGE = 100_000_000       # the DECL INT a[1e8]: 899 MB before the limit


def test_huge_local_array_is_an_error_at_its_decl(tmp_path):
    res, _, _ = run_both(tmp_path, "DEF prog()\n  DECL INT n\n  DECL INT a[100000000]\n  n = 1\nEND\n")
    assert_error(res, rf"data memory exhausted: a needs {HUGE} data elements", 3)


def test_array_far_past_any_memory_is_an_error_not_memoryerror(tmp_path):
    res, _, _ = run_both(tmp_path, "DEF prog()\n  DECL CHAR s[99999999999]\n  s[1] = \"A\"\nEND\n")
    assert_error(res, r"data memory exhausted: s needs 99999999999 data elements", 2)


def test_huge_data_list_array_is_an_error_at_its_dat_line(tmp_path):
    dat = "DEFDAT prog\n  DECL INT b[10]\n  DECL INT a[100000000]\nENDDAT\n"
    res, _, _ = run_both(tmp_path, "DEF prog()\n  b[1] = 1\nEND\n", dat)
    assert_error(res, rf"data memory exhausted: a needs {HUGE}", 3, "prog.dat")


def test_data_list_of_a_module_loaded_during_the_run(tmp_path):
    """OTHER's data list is loaded when OTHER is first called (line 3): its DECL is the error."""
    (tmp_path / "other.src").write_text("DEF other()\n  big[1] = 1\nEND\n")
    (tmp_path / "other.dat").write_text("DEFDAT other\n  DECL INT big[2000000]\nENDDAT\n")
    res, _, _ = run_both(tmp_path, "DEF prog()\n  n = 1\n  OTHER()\nEND\n", "DEFDAT prog\n  DECL INT n\nENDDAT\n")
    assert_error(res, r"data memory exhausted: big needs 2000000", 2, "other.dat")


def test_config_dat_past_the_limit_stops_the_start(tmp_path):
    """$config.dat is loaded before the run: the program does not start; the error is its DECL."""
    (tmp_path / "$config.dat").write_text("DEFDAT $CONFIG\n  DECL GLOBAL INT n\n  DECL GLOBAL INT big[3000000]\nENDDAT\n")
    res, ev, _ = run_both(tmp_path, "DEF prog()\n  n = 1\nEND\n")
    assert_error(res, r"data memory exhausted: big needs 3000000", 3, "$config.dat")
    assert [e["kind"] for e in ev] == ["error", "end"]


def test_nested_struc_arrays_count_every_element(tmp_path):
    # 100 000 x (1 structure + 1000 INT + 1 REAL) = 100 200 000 elements
    dat = "DEFDAT prog\n  STRUC SS INT A[1000], REAL B\nENDDAT\n"
    res, _, _ = run_both(tmp_path, "DEF prog()\n  DECL SS x[100000]\n  x[1].B = 1.0\nEND\n", dat)
    assert_error(res, r"data memory exhausted: x needs 100200000 data elements", 2)


def test_an_array_that_fits_runs(tmp_path):
    n = MAX_DATA_ELEMENTS // 2
    res, _, var = run_both(tmp_path, f"DEF prog()\n  DECL INT a[{n}]\n  a[{n}] = 7\n  r = a[{n}]\nEND\n",
                           "DEFDAT prog\n  DECL INT r\nENDDAT\n")
    assert res.reason == "completed", res.text
    assert var("r") == 7


def test_routine_memory_is_given_back_on_return(tmp_path):
    """Two calls in a row of a routine holding 60 % of the memory: the second fits only if
    the first gave its share back; recursion of the same routine does not fit."""
    n = MAX_DATA_ELEMENTS * 6 // 10
    src = ("DEF prog()\n"              # 1
           "  BIG(0)\n"                # 2
           "  BIG(0)\n"                # 3
           "  done = TRUE\n"           # 4
           "  BIG(1)\n"                # 5
           "END\n"                     # 6
           "DEF BIG(deeper:IN)\n"      # 7
           "  DECL INT deeper\n"       # 8
           f"  DECL INT a[{n}]\n"      # 9
           "  a[1] = 1\n"              # 10
           "  IF deeper > 0 THEN\n"    # 11
           "    BIG(0)\n"              # 12
           "  ENDIF\n"                 # 13
           "END\n")
    res, _, var = run_both(tmp_path, src, "DEFDAT prog\n  DECL BOOL done = FALSE\nENDDAT\n")
    assert var("done") is True
    assert_error(res, rf"data memory exhausted: a needs {n} data elements", 9)


def test_recursion_with_local_arrays_stops_at_the_decl(tmp_path):
    # each call holds 100 000 elements: about ten calls fit, far below the 100 nested calls
    src = "DEF prog()\n  R(0)\nEND\nDEF R(n:IN)\n  DECL INT n\n  DECL INT a[100000]\n  R(n + 1)\nEND\n"
    res, _, _ = run_both(tmp_path, src)
    assert_error(res, r"data memory exhausted: a needs 100000 data elements", 6)


def test_in_parameter_copy_counts(tmp_path):
    """An :IN array parameter is a copy: a 60 % array passed by value does not fit twice;
    the same array passed :OUT (a reference) does."""
    n = MAX_DATA_ELEMENTS * 6 // 10
    src = ("DEF prog()\n"                       # 1
           "  BYREF(big[])\n"                   # 2
           "  ok = TRUE\n"                      # 3
           "  BYVAL(big[])\n"                   # 4
           "END\n"                              # 5
           "DEF BYREF(v[]:OUT)\n"               # 6
           "  DECL INT v[]\n"                   # 7
           "  v[1] = 1\n"                       # 8
           "END\n"                              # 9
           "DEF BYVAL(v[]:IN)\n"                # 10
           "  DECL INT v[]\n"                   # 11
           "  n = v[1]\n"                       # 12
           "END\n")
    dat = f"DEFDAT prog\n  DECL INT big[{n}]\n  DECL INT n\n  DECL BOOL ok = FALSE\nENDDAT\n"
    res, _, var = run_both(tmp_path, src, dat)
    assert var("ok") is True
    assert_error(res, rf"data memory exhausted: a copy of :IN parameter v needs {n}", 4)


def test_struc_that_contains_itself_is_an_error_at_the_decl(tmp_path):
    dat = "DEFDAT prog\n  STRUC SS INT A, SS B\nENDDAT\n"
    res, _, _ = run_both(tmp_path, "DEF prog()\n  DECL SS v\n  v.A = 1\nEND\n", dat)
    assert_error(res, r"STRUC SS contains itself", 2)


@pytest.mark.parametrize("levels, fits", [(MAX_NESTING, True), (MAX_NESTING + 1, False)])
def test_struc_nesting_shares_the_nesting_budget(tmp_path, levels, fits):
    lines = ["DEFDAT prog", "  STRUC S1 INT A"]
    lines += [f"  STRUC S{i} INT A, S{i - 1} B" for i in range(2, levels + 1)]
    lines += [f"  DECL S{levels} V", "ENDDAT"]
    dat = "\n".join(lines) + "\n"
    res, _, var = run_both(tmp_path, "DEF prog()\n  V.B.B.A = 2\n  V.A = 3\nEND\n", dat)
    if fits:
        assert res.reason == "completed", res.text
        assert var("V")["A"] == 3
    else:
        # the DECL is the line after ENDDAT's predecessors: DEFDAT + `levels` STRUC lines
        assert_error(res, rf"nesting too deep: more than {MAX_NESTING} levels of STRUC", levels + 2, "prog.dat")


# ---------------------------------------------------------------- SWRITE / SREAD formats
SW_DAT = """DEFDAT prog
  DECL CHAR buf[20]
  DECL STATE_T st
  DECL INT p, n
  DECL REAL r
ENDDAT
"""


@pytest.mark.parametrize("spec", ["%2000000000d", "%99999999999999999999d", "%\u00b2d", "%.21f", "%21d", "%q"],
                         ids=["2e9", "20-digits", "superscript", "precision-21", "width-21", "unknown"])
def test_bad_swrite_format_is_fmt_err_in_the_state(tmp_path, spec):
    """The controller's answer to a bad format: the text before it is written, RET1 =
    #FMT_ERR, HITS = the values converted before it; the program goes on."""
    src = ("DEF prog()\n"
           "  p = 0\n"
           f"  SWRITE(buf[], st, p, \"ab%d;{spec}|\", 7, 8)\n"
           "  n = 1\n"
           "END\n")
    res, _, var = run_both(tmp_path, src, SW_DAT)
    assert res.reason == "completed", res.text
    assert var("buf") == "ab7;"
    assert var("st")["RET1"] == "FMT_ERR" and var("st")["HITS"] == 1
    assert var("p") == 4 and var("n") == 1


def test_width_up_to_the_buffer_length_is_fine(tmp_path):
    src = "DEF prog()\n  p = 0\n  SWRITE(buf[], st, p, \"%20d\", 7)\nEND\n"
    res, _, var = run_both(tmp_path, src, SW_DAT)
    assert res.reason == "completed", res.text
    assert var("buf") == " " * 19 + "7"
    assert var("st")["RET1"] == "CMD_OK" and var("st")["HITS"] == 1 and var("p") == 20


def test_sread_superscript_digits_are_not_numbers(tmp_path):
    """'²' is a CHAR (code 178) that str.isdigit() takes for a digit; scanf does not."""
    src = ("DEF prog()\n"
           "  buf[] = \"12 \u00b2\"\n"
           "  p = 0\n"
           "  SREAD(buf[], st, p, \"%d %d\", n, r)\n"
           "END\n")
    res, _, var = run_both(tmp_path, src, SW_DAT)
    assert res.reason == "completed", res.text
    assert var("n") == 12
    assert var("st")["RET1"] == "FMT_ERR" and var("st")["HITS"] == 1


def test_sread_width_past_the_source_is_fmt_err(tmp_path):
    src = "DEF prog()\n  buf[] = \"12\"\n  p = 0\n  SREAD(buf[], st, p, \"%99999999999999999999d\", n)\nEND\n"
    res, _, var = run_both(tmp_path, src, SW_DAT)
    assert res.reason == "completed", res.text
    assert var("st")["RET1"] == "FMT_ERR" and var("st")["HITS"] == 0


# ---------------------------------------------------------------- CAST offsets
CAST_DAT = "DEFDAT prog\n  DECL CHAR buf[20]\n  DECL INT p, x\nENDDAT\n"


@pytest.mark.parametrize("op, offset", [("CAST_FROM", -4), ("CAST_FROM", -100), ("CAST_FROM", 21),
                                        ("CAST_TO", -4), ("CAST_TO", 21)])
def test_cast_offset_outside_the_buffer_is_an_error(tmp_path, op, offset):
    src = f"DEF prog()\n  x = 5\n  p = {offset}\n  {op}(buf[], p, x)\nEND\n"
    res, _, var = run_both(tmp_path, src, CAST_DAT)
    assert_error(res, rf"{op}: offset {offset} outside 0\.\.20", 4)
    assert var("x") == 5         # nothing read from the end of the buffer


def test_cast_at_the_last_fitting_offset_works(tmp_path):
    src = "DEF prog()\n  x = -2\n  p = 16\n  CAST_TO(buf[], p, x)\n  x = 0\n  p = 16\n  CAST_FROM(buf[], p, x)\nEND\n"
    res, _, var = run_both(tmp_path, src, CAST_DAT)
    assert res.reason == "completed", res.text
    assert var("x") == -2 and var("p") == 20


# ---------------------------------------------------------------- StrToInt / StrToReal
# KRL literal syntax (reference §1.5, grammar/KRL.g4): INT [0-9]+, 'H' hex, 'B' binary;
# REAL [0-9]+.[0-9]*E?, .[0-9]+E?, [0-9]+E; a sign as in data-list initial values.
INT_TABLE = [("12", 12), ("-7", -7), ("+3", 3), ("'H1F'", 31), ("'hff'", 255), ("'B0101'", 5),
             ("2147483647", 2147483647), ("-2147483648", -2147483648), ("007", 7),
             ("1_000", None), ("nan", None), ("infinity", None), (" 12", None), ("12 ", None),
             ("2147483648", None), ("0x1F", None), ("1.5", None), ("1E3", None), ("", None),
             ("\u00b2", None), ("'H'", None), ("'HFFFFFFFF'", None), ("--1", None)]
REAL_TABLE = [("1.5", 1.5), ("0.0", 0.0), ("1E6", 1e6), ("1.0E-03", 1e-3), ("-3.4e+2", -340.0), (".5", 0.5),
              ("5.", 5.0), ("5", 5.0), ("+2.5", 2.5),
              ("nan", None), ("inf", None), ("infinity", None), ("1_0.0", None), (" 1.0", None),
              ("1.0 ", None), ("1e", None), ("e5", None), (".", None), ("1e999", None), ("0x1p3", None),
              ("1,5", None), ("\u00b2", None)]


@pytest.mark.parametrize("fn, table", [("StrToInt", INT_TABLE), ("StrToReal", REAL_TABLE)])
def test_str_to_number_accepts_krl_literal_syntax_only(tmp_path, fn, table):
    t = "INT" if fn == "StrToInt" else "REAL"
    body = []
    for k, (text, _) in enumerate(table, 1):
        body.append(f"  v[{k}] = -1\n  ok[{k}] = {fn}(\"{text}\", v[{k}])\n")
    dat = f"DEFDAT prog\n  DECL {t} v[{len(table)}]\n  DECL BOOL ok[{len(table)}]\nENDDAT\n"
    res, _, var = run_both(tmp_path, "DEF prog()\n" + "".join(body) + "END\n", dat)
    assert res.reason == "completed", res.text
    oks, vals = var("ok"), var("v")
    for k, (text, want) in enumerate(table):
        assert oks[k] is (want is not None), (text, oks[k], vals[k])
        assert vals[k] == (want if want is not None else -1), (text, vals[k])


# ---------------------------------------------------------------- nesting and expression size
def nested_ifs(levels: int) -> str:
    return ("DEF prog()\n  DECL INT i\n  i = 1\n" + "IF i == 1 THEN\n" * levels + "i = 2\n"
            + "ENDIF\n" * levels + "END\n")


def test_nesting_within_the_budget_runs(tmp_path):
    res, _, _ = run_both(tmp_path, nested_ifs(MAX_NESTING))
    assert res.reason == "completed", res.text


def test_nesting_past_the_budget_stops_the_start(tmp_path):
    """`krl run` of a program nesting one level too deep: it does not start, on either
    interpreter; the error names the IF that went past it (line 3 + its depth)."""
    res, ev, _ = run_both(tmp_path, nested_ifs(MAX_NESTING + 1))
    assert_error(res, rf"cannot start: .*prog\.src:{3 + MAX_NESTING + 1}:1: nesting too deep", 3 + MAX_NESTING + 1)
    assert [e["kind"] for e in ev] == ["error", "end"]      # not one statement ran


def test_deep_recursion_is_a_stack_overflow_at_the_call(tmp_path):
    src = "DEF prog()\n  R(0)\nEND\nDEF R(n:IN)\n  DECL INT n\n  R(n + 1)\nEND\n"
    res, _, _ = run_both(tmp_path, src)
    assert_error(res, r"stack overflow", 6)


@pytest.mark.parametrize("terms", [10_000, 20_000])
def test_too_long_expression_stops_the_start(tmp_path, terms):
    """E019 before the run: never dropped with a warning, never a tree-only RecursionError."""
    src = "DEF prog()\n  DECL INT i\n  i = " + " + ".join(["1"] * terms) + "\n  i = 0\nEND\n"
    res, ev, _ = run_both(tmp_path, src)
    assert_error(res, rf"cannot start: .*prog\.src:3:3: expression too long: more than {MAX_EXPRESSION_TERMS} terms", 3)
    assert [e["kind"] for e in ev] == ["error", "end"]


def test_longest_expression_runs_alike(tmp_path):
    src = ("DEF prog()\n  i = " + " + ".join(["1"] * MAX_EXPRESSION_TERMS) + "\nEND\n")
    res, _, var = run_both(tmp_path, src, "DEFDAT prog\n  DECL INT i\nENDDAT\n")
    assert res.reason == "completed", res.text
    assert var("i") == MAX_EXPRESSION_TERMS


# ---------------------------------------------------------------- beyond the list
def test_wait_sec_nan_and_infinity_are_errors(tmp_path):
    src = ("DEF prog()\n"
           "  DECL REAL r\n"
           "  r = 1E308 * 10.0\n"     # no REAL range check: a float infinity
           "  WAIT SEC r - r\n"      # 4: NaN
           "END\n")
    res, _, _ = run_both(tmp_path, src)
    assert_error(res, r"WAIT SEC with an invalid time \(nan\)", 4)


@pytest.mark.parametrize("stmt, what", [("INTERRUPT ON r", "interrupt number"),
                                        ("SWRITE(buf[], st, p, \"%c\", r)", "%c argument")])
def test_infinite_real_where_an_int_is_taken_is_an_error(tmp_path, stmt, what):
    src = f"DEF prog()\n  r = 1E308 * 10.0\n  p = 0\n  {stmt}\nEND\n"
    res, _, _ = run_both(tmp_path, src, SW_DAT)
    assert_error(res, rf"{what}: REAL value cannot be converted to INT", 4)


@pytest.mark.parametrize("start, step", [(2147483000, 100), (1, 1073741824), (-2147483000, -1000)])
def test_int_overflow_of_a_for_counter_is_an_error_at_the_for(tmp_path, start, step):
    """The counter's last step leaves the INT range: an error of the FOR statement (line 3),
    not of the body's last line, and not a loop that wraps around forever."""
    end = 2147483647 if step > 0 else -2147483648
    src = ("DEF prog()\n"
           "  n = 0\n"
           f"  FOR i = {start} TO {end} STEP {step}\n"
           "    n = n + 1\n"
           "  ENDFOR\n"
           "END\n")
    res, _, var = run_both(tmp_path, src, "DEFDAT prog\n  DECL INT i, n\nENDDAT\n")
    assert_error(res, r"INT overflow", 3)
    # the body ran once per value in range: (end - start) // step + 1 times
    assert var("n") == (end - start) // step + 1


def test_varstate_of_any_text_is_an_answer(tmp_path):
    texts = ["buf[\u00b2]", "buf[1", "buf.1", "buf[x]", "buf[99999999999999999999]", "buf[-1]", ""]
    body = "".join(f"  vs[{k}] = VARSTATE(\"{t}\")\n" for k, t in enumerate(texts, 1))
    dat = f"DEFDAT prog\n  DECL CHAR buf[20]\n  DECL VAR_STATE vs[{len(texts)}]\nENDDAT\n"
    res, _, var = run_both(tmp_path, "DEF prog()\n" + body + "END\n", dat)
    assert res.reason == "completed", res.text
    assert var("vs") == ["UNKNOWN"] * len(texts)


def test_stimuli_do_not_hide_a_data_list_past_the_limit(tmp_path):
    """The stimuli's SIGNAL names are resolved from the data list before the run: its memory
    error still ends the run as a KRL error, not an internal one."""
    (tmp_path / "stim.yaml").write_text("stimuli:\n  - at: 0.5\n    set: {GO: true}\n")
    dat = "DEFDAT prog\n  SIGNAL GO $IN[3]\n  DECL INT a[100000000]\nENDDAT\n"
    res, _, _ = run_both(tmp_path, "DEF prog()\n  WAIT SEC 1\nEND\n", dat, inputs=tmp_path / "stim.yaml")
    assert_error(res, rf"data memory exhausted: a needs {HUGE}", 3, "prog.dat")


# ---------------------------------------------------------------- any lexer text through SWRITE and messages
# every character the KRL lexer accepts in a string: anything but CR, LF and '"' (NUL makes a
# file binary; surrogates cannot come out of decoding); the CHAR buffer holds codes 0..255
_STRING = st.text(st.characters(blacklist_categories=("Cs",), blacklist_characters='\r\n\x00"'), max_size=12)


@settings(max_examples=examples(15))
@given(text=_STRING)
def test_any_lexer_string_through_swrite_and_messages_leaves_tree_equal_vm(tmp_path_factory, text):
    """A string of any lexer-accepted characters, formatted by SWRITE (as an argument and as
    the format itself, where a '%' may make a format error) and shown by SET_KRLMSG: both
    interpreters end alike with identical traces, and the "<%s>" message is the string."""
    tmp = tmp_path_factory.mktemp("swrite")
    src = ("DEF prog()\n"
           "DECL CHAR s[40], b[80], f[80]\n"
           "DECL STATE_T st\n"
           "DECL INT p, h\n"
           "DECL KRLMSG_T msg\n"
           "DECL KRLMSGPAR_T par[3]\n"
           "DECL KRLMSGOPT_T opt\n"
           f"s[] = \"{text}\"\n"
           "p = 0\n"
           "SWRITE(b[], st, p, \"<%s>\", s[])\n"
           "msg.MSG_TXT[] = b[]\n"
           "h = SET_KRLMSG(#NOTIFY, msg, par[], opt)\n"
           "p = 0\n"
           f"SWRITE(f[], st, p, \"{text}\", 7, s[])\n"
           "msg.MSG_TXT[] = f[]\n"
           "h = SET_KRLMSG(#NOTIFY, msg, par[], opt)\n"
           "END\n")
    (tmp / "prog.src").write_bytes(src.encode("utf-8"))
    ends, lines = [], []
    for kind in ("tree", "vm"):
        tw = TraceWriter()
        rt, _ = make_runtime(run_spec(tmp / "prog.src", max_sim_time=5.0, max_steps=10_000, mujoco=False,
                             interp=kind, check=False), RunSinks(trace=tw))
        res = rt.run()
        ends.append((res.reason, res.text, res.file, res.line))
        lines.append(list(tw.lines))
    assert ends[0] == ends[1] and lines[0] == lines[1]
    assert "internal" not in ends[0][1]
    messages = [json.loads(x)["text"] for x in lines[0] if json.loads(x)["kind"] == "message"]
    if all(ord(c) < 256 for c in text):       # a CHAR holds codes 0..255
        assert ends[0][0] == "completed", ends[0]
        shown = text.split("\0")[0]
        assert messages[0] == f"KRL message: <{shown}>"
        assert len(messages) == 2


# ---------------------------------------------------------------- the console of `krl run`
@pytest.mark.parametrize("interp", ["tree", "vm"])
@pytest.mark.parametrize("case, src, dat, shown", [
    ("nesting", nested_ifs(MAX_NESTING + 1), None, f"prog.src:{3 + MAX_NESTING + 1}:1: nesting too deep"),
    ("memory", "DEF prog()\n  a[1] = 1\nEND\n", "DEFDAT prog\n  DECL INT a[100000000]\nENDDAT\n",
     "prog.dat:2: data memory exhausted"),
    ("cast", "DEF prog()\n  p = -4\n  CAST_FROM(buf[], p, x)\nEND\n", CAST_DAT, "prog.src:3: CAST_FROM: offset -4"),
])
def test_krl_run_shows_the_limit_with_its_place(tmp_path, interp, case, src, dat, shown):
    """`krl run`: exit 1 (a KRL run-time error), the message with file:line, no internal error."""
    (tmp_path / "prog.src").write_text(src)
    if dat is not None:
        (tmp_path / "prog.dat").write_text(dat)
    res = CliRunner().invoke(main, ["run", "--interp", interp, str(tmp_path / "prog.src")])
    assert res.exit_code == 1, res.output
    assert shown in res.output
    assert "internal error" not in res.output and "Traceback" not in res.output


def test_a_construct_that_cannot_be_built_stops_the_start(tmp_path):
    """E003: an INT literal of 5000 digits cannot become a value; the program does not start
    on either interpreter and the error names its line (3)."""
    src = "DEF prog()\n  DECL INT i\n  i = " + "9" * 5000 + "\n  i = 0\nEND\n"
    res, ev, _ = run_both(tmp_path, src)
    assert_error(res, r"cannot start: .*prog\.src:3:3: cannot build", 3)
    assert [e["kind"] for e in ev] == ["error", "end"]


# ---------------------------------------------------------------- the format engine on any format
_FORMAT_CHARS = "%%%-+ 0#.0123456789\u00b2\u0663dixXofFeEgGcsqlhL;ab"
_VALUES = st.lists(st.one_of(st.integers(-2**31, 2**31 - 1), st.floats(allow_nan=True, allow_infinity=True),
                             st.booleans(), st.text(max_size=3)), max_size=4)


@settings(max_examples=examples(200))
@given(fmt=st.text(alphabet=_FORMAT_CHARS, max_size=16), values=_VALUES, room=st.integers(0, 30),
       src=st.text(alphabet="0123456789 +-.eE\u00b2xf", max_size=12))
def test_any_format_is_text_a_format_error_or_a_krl_error(fmt, values, room, src):
    """SWRITE/SREAD on any format and values: a text that fits, a format error, or a KRL
    run-time error (a value that does not suit its conversion), never a Python exception."""
    try:
        text, hits, error = swrite_text(fmt, values, room)
    except KrlRuntimeError:
        pass
    else:
        assert len(text) <= room and 0 <= hits <= len(values)
        assert error is None or error.startswith("format error")
    try:
        got, pos, error = sread_values(src, fmt)
    except KrlRuntimeError:
        pass
    else:
        assert 0 <= pos <= len(src) and (error is None or error.startswith("format error"))


def test_a_huge_real_taken_as_an_int_is_int_overflow():
    """trunc_int (interrupt numbers, S/T, TRIGGER DISTANCE/PRIO, %c) checks the INT range
    like every other REAL -> INT conversion: 1E30 is INT overflow, 2147483647.9 truncates."""
    with pytest.raises(KrlRuntimeError, match="INT overflow"):
        trunc_int(1e30, "interrupt number")
    with pytest.raises(KrlRuntimeError, match="INT overflow"):
        trunc_int(-2147483649.0)
    assert trunc_int(2147483647.9) == 2147483647 and trunc_int(-7.9) == -7
