"""No exception escapes `krl check`, from random bytes or from mutated programs."""

from __future__ import annotations

import json

import pytest
from hypothesis import given, settings, strategies as st

from tests.budget import examples

from app.check import run_check
from krl.workspace import check_texts, load_workspace
from krl.ast import nodes as N
from krl.ast.printer import print_module
from krl.source import is_krl_file

from .strategies import modules

SEED = """&ACCESS RVP
DEF seed(p :IN, q :OUT)
  DECL INT p, i, a[4]
  DECL REAL q
  DECL E6POS here
  DECL CHAR s[8]
  q = p * 2.5
  s[] = "ab"
  FOR i = 1 TO 4 STEP 1
    a[i] = i
  ENDFOR
  IF (p > 1) AND $IN[2] THEN
    PTP {A1 0, A2 -90} C_PTP
    LIN here : {X 10} C_DIS
  ELSE
    SWITCH p
    CASE 1, 2
      WAIT SEC 0.1
    DEFAULT
      GOTO done
    ENDSWITCH
  ENDIF
  TRIGGER WHEN DISTANCE = 1 DELAY = 0 DO $OUT[1] = TRUE
  SPTP here WITH $VEL_AXIS[1] = 20 C_SPL
  done:
END
"""
SEED_DAT = "DEFDAT seed\n  DECL E6POS XP1 = {X 1, Y 2, Z 3, A 0, B 0, C 0, S 2, T 10}\n  INT n[3]\n  n[2] = 5\nENDDAT\n"


def _safe_check_text(text: str, dat: str | None = None):
    files = {"seed.src": text}
    if dat is not None:
        files["seed.dat"] = dat
    ws = check_texts(files)   # must not raise
    for d in ws.diagnostics:
        assert d.line >= 0 and d.code[0] in "EW"
        assert d.code != "E901", str(d)          # an internal checker error is a bug
        if all(f.ok for f in ws.files):
            assert d.code != "W003", str(d)      # a tree that parsed must build completely
    return ws


def test_seed_is_clean():
    ws = _safe_check_text(SEED, SEED_DAT)
    assert not [d for d in ws.diagnostics if d.is_error], [str(d) for d in ws.diagnostics]


@given(st.binary(max_size=300))
def test_random_bytes_through_files(tmp_path_factory, data):
    folder = tmp_path_factory.mktemp("fuzz")
    (folder / "f.src").write_bytes(data)
    (folder / "f.dat").write_bytes(data[::-1])
    lines: list[str] = []
    status = run_check([str(folder)], as_json=True, echo=lines.append)
    assert status in (0, 1)
    assert all(isinstance(json.loads(line), dict) for line in lines)


@given(st.text(max_size=300))
def test_random_text(text):
    _safe_check_text(text)


_MUTATIONS = st.lists(st.tuples(st.sampled_from(["del", "ins", "dup", "swap", "tok"]),
                                st.integers(0, 10_000), st.integers(0, 10_000),
                                st.sampled_from(["", "=", "[", "]", "(", ")", ",", ":", "#", "\"", "{", "}",
                                                 "\n", " IF ", " ENDIF", " DECL INT z", "$", "1.5E", " AND ",
                                                 "ENDFOR\n", "DEF x()\n", "END\n", ";"])),
                      min_size=1, max_size=6)


def _mutate(text: str, muts) -> str:
    lines = text.split("\n")
    for kind, i, j, tok in muts:
        if kind == "del" and text:
            k = i % len(text)
            text = text[:k] + text[k + 1 + j % 5:]
        elif kind == "ins":
            k = i % (len(text) + 1)
            text = text[:k] + tok + text[k:]
        elif kind == "dup" and lines:
            lines = text.split("\n")
            k = i % len(lines)
            lines.insert(j % (len(lines) + 1), lines[k])
            text = "\n".join(lines)
        elif kind == "swap" and lines:
            lines = text.split("\n")
            a, b = i % len(lines), j % len(lines)
            lines[a], lines[b] = lines[b], lines[a]
            text = "\n".join(lines)
        elif kind == "tok":
            words = text.split(" ")
            if words:
                words[i % len(words)] = tok
                text = " ".join(words)
    return text


@given(_MUTATIONS)
def test_mutated_programs(muts):
    _safe_check_text(_mutate(SEED, muts), _mutate(SEED_DAT, muts[:1]))


def test_unreadable_inputs(tmp_path):
    (tmp_path / "bin.src").write_bytes(b"DEF x()\x00\x01END")
    (tmp_path / "empty.dat").write_bytes(b"")
    ws = load_workspace([tmp_path, tmp_path / "missing.src"])
    diags = ws.check()
    assert {d.code for d in diags} == {"E001"}
    assert run_check([str(tmp_path / "nothing-here")], echo=lambda s: None) == 1


@given(modules)
def test_generated_programs_check_without_internal_errors(module):
    ws = _safe_check_text(print_module(module))
    for f in ws.files:
        assert all(N.type_of(n) is not None for n in f.module.walk() if isinstance(n, N.Expr))


@pytest.mark.corpus
@settings(max_examples=examples(15))
@given(st.data())
def test_mutated_corpus_files(corpus, data):
    """Mutations of real backup files: still no exception and no internal error."""
    files = _sample_files(corpus)
    path = data.draw(st.sampled_from(files))
    text = path.read_bytes().decode("utf-8", errors="replace")
    muts = data.draw(_MUTATIONS)
    suffix = path.suffix.lower()
    ws = check_texts({f"m{suffix}": _mutate(text, muts)})
    assert not [d for d in ws.diagnostics if d.code == "E901"]


_SAMPLE: list = []


def _sample_files(corpus):
    if not _SAMPLE:
        files = sorted(p for p in corpus.rglob("*") if p.is_file() and is_krl_file(p)
                       and p.stat().st_size < 20_000)
        _SAMPLE.extend(files[:: max(1, len(files) // 40)])
    return _SAMPLE
