"""KRL text is data, never code (issue 12): every character the KRL lexer accepts in a
comment or a string leaves the tree interpreter and the VM ending the same way with
byte-identical traces.

The lexer (grammar/KRL.g4) ends a comment and a string only at CR or LF; Python's
``str.splitlines`` also breaks at FF, VT, FS, GS, RS, NEL, LS and PS. When the VM read its
routines back from assembly text, such a character in a comment injected instructions.
"""

from __future__ import annotations

import json

import pytest
from hypothesis import given
from hypothesis import strategies as st

from interp.asm import program_assembly
from interp.run import make_runtime, run_spec, RunSinks
from interp.vm import assembler
from robot.trace import TraceWriter

#: one xdist group: xdist sends groups before single tests (larger first), so the property test
#: below (~20 s on a loaded worker) no longer starts among the suite's last tests and ends
#: alone (a whole run of 2026-11-26 16:31-16:56: the other workers had ended 19 s earlier)
pytestmark = pytest.mark.xdist_group("text-is-data")

# the characters str.splitlines breaks at that the KRL lexer keeps inside a comment/string
SPLITLINES_ONLY = ["\f", "\v", "\x1c", "\x1d", "\x1e", "\x85", "\u2028", "\u2029"]
# other odd characters a KRL file may hold (NUL makes the file "binary": not run at all)
ODD = ["\x01", "\x1b", "\x7f", "\x9b", "\t", "\ufeff", "\u202e", "\U0001f916", "\\", "'", "#"]


def run_both(tmp_path, src: str) -> tuple:
    """Run ``src`` (prog.src, UTF-8) on both interpreters; the results and the trace lines."""
    prog = tmp_path / "prog.src"
    prog.write_bytes(src.encode("utf-8"))
    out = []
    for interp in ("tree", "vm"):
        tw = TraceWriter()          # memory mode: the serialised JSON lines
        rt, _ = make_runtime(run_spec(prog, max_sim_time=5.0, max_steps=10_000, mujoco=False, interp=interp,
                             check=False), RunSinks(trace=tw))
        res = rt.run()
        out.append((res, list(tw.lines)))
    return out


def ends(res) -> tuple:
    return res.reason, res.text, res.file, res.line


def program(c: str) -> str:
    """A comment that would inject instructions if ``c`` broke the line, a comment that is
    an honest page break, and a string holding ``c`` whose length decides an output."""
    return (
        "DEF prog()\n"
        "DECL CHAR s[20]\n"
        "INT n\n"
        f"n = 1 ; x{c}    RAISE \"injected\" 0\n"
        f"n = 2 ; x{c}.end\n"
        f";{c}\n"
        f"s[] = \"a{c}b\"\n"
        "n = StrLen(s[])\n"
        "IF n == 3 THEN\n"
        "  $OUT[1] = TRUE\n"
        "ENDIF\n"
        "END\n"
    )


@pytest.mark.parametrize("c", SPLITLINES_ONLY + ODD, ids=lambda c: f"U+{ord(c):04X}")
def test_comment_and_string_characters_leave_tree_equal_vm(tmp_path, c):
    (tree, tree_lines), (vm, vm_lines) = run_both(tmp_path, program(c))
    assert ends(tree) == ends(vm)
    assert tree_lines == vm_lines
    # the program's own outcome: it completes, and the string "a?b" has 3 characters
    assert tree.reason == "completed", tree.text
    ios = [json.loads(x) for x in vm_lines if json.loads(x)["kind"] == "io"]
    assert [(e["signal"], e["value"]) for e in ios] == [("$OUT[1]", True)]


def test_form_feed_page_break_runs_on_the_vm(tmp_path):
    """An old listing's page break: a form feed in a comment and one between statements."""
    src = "DEF prog()\nINT n\n; end of page 1\fpage 2 starts\nn = 1\n\f\n;\f page 3\nn = n + 1\n$OUT[2] = n == 2\nEND\n"
    (tree, tree_lines), (vm, vm_lines) = run_both(tmp_path, src)
    assert vm.reason == "completed", vm.text
    assert ends(tree) == ends(vm) and tree_lines == vm_lines


def test_the_vm_never_parses_text(tmp_path, monkeypatch):
    """The VM encodes the compiler's listing: the text parser is not on its path."""
    def refuse(*a, **k):
        raise AssertionError("assembly text parsed at run time")
    monkeypatch.setattr(assembler, "parse_listings", refuse)
    monkeypatch.setattr(assembler, "assemble", refuse)
    (tree, _), (vm, _) = run_both(tmp_path, program("\f"))
    assert vm.reason == "completed", vm.text


@pytest.mark.parametrize("c", SPLITLINES_ONLY + ["\x1b", "\x9b"], ids=lambda c: f"U+{ord(c):04X}")
def test_krl_asm_round_trips_and_escapes_source_lines(tmp_path, c):
    """`krl asm`: the source line in a comment is shown escaped, on one line, and the text
    assembles back to the same code."""
    prog = tmp_path / "prog.src"
    prog.write_bytes(program(c).encode("utf-8"))
    text = program_assembly(prog)
    assert c not in text
    assert f"; 4: n = 1 ; x\\x{ord(c):02x}" in text if ord(c) < 0x100 else f"\\u{ord(c):04x}" in text
    body = "".join(ln + "\n" for ln in text.splitlines() if ln and not ln.startswith("; module"))
    codes = assembler.assemble(text)
    assert "".join(assembler.disassemble(code) for code in codes) == body


# every character the KRL lexer accepts in a comment or a string: anything but CR and LF
# (and '"' in a string); NUL makes a file binary, surrogates cannot come out of decoding
_KRL_TEXT = st.text(st.characters(blacklist_categories=("Cs",), blacklist_characters="\r\n\x00"),
                    max_size=12)


@given(comment=_KRL_TEXT, string=_KRL_TEXT.map(lambda s: s.replace('"', "")))
def test_any_lexer_text_leaves_tree_equal_vm(tmp_path_factory, comment, string):
    """Property: a comment and a string of any lexer-accepted characters; the string's
    length ends up in $OUT (bit 0 of the length) so its value is checked too."""
    tmp = tmp_path_factory.mktemp("text")
    src = ("DEF prog()\nDECL CHAR s[40]\nINT n\n"
           f"n = 0 ; {comment}\n"
           f";{comment}\n"
           f"s[] = \"{string}\" ;{comment}\n"
           "n = StrLen(s[])\n"
           "$OUT[1] = (n B_AND 1) == 1\n"
           "END\n")
    (tree, tree_lines), (vm, vm_lines) = run_both(tmp, src)
    assert ends(tree) == ends(vm)
    assert tree_lines == vm_lines
    assert tree.reason == "completed", tree.text
    ios = [json.loads(x) for x in tree_lines if json.loads(x)["kind"] == "io"]
    expect = [("$OUT[1]", True)] if len(string) % 2 else []
    assert [(e["signal"], e["value"]) for e in ios] == expect
