"""A token-level pass over a file's lines: the nesting budget, the expression size limit and
the block structure (IF ... ENDIF and the other block statements, reference 5).

It runs on the lexer's tokens before the parser, and needs no parse tree, so that

* a file nested deeper than ``MAX_NESTING`` (krl/limits.py) is rejected with "nesting too deep"
  at the opener that went past the budget, before the recursive-descent parser (and after it
  the AST builder, the checker and both interpreters) could run out of stack;
* a statement with more than ``MAX_EXPRESSION_TERMS`` operands is rejected at its line;
* a syntax error on a block statement is reported where the block is opened ("missing ENDIF for
  the IF at line 4"), not where the parser noticed it (at END, far below).

Depth counts blocks (IF, FOR, WHILE, REPEAT, LOOP, SWITCH, SPLINE) and, inside a line, brackets
``( [ {`` and prefix operators (NOT, B_NOT, unary ``-``/``+``), each one level. Routines
(DEF, DEFFCT) and data lists are level 0: they cannot nest.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field

from antlr4 import Token

from krl.diagnostics.codes import E010, E011, E018, E019
from krl.limits import MAX_EXPRESSION_TERMS, MAX_NESTING

# opener -> its closer; middle keywords of a block
CLOSER = {"IF": "ENDIF", "FOR": "ENDFOR", "WHILE": "ENDWHILE", "REPEAT": "UNTIL", "LOOP": "ENDLOOP",
          "SWITCH": "ENDSWITCH", "SPLINE": "ENDSPLINE", "DEF": "END", "DEFFCT": "ENDFCT",
          "DEFDAT": "ENDDAT"}
OPENER_OF = {v: k for k, v in CLOSER.items()}
MIDDLE = {"ELSE": "IF", "CASE": "SWITCH", "DEFAULT": "SWITCH"}
ROUTINES = ("DEF", "DEFFCT", "DEFDAT")
_ALIASES = {"PTP_SPLINE": "SPLINE"}

_OPEN = {"(": ")", "[": "]", "{": "}"}
_CLOSE = {v: k for k, v in _OPEN.items()}
_PREFIX = {"NOT", "B_NOT"}
_SIGN = {"+", "-"}
_BINARY = {"+", "-", "*", "/", "AND", "OR", "EXOR", "B_AND", "B_OR", "B_EXOR", "==", "<>", "<", ">",
           "<=", ">=", ":"}


@dataclass(slots=True)
class Tok:
    """A default-channel token: its KRL word (upper-case text or symbolic name), the text,
    1-based line and 1-based column."""

    word: str
    text: str
    line: int
    column: int


@dataclass(slots=True)
class Line:
    number: int
    toks: list[Tok]

    @property
    def keyword(self) -> str:
        """The statement keyword: the first word, after GLOBAL (GLOBAL DEF, GLOBAL INTERRUPT)."""
        words = [t.word for t in self.toks]
        if len(words) > 1 and words[0] == "GLOBAL":
            return _ALIASES.get(words[1], words[1])
        return _ALIASES.get(words[0], words[0]) if words else ""


@dataclass(slots=True)
class Finding:
    """A block-structure or limit finding: code, message, place (1-based), span end column,
    optional note place and text, help; `closer_line` is the line whose token the parser
    would complain about (its errors there are replaced by this finding)."""

    code: str
    message: str
    line: int
    column: int
    end_column: int = 0
    note: tuple[int, int, str] | None = None
    help: str = ""
    closer_line: int = 0


def lines_of(tokens, bundle) -> list[Line]:
    """Group ANTLR tokens (default channel) into lines at NEWLINE tokens."""
    out: list[Line] = []
    cur: list[Tok] = []
    for t in tokens:
        if t.type == Token.EOF:
            break
        if t.channel != Token.DEFAULT_CHANNEL:
            continue
        name = bundle.token_name(t.type)
        if name == "NEWLINE":
            if cur:
                out.append(Line(cur[0].line, cur))
            cur = []
            continue
        text = t.text or ""
        word = text.upper() if text[:1].isalpha() or text[:1] == "_" else text
        if name in ("IDENTIFIER", "SYSNAME", "INTLITERAL", "REALLITERAL", "STRINGLITERAL",
                    "HEXLITERAL", "BINLITERAL", "ENUMLITERAL"):
            word = name
        elif name == "BRAKE_F":
            word = "BRAKE"
        cur.append(Tok(word, text, t.line, t.column + 1))
    if cur:
        out.append(Line(cur[0].line, cur))
    return out


@dataclass(slots=True)
class _Open:
    keyword: str
    line: int
    column: int
    end_column: int
    seen_else: bool = False


@dataclass
class BlockScan:
    """The result of :func:`scan`: the first limit finding (if any) and block findings."""

    limit: Finding | None = None
    blocks: list[Finding] = field(default_factory=list)
    # closer line -> opener line, for closers that matched their opener
    matched: dict[int, int] = field(default_factory=dict)


def _line_limits(line: Line, block_depth: int) -> Finding | None:
    """Brackets and prefix operators of one line on top of `block_depth`; terms per line."""
    frames = [0]          # prefix operators per open bracket level
    depth = block_depth
    terms = 1
    prev = ""
    for i, t in enumerate(line.toks):
        w = t.word
        operand_expected = i == 0 or prev in _OPEN or prev in _BINARY or prev in _PREFIX or prev in (
            ",", "=", "THEN", "TO", "STEP", "WHEN", "FOR", "UNTIL", "WHILE", "SWITCH", "CASE", "RETURN",
            "PTP", "LIN", "CIRC", "SPTP", "SLIN", "SCIRC", "SPL", "SEC", "IF")
        if w in _OPEN:
            depth += 1
            frames.append(0)
            if depth > MAX_NESTING:
                return _too_deep(t)
        elif w in _CLOSE:
            if len(frames) > 1:
                depth -= 1 + frames.pop()
        elif w in _PREFIX or (w in _SIGN and operand_expected):
            frames[-1] += 1
            depth += 1
            if depth > MAX_NESTING:
                return _too_deep(t)
        elif w in _BINARY or w == ",":
            depth -= frames[-1]
            frames[-1] = 0
            if w in _BINARY:
                terms += 1
                if terms > MAX_EXPRESSION_TERMS:
                    return Finding(*E019(limit=MAX_EXPRESSION_TERMS), line.number, line.toks[0].column,
                                   help="split it with intermediate variables")
        prev = w
    return None


def _wrong_closer(kw: str, tok: Tok, top: _Open) -> Finding:
    return Finding(*E011("wrong", kw=kw, opener=top.keyword, line=top.line, closer=CLOSER[top.keyword]),
                   tok.line, tok.column, tok.column + len(tok.text),
                   (top.line, top.column, f"the {top.keyword} opened here"), closer_line=tok.line)


def _too_deep(t: Tok) -> Finding:
    return Finding(*E018(limit=MAX_NESTING),
                   t.line, t.column, t.column + max(len(t.text), 1),
                   help="split the routine or the expression into smaller parts")


def scan(lines: list[Line], limits_only: bool = False) -> BlockScan:
    """Walk the lines once: the nesting budget and expression size (stops at the first finding
    past a limit) and the block structure (`limits_only`: the caller wants the limit only)."""
    res = BlockScan()
    stack: list[_Open] = []

    def depth() -> int:
        return sum(1 for o in stack if o.keyword not in ROUTINES)

    def missing(o: _Open, closer_tok: Tok | None) -> None:
        closer = CLOSER[o.keyword]
        if closer_tok is None:
            note = None
            where = "the end of the file"
        else:
            note = (closer_tok.line, closer_tok.column, f"{closer_tok.text.upper()} reached here "
                                                        f"while the {o.keyword} is open")
            where = f"line {closer_tok.line}"
        res.blocks.append(Finding(*E010(closer=closer, opener=o.keyword, line=o.line),
                                  o.line, o.column, o.end_column, note,
                                  f"add {closer} before {where}",
                                  closer_tok.line if closer_tok is not None else -1))

    for line in lines:
        kw = line.keyword
        first = line.toks[0]
        kw_tok = line.toks[1] if first.word == "GLOBAL" and len(line.toks) > 1 else first
        if kw == "END" and len(line.toks) > 1 and "END" + line.toks[1].word in OPENER_OF:
            kw = "END" + line.toks[1].word  # `END IF`: read as the closer it means
            res.blocks.append(Finding(*E011("two_words", word=line.toks[1].text, kw=kw),
                                      line.number, first.column, line.toks[1].column + len(line.toks[1].text),
                                      closer_line=line.number))
        if kw in CLOSER:
            if kw in ROUTINES:
                for o in reversed(stack):
                    missing(o, kw_tok)
                stack.clear()
            stack.append(_Open(kw, line.number, kw_tok.column, kw_tok.column + len(kw_tok.text)))
            if depth() > MAX_NESTING:
                res.limit = _too_deep(kw_tok)
                return res
        elif kw in OPENER_OF:
            opener = OPENER_OF[kw]
            positions = [i for i, o in enumerate(stack) if o.keyword == opener]
            if positions:
                i = positions[-1]
                for o in reversed(stack[i + 1:]):
                    missing(o, kw_tok)
                res.matched[line.number] = stack[i].line
                del stack[i:]
            elif kw in ("END", "ENDFCT", "ENDDAT") and any(o.keyword in ROUTINES for o in stack):
                while stack[-1].keyword not in ROUTINES:
                    missing(stack.pop(), kw_tok)
                top = stack.pop()
                res.blocks.append(_wrong_closer(kw, kw_tok, top))
            elif stack and stack[-1].keyword not in ROUTINES:
                res.blocks.append(_wrong_closer(kw, kw_tok, stack.pop()))
            else:
                res.blocks.append(Finding(*E011(kw=kw, opener=opener), line.number,
                                          kw_tok.column, kw_tok.column + len(kw_tok.text),
                                          closer_line=line.number))
        elif kw in MIDDLE:
            opener = MIDDLE[kw]
            inner = next((o for o in reversed(stack) if o.keyword not in ROUTINES), None)
            if inner is None or inner.keyword != opener:
                res.blocks.append(Finding(*E011("outside", kw=kw, article="an" if opener == "IF" else "a",
                                                opener=opener), line.number,
                                          kw_tok.column, kw_tok.column + len(kw_tok.text),
                                          closer_line=line.number))
            elif kw == "ELSE":
                if inner.seen_else:
                    res.blocks.append(Finding(*E011("second_else", line=inner.line),
                                              line.number, kw_tok.column, kw_tok.column + 4,
                                              (inner.line, inner.column, "the IF opened here"),
                                              closer_line=line.number))
                inner.seen_else = True
        found = _line_limits(line, depth())
        if found is not None:
            res.limit = found
            return res
    for o in reversed(stack):
        missing(o, None)
    return res


def first_past_limit(tokens, bundle) -> Finding | None:
    """The first place where the token stream goes past MAX_NESTING or MAX_EXPRESSION_TERMS,
    or None; for the parser's pre-pass (cheap: one walk over the tokens, no recursion)."""
    return scan(lines_of(tokens, bundle), limits_only=True).limit


# ----------------------------------------------------------------------- text pre-filter

_W = r"(?![A-Z0-9_$])"
# A line whose first token may be a block opener: any characters that are no token of their
# own (blanks, characters the lexer rejects) may come before it, so this over-matches.
_LINE_EVENTS = re.compile(
    r"^(?P<routine>[ \t\f]*(?:GLOBAL[ \t\f]+)?(?:DEFFCT|DEFDAT|DEF)" + _W + ")"
    r"|^(?P<closer>[ \t\f]*(?:ENDIF|ENDFOR|ENDWHILE|UNTIL|ENDLOOP|ENDSWITCH|ENDSPLINE|ENDFCT|ENDDAT|END)" + _W + ")"
    r"|^(?P<opener>[^A-Z0-9_$;\n]*(?:GLOBAL[^A-Z0-9_$;\n]*)?(?:IF|FOR|WHILE|REPEAT|LOOP|SWITCH|PTP_SPLINE|SPLINE)" + _W + ")",
    re.IGNORECASE | re.ASCII | re.MULTILINE)
_NEST_CHARS = re.compile(r"[(\[{+\-]|NOT", re.IGNORECASE | re.ASCII)
_TERM_CHARS = re.compile(r"[+\-*/<>=:]|AND|OR", re.IGNORECASE | re.ASCII)


def may_pass_limit(text: str) -> bool:
    """True when `text` might go past MAX_NESTING or MAX_EXPRESSION_TERMS in :func:`scan`
    (a conservative bound from the text alone: False means it cannot).

    A parse engine that runs no token pass of its own (krl/syntax/engines) hands such a file to
    the Python engine. The bound: the block depth at a line is at most the number of opener lines
    since the last routine line, minus one per certain closer line (a closer pops at least one
    open block, a routine line clears them); a line adds at most one level per bracket, sign or
    NOT, and one term per operator character or AND/OR (tests/syntax/test_engines.py checks it
    against :func:`scan` on generated and real files)."""
    t = text.replace("\r\n", "\n").replace("\r", "\n")
    depth = top = 0
    depth_at: list[tuple[int, int]] = []   # (offset of a line, block depth after that line)
    for m in _LINE_EVENTS.finditer(t):
        kind = m.lastgroup
        if kind == "routine":
            depth = 0
        elif kind == "closer":
            depth = max(0, depth - 1)
        else:
            depth += 1
            top = max(top, depth)
        depth_at.append((m.start(), depth))
    if top > MAX_NESTING:
        return True
    # Only a line longer than the room left can go past a limit: one level or term per character.
    room = min(MAX_NESTING - top, MAX_EXPRESSION_TERMS - 1)
    positions = [p for p, _ in depth_at]
    for m in re.finditer(r"^[^\n]{%d,}" % (room + 1), t, re.MULTILINE):
        line = m.group()
        k = bisect.bisect_right(positions, m.start()) - 1
        block = depth_at[k][1] if k >= 0 else 0
        if block + len(_NEST_CHARS.findall(line)) > MAX_NESTING:
            return True
        if len(line) >= MAX_EXPRESSION_TERMS and 1 + len(_TERM_CHARS.findall(line)) > MAX_EXPRESSION_TERMS:
            return True
    return False
