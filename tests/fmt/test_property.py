"""krl fmt over generated programs: the printed AST (tests/frontend/strategies.py), scrambled
(random blanks between tokens, random keyword case, indentation, trailing comments, blank
lines, CRLF), must format to text that parses to the same AST and formats to itself. Data lists
are generated as text (values, aggregates, signs, comments, inline-form folds) for the same
properties, plus: compact KUKA style and the inline form's lines kept."""

from __future__ import annotations

import random

from antlr4 import InputStream
from hypothesis import assume, given, settings, strategies as st

from krl.ast.build import build_module
from krl.ast.compare import first_difference, same_tree
from krl.ast.printer import print_module
from krl.fmt import FormatOptions, format_text
from krl.syntax.parse import default_bundle, keyword_types, parse_text
from tests.budget import examples
from tests.frontend.strategies import modules

GAPS = ["", " ", "  ", "\t", " \t "]


def tokens(text: str):
    bundle = default_bundle()
    lexer = bundle.lexer_cls(InputStream(text))
    lexer.removeErrorListeners()
    return [(t.type, t.text.upper()) for t in lexer.getAllTokens()]


def code(text: str):
    """The program's tokens without comments and line ends, keywords upper-case."""
    bundle = default_bundle()
    return [t for t in tokens(text) if t[0] not in (bundle.lexer_cls.NEWLINE, bundle.lexer_cls.COMMENT)]


_GLUE = set("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_$#'\"<>=.")


def scramble(text: str, seed: int) -> str:
    """The same program with other blanks, keyword case, comments and line ends."""
    rnd = random.Random(seed)
    bundle = default_bundle()
    kw = keyword_types(bundle)
    lexer = bundle.lexer_cls(InputStream(text))
    lexer.removeErrorListeners()
    out: list[str] = []
    at_line_start = True
    prev = ""
    nl = "\r\n" if rnd.random() < 0.5 else "\n"
    for tok in lexer.getAllTokens():
        if tok.type == bundle.lexer_cls.NEWLINE:
            if rnd.random() < 0.2:
                out.append(" " * rnd.randint(0, 3) + "; note = 1 ;" + rnd.choice(["", "  x  "]))
            out.append(nl)
            if rnd.random() < 0.1:
                out.append(" " * rnd.randint(0, 4) + nl)
            if rnd.random() < 0.15:
                out.append(" " * rnd.randint(0, 6) + ";full line  comment" + nl)
            at_line_start = True
            continue
        word = tok.text
        if tok.type in kw:
            word = "".join(c.upper() if rnd.random() < 0.5 else c.lower() for c in word)
        if at_line_start:
            out.append(" " * rnd.randint(0, 6))
        else:
            glue = prev[-1:] in _GLUE and word[:1] in _GLUE
            out.append(rnd.choice(GAPS[1:] if glue else GAPS))
        out.append(word)
        prev = word
        at_line_start = False
    return "".join(out)


@settings(max_examples=examples(40))
@given(modules, st.integers(0, 2**32 - 1), st.sampled_from(["upper", "lower", "keep"]))
def test_format_keeps_the_ast_and_is_idempotent(module, seed, case):
    printed = print_module(module)
    messy = scramble(printed, seed)
    assume(code(messy) == code(printed))   # no two tokens glued into one by a removed blank
    before = parse_text(messy, "gen.src")
    assert before.ok, messy
    opts = FormatOptions(keyword_case=case)
    once = format_text(messy, opts)
    after = parse_text(once, "gen.src")
    assert after.ok, once
    a, b = build_module(before), build_module(after)
    assert same_tree(a, b, fold_keywords=True), (first_difference(a, b, True), messy, once)
    assert format_text(once, opts) == once, once
    # line ends are kept line by line
    assert once.count("\r\n") == messy.count("\r\n")


# ------------------------------------------------------------------ data lists, written as text

_SP = st.sampled_from(["", " ", "  ", "\t"])
_SP1 = st.sampled_from([" ", "  ", "\t"])


@st.composite
def _number(draw):
    sign = draw(st.sampled_from(["", "-", "+"]))
    if draw(st.booleans()):
        return sign + str(draw(st.integers(0, 99999)))
    return sign + f"{draw(st.floats(0, 1e4, allow_nan=False)):.3f}"


@st.composite
def _value(draw):
    kind = draw(st.sampled_from(["num", "agg", "bool", "str", "enum"]))
    if kind == "num":
        return draw(_number())
    if kind == "bool":
        return draw(st.sampled_from(["TRUE", "false"]))
    if kind == "str":
        return '"' + draw(st.text(st.characters(min_codepoint=32, max_codepoint=126,
                                                blacklist_characters='"'), max_size=6)) + '"'
    if kind == "enum":
        return "#" + draw(st.sampled_from(["base", "TOOL", "x_1"]))
    comps = draw(st.lists(st.sampled_from(["X", "y", "Z", "A", "S", "t"]), min_size=1, max_size=4, unique=True))
    head = draw(st.sampled_from(["", "E6POS:", "FRAME :"]))
    items = [c + draw(_SP1) + draw(_number()) for c in comps]
    sep = draw(_SP) + "," + draw(_SP)
    return "{" + draw(_SP) + head + draw(_SP) + sep.join(items) + draw(_SP) + "}"


@st.composite
def _data_line(draw):
    kind = draw(st.sampled_from(["decl", "plain", "comment", "fold", "blank"]))
    lead = draw(st.sampled_from(["", "  ", "   ", "\t"]))
    name = draw(st.sampled_from(["xp1", "Counter", "gVal", "P_HOME"]))
    if kind == "decl":
        typ = draw(st.sampled_from(["E6POS", "frame", "INT", "MyStruc", "real"]))
        glob = draw(st.sampled_from(["", "GLOBAL "]))
        return f"{lead}DECL {glob}{typ} {name}{draw(_SP)}={draw(_SP)}{draw(_value())}"
    if kind == "plain":
        return f"{lead}int {name}{draw(_SP)}={draw(_SP)}{draw(_number())}"
    if kind == "comment":
        return f"{lead};  a  = {{X 1}} comment"
    if kind == "fold":
        return f"{lead};FOLD section;%{{PE}}\n DECL  INT   kept={draw(_number())}\n;ENDFOLD"
    return lead


@settings(max_examples=examples(40))
@given(st.lists(_data_line(), max_size=8), st.sampled_from(["\n", "\r\n"]))
def test_data_lists_keep_the_ast_and_are_idempotent(body, nl):
    text = "\n".join(["DEFDAT  gen PUBLIC", *body, "ENDDAT", ""]).replace("\n", nl)
    before = parse_text(text, "gen.dat")
    assert before.ok, (text, [e.message for e in before.errors])
    once = format_text(text)
    after = parse_text(once, "gen.dat")
    assert after.ok, once
    a, b = build_module(before), build_module(after)
    assert same_tree(a, b, fold_keywords=True), (first_difference(a, b, True), text, once)
    assert format_text(once) == once, once
    assert once.count("\r\n") == text.count("\r\n")
    for ln in once.splitlines():
        if ln.startswith("DECL") and "{" in ln:
            code = ln.split('"')[0]
            assert ", " not in code and " = " not in code    # data lists are written compact
    kept = [ln for ln in text.split(nl) if "kept=" in ln]
    assert all(ln in once.split(nl) for ln in kept)               # inline-form payload verbatim
