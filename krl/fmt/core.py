"""`krl fmt`: the KRL formatter, working on the ANTLR token stream and parse tree.

What it changes, line by line (reference 1.1-1.6 for the lexical rules it relies on):

* **Indentation** of code lines: one level (``FormatOptions.indent``, default three spaces)
  per enclosing block -- DEF/DEFFCT bodies, IF/ELSE/ENDIF, FOR, WHILE, LOOP, REPEAT/UNTIL,
  SWITCH (CASE/DEFAULT one level in, their statements two), SPLINE/PTP_SPLINE, and a plain
  ``;FOLD`` opened inside a routine. ELSE, CASE and DEFAULT sit at their block's level; labels
  at the level of the statements. DEFDAT contents start in column 1, as KUKA writes data lists.
  A full comment line indented exactly like the code line after it (or else before it) moves
  with that line; other comment lines (column 1, aligned with something else) stay.
* **Keyword case** (``keyword_case``: ``"upper"``, KUKA's spelling and the default; ``"lower"``;
  ``"keep"``). Only reserved words change; names (identifiers, $system names, #enum literals,
  and keywords used as structure components or enum values: ``ON``, ``OFF``, ``IN`` ...) keep
  the case their author wrote, since KRL names are case-insensitive (1.1) and the case is a
  person's choice.
* **Spacing** between the tokens of a code line, the corpus' majority per file (measured on the
  .src/.sub files of ../shared/krl-corpus outside inline forms, one vote per file):
  one space around ``=`` (193 files spaced, 98 compact), relational operators (128:94) and
  arithmetic operators (63:60, spaced for consistency); none around the geometric operator
  ``:`` (95% of its uses: ``$BASE:XP1``); none after a unary ``-``/``+``; ``{X 10, Y 20}`` in
  routine aggregates (41:25); no blank after the commas of argument lists, indices and
  declarations (``F(a,b)``, ``a[i,j]``; 175:73); none inside ``()``, ``[]``, ``{}``; none between
  a name and its ``(`` or ``[``; one elsewhere. Data lists (DEFDAT) are written compact as the
  smartPAD writes them: ``DECL E6POS XP1={X 10,Y 20}`` (95% of ``=`` and 99.7% of aggregate
  commas in the corpus' .dat files). Parameter modes (``a :IN`` / ``a:IN``, split evenly in the
  corpus), CHANNEL and IMPORT declarations keep the author's choice, collapsed to one blank or
  none. Trailing blanks of code lines and whitespace-only lines are removed.

What it never changes: comments (also their position after code: the blank run before a
trailing comment is kept), full comment lines, ``;FOLD`` / ``;ENDFOLD`` lines, every line of a
folded inline form (a FOLD whose line carries a ``%{...}`` marker, e.g.
``;FOLD PTP P1 ...;%{PE}%R 8.3.31,%MKUKATPBASIS,...``, down to its ENDFOLD, nested folds
included: the smartPAD regenerates those lines and expects their exact text), ``&`` header
lines, blank lines (their number), string literals, literals' spelling, line ends (CRLF, LF
and CR per line), a leading byte order mark and a missing final line end.

A file that does not parse is never formatted: :func:`format_text` raises
:class:`FormatSyntaxError`. After formatting, the result is lexed again and its token stream
must equal the input's (keyword case aside); a difference raises :class:`FormatSafetyError`
instead of returning changed meaning.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from krl.diagnostics.codes import E001, E002
from krl.syntax.messages import syntax_diagnostics
from krl.syntax.parse import ParseResult, ParserBundle, default_bundle, keyword_types, parse_text
from krl.syntax.tokens import DEFAULT_CHANNEL, EOF, is_rule, is_token_node, lex, rule_name

__all__ = ["FormatOptions", "FormatError", "FormatSyntaxError", "FormatSafetyError", "format_text",
           "format_parsed"]

KeywordCase = Literal["upper", "lower", "keep"]


@dataclass(frozen=True, slots=True)
class FormatOptions:
    """How :func:`format_text` formats.

    keyword_case: "upper" (default, KUKA's spelling), "lower" or "keep".
    indent: the text of one indentation level (default three spaces, the corpus' most common
        step; a tab is allowed).
    indent_case: CASE/DEFAULT one level inside SWITCH (default True, the corpus' majority).
    indent_data: indent the contents of a DEFDAT (default False: KUKA's data lists start every
        line in column 1).
    indent_folds: the statements inside a plain ``;FOLD`` (not an inline form) of a routine one
        level deeper (default True: 127 of the corpus' 170 files with such folds do so).
    """

    keyword_case: KeywordCase = "upper"
    indent: str = "   "
    indent_case: bool = True
    indent_data: bool = False
    indent_folds: bool = True

    def __post_init__(self) -> None:
        if self.keyword_case not in ("upper", "lower", "keep"):
            raise ValueError(f"keyword_case must be upper, lower or keep, not {self.keyword_case!r}")
        if self.indent.strip(" \t") != "":
            raise ValueError("indent must be spaces or tabs")


class FormatError(Exception):
    """Base class of the formatter's errors; the text is left unformatted."""


@dataclass
class SyntaxProblem:
    """One reason a text does not parse: 1-based line and column, a message."""

    line: int
    column: int
    message: str
    code: str = E002


class FormatSyntaxError(FormatError):
    """The text does not parse (syntax or lexer error, or past a limit of krl/limits.py);
    `problems` lists them (1-based line and column), `result` is the ParseResult and
    `diagnostics` its syntax errors as `krl parse` words them (krl/syntax/messages.py
    ``syntax_diagnostics``, named by the `path` given to :func:`format_text`; empty when none
    could be worded), so that a caller prints them without parsing the text again."""

    def __init__(self, problems: list[SyntaxProblem], result: ParseResult | None = None,
                 diagnostics: list | None = None):
        self.problems = problems
        self.result = result
        self.diagnostics = diagnostics if diagnostics is not None else []
        first = problems[0] if problems else SyntaxProblem(1, 1, "does not parse")
        super().__init__(f"{first.line}:{first.column}: {first.message}")


class FormatSafetyError(FormatError):
    """The formatted text would not lex to the same tokens (a formatter bug); nothing is
    returned rather than a changed program."""


# ---------------------------------------------------------------------------- token roles

# Roles of default-channel tokens, decided from the parse tree.
BINOP = "binop"          # binary operator, relational operator, AND/OR/...
GEO = "geo"              # the geometric operator ':'
UNARY = "unary"          # unary - + NOT B_NOT, the sign of a data-list constant
ASSIGN = "assign"        # '=' of an assignment, FOR, WITH, DELAY=, an initial value
NAME = "name"            # a keyword used as a name (structure component, enum value, FRAME as a variable)
CALL_OPEN = "call("      # '(' after a routine name (call, DEF, DEFFCT, EXT)
KEEP = "keep"            # spacing kept as written (collapsed to one space or none)
TIGHT = "tight"          # no spaces around (open dimensions [,])
AGG_COLON = "aggcolon"   # '{E6POS: X 1}' type colon
LABEL_COLON = "labelcolon"
AGG_COMMA = "aggcomma"   # ',' between aggregate components
_OPS = frozenset((BINOP, GEO, ASSIGN))

_BINARY_LABELS = frozenset(("multiplicativeExpression", "additiveExpression", "andExpression",
                            "exorExpression", "orExpression", "relationalExpression"))
_KEEP_RULES = frozenset(("channelDeclaration", "importDeclaration", "parameter", "externalParameter"))

_OPENERS = frozenset(("IF", "FOR", "WHILE", "LOOP", "REPEAT", "SWITCH", "SPLINE", "PTP_SPLINE",
                      "DEF", "DEFFCT", "DEFDAT"))
_CLOSERS = {"ENDIF": "IF", "ENDFOR": "FOR", "ENDWHILE": "WHILE", "ENDLOOP": "LOOP", "UNTIL": "REPEAT",
            "ENDSWITCH": "SWITCH", "ENDSPLINE": "SPLINE", "END": "DEF", "ENDFCT": "DEFFCT",
            "ENDDAT": "DEFDAT"}

_WORDISH = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_$#'\"")
_OPCHARS = frozenset("<>=")


def _roles(tree) -> dict[int, str]:
    """token index -> role, for the tokens whose spacing depends on their place in the tree."""
    roles: dict[int, str] = {}
    stack = [tree]
    while stack:
        ctx = stack.pop()
        rule = rule_name(ctx)
        kids = ctx.children or ()
        for i, c in enumerate(kids):
            if is_rule(c):
                stack.append(c)
                continue
            if not is_token_node(c):
                continue
            tok = c.symbol
            text = tok.text
            role = None
            if rule in _BINARY_LABELS and i == 1:
                role = BINOP
            elif rule == "geometricExpression" and i == 1:
                role = GEO
            elif rule == "unaryExpression" and i == 0:
                role = UNARY
            elif rule == "constantValue" and text in ("-", "+"):
                role = UNARY
            elif text == "=":
                role = ASSIGN
            elif rule in ("contextKeyword", "name"):
                role = NAME       # a keyword token standing as a name (FRAME as a variable, 1.6)
            elif rule in _KEEP_RULES and text != "(" and text != ")" and text != ",":
                role = KEEP if text in (":", "/", "..", "[", "]") else None
            elif rule == "openDimensions":
                role = TIGHT
            elif text == "(" and rule in ("call", "procedureDefinition", "functionDefinition",
                                          "externalDeclaration"):
                role = CALL_OPEN
            elif text == ":" and rule in ("aggregate", "constantAggregate"):
                role = AGG_COLON
            elif text == "," and rule in ("aggregate", "constantAggregate"):
                role = AGG_COMMA
            elif text == ":" and rule == "label":
                role = LABEL_COLON
            elif rule == "channelDeclaration":
                role = KEEP
            if role is not None:
                roles[tok.tokenIndex] = role
    return roles


# ---------------------------------------------------------------------------- spacing


def _gap(a, b, ra: str | None, rb: str | None, original: str, data: bool) -> str:
    """The blank between two adjacent default-channel tokens a, b of one code line; `data`:
    the line is in a data list (DEFDAT), written compact as KUKA writes data lists."""
    ta, tb = a.text, b.text
    if ra == KEEP or rb == KEEP:
        want = " " if original else ""
    elif ra == TIGHT or rb == TIGHT:
        want = ""
    elif ra in _OPS or rb in _OPS:
        op = ta if ra in _OPS else tb
        if op[:1].isalpha():
            want = " "                                    # AND, OR, EXOR, B_AND, ...
        elif GEO in (ra, rb):
            want = ""                                     # p1:p2
        else:
            want = "" if data else " "                    # a = b + 1; DECL INT n=3
    elif ra == UNARY:
        want = " " if ta[:1].isalpha() else ""            # NOT x, B_NOT x; -x
    elif ra == AGG_COMMA:
        want = "" if data else " "                        # {X 10, Y 20}; {X 10,Y 20}
    elif tb in (",", ")", "]", "}") or ta in ("(", "[", "{", ","):
        want = ""                                         # f(a,b), a[i,j], (x)
    elif ta == "." or tb == "." or tb == "[" or rb in (CALL_OPEN, AGG_COLON, LABEL_COLON):
        want = ""                                         # p.x, a[1], f(, {E6POS: ...}, L1:
    else:
        want = " "
    if want == "" and _would_merge(ta, tb):
        want = " "
    return want


def _would_merge(ta: str, tb: str) -> bool:
    """True when writing `ta` and `tb` without a blank could lex differently."""
    la, fb = ta[-1:], tb[:1]
    if la in _WORDISH and fb in _WORDISH:
        return True
    if la in _OPCHARS and fb in _OPCHARS:
        return True
    if la == "." and (fb == "." or fb.isdigit()):
        return True                                       # '..', '.5'
    return la.isdigit() and fb == "."                     # '1.'


# ---------------------------------------------------------------------------- formatting


def _syntax_error(result: ParseResult, text: str) -> FormatSyntaxError:
    """The error for a text that does not parse: its syntax errors as `krl parse` words them
    (krl/syntax/messages.py: codes E0xx), worded once."""

    diags = syntax_diagnostics(result, text)
    out = [SyntaxProblem(d.line, d.column, d.message, d.code) for d in diags]
    if not out:
        out = [SyntaxProblem(e.line, e.column + 1, e.message, E002) for e in result.errors]     # the parser's words
    if not out:
        code, message = E001(why=result.status)
        out.append(SyntaxProblem(1, 1, message, code))
    return FormatSyntaxError(out, result, diags)


def format_text(text: str, options: FormatOptions | None = None, path: str = "<fmt>") -> str:
    """Format KRL source text (one .src/.sub/.dat file) and return the new text.

    `text` is the decoded file (krl.source.decode_bytes); a leading U+FEFF (BOM) is
    kept. `path` names the file in the diagnostics of a FormatSyntaxError. Returns `text`
    itself when nothing changes. Idempotent: ``format_text(format_text(t)) == format_text(t)``.
    The text is parsed once.

    Raises FormatSyntaxError when the text does not parse (nothing is formatted; it carries
    the parse result and its diagnostics), and FormatSafetyError if the result would not lex
    to the same tokens (a formatter bug).
    """
    options = options or FormatOptions()
    bom = ""
    body = text
    if body.startswith("\ufeff"):
        bom, body = "\ufeff", body[1:]
    added_newline = bool(body) and not body.endswith(("\n", "\r"))
    prepared = body + "\n" if added_newline else body
    result = parse_text(prepared, path)
    if not result.ok or result.tree is None:
        raise _syntax_error(result, prepared)
    out = format_parsed(prepared, result, options)
    if added_newline and out.endswith("\n"):
        out = out[:-1]
    new = bom + out
    return text if new == text else new


def format_parsed(text: str, result: ParseResult, options: FormatOptions) -> str:
    """Format `text` given its successful ParseResult (the tree kept); see :func:`format_text`."""
    tree = result.tree
    parser = tree.parser
    bundle = default_bundle()
    tokens = parser.getTokenStream().tokens
    kw = keyword_types(bundle)
    roles = _roles(tree)
    sym = bundle.symbolic
    NL = bundle.lexer_cls.NEWLINE
    FOLD, ENDFOLD, HEADER = bundle.lexer_cls.FOLD, bundle.lexer_cls.ENDFOLD, bundle.lexer_cls.HEADER

    def case(tok) -> str:
        if options.keyword_case == "keep" or tok.type not in kw or roles.get(tok.tokenIndex) == NAME:
            return tok.text
        return tok.text.upper() if options.keyword_case == "upper" else tok.text.lower()

    out: list[str] = []
    blocks: list[str] = []       # open blocks, innermost last ("IF", "SWITCH", "CASE", ...)
    folds: list[tuple[bool, int | None]] = []   # open FOLDs: (plain, the routine it opened in)
    routine = [0, None]          # [routines opened so far, the id of the open DEF/DEFFCT or None]
    verbatim_from = 0            # 0: not in an inline form; else the fold depth that opened one
    line_start = 0               # char index where the current line starts
    line: list = []              # tokens of the current line (all channels, no NEWLINE)

    def depth() -> int:
        return sum(1 for b in blocks if b != "SWITCH0")

    def emit(line_tokens: list, nl_tok) -> None:
        nonlocal verbatim_from, line_start
        end = nl_tok.start if nl_tok is not None else len(text)
        raw = text[line_start:end]
        newline = nl_tok.text if nl_tok is not None else ""
        code = [t for t in line_tokens if t.channel == DEFAULT_CHANNEL]
        hidden = [t for t in line_tokens if t.channel != DEFAULT_CHANNEL]
        verbatim = verbatim_from > 0
        # block structure, from the line's first word (the file parses, so this is exact)
        first = sym[code[0].type] if code else ""
        if first == "GLOBAL" and len(code) > 1:
            first = sym[code[1].type]
        level = depth()
        if first in _CLOSERS:
            want = _CLOSERS[first]
            if want == "SWITCH" and blocks and blocks[-1] == "CASE":
                blocks.pop()
            if want == "SWITCH" and blocks and blocks[-1] == "SWITCH0":
                want = "SWITCH0"
            if want == "SPLINE" and blocks and blocks[-1] == "PTP_SPLINE":
                want = "PTP_SPLINE"
            if want == "DEF" and blocks and blocks[-1] == "DEFFCT":
                want = "DEFFCT"
            if blocks and blocks[-1] == want:
                blocks.pop()
            level = depth()
        elif first == "ELSE":
            level = depth() - 1
        elif first in ("CASE", "DEFAULT"):
            if blocks and blocks[-1] == "CASE":
                blocks.pop()
            level = depth()
            blocks.append("CASE")
        if first in _OPENERS:
            blocks.append("SWITCH0" if first == "SWITCH" and not options.indent_case else first)
            if first in ("DEF", "DEFFCT"):
                routine[0] += 1
                routine[1] = routine[0]
        if "DEF" not in blocks and "DEFFCT" not in blocks:
            routine[1] = None
        if options.indent_folds and routine[1] is not None:
            # the statements of a plain FOLD opened in this routine sit one level deeper
            level += sum(1 for plain, rid in folds if plain and rid == routine[1])
        # folds: a FOLD line with a %{..} marker opens an inline form, kept verbatim to its ENDFOLD
        for t in hidden:
            if t.type == FOLD:
                inline = "%{" in t.text
                folds.append((not inline and verbatim_from == 0, routine[1]))
                if verbatim_from == 0 and inline:
                    verbatim_from = len(folds)
                    verbatim = True
            elif t.type == ENDFOLD:
                if verbatim_from and len(folds) == verbatim_from:
                    verbatim_from = 0
                    verbatim = True
                if folds:
                    folds.pop()
        data = "DEFDAT" in blocks
        if data and not options.indent_data:
            level -= 1
        indent_ws = raw[:len(raw) - len(raw.lstrip(" \t\f"))]
        if not line_tokens:
            out.append(["keep", (raw if verbatim else "") + newline, None, ""])
        elif verbatim or line_tokens[0].type in (HEADER, FOLD, ENDFOLD):
            out.append(["keep", raw + newline, None, ""])
        elif not code:
            # a full comment line: its text as written; its indentation follows the code line
            # it was aligned with (decided in the second pass), otherwise stays as it is
            out.append(["comment", raw[len(indent_ws):] + newline, indent_ws, None])
        else:
            parts = [case(code[0])]
            for a, b in zip(code, code[1:]):
                original = text[a.stop + 1:b.start]
                parts.append(_gap(a, b, roles.get(a.tokenIndex), roles.get(b.tokenIndex), original, data))
                parts.append(case(b))
            if hidden:
                # a trailing comment: the blank run before it as written
                c0 = hidden[0]
                parts.append(text[code[-1].stop + 1:c0.start])
                parts.append(text[c0.start:end])
            out.append(["code", "".join(parts) + newline, indent_ws, options.indent * max(level, 0)])
        line_start = nl_tok.stop + 1 if nl_tok is not None else len(text)

    for tok in tokens:
        if tok.type == EOF:
            break
        if tok.type == NL:
            emit(line, tok)
            line = []
        else:
            line.append(tok)
    if line or line_start < len(text):
        emit(line, None)
    formatted = "".join(_place_comments(out))
    _verify(tokens, text, formatted, bundle)
    return formatted


def _nearest_code(lines: list[list], order) -> list[int | None]:
    """For each line, walking `order`, the index of the last code line seen before it (None
    after a kept non-blank line: a fold, header or inline form stops the search)."""
    found: list[int | None] = [None] * len(lines)
    last = None
    for i in order:
        found[i] = last
        kind = lines[i][0]
        if kind == "code":
            last = i
        elif kind == "keep" and lines[i][1].strip():
            last = None
    return found


def _place_comments(lines: list[list]) -> list[str]:
    """Second pass: the text of each line. A full comment line indented exactly like the next
    code line (or else the previous one) moves with it; any other comment line (column 1,
    aligned with something else) keeps its indentation. Blank and comment lines between are
    skipped when looking for that code line; a kept line (fold, header, inline form) stops it."""
    n = len(lines)
    prv = _nearest_code(lines, range(n))
    nxt = _nearest_code(lines, range(n - 1, -1, -1))
    out = []
    for i, (kind, body, old, new) in enumerate(lines):
        if kind == "keep":
            out.append(body)
        elif kind == "code":
            out.append(new + body)
        else:
            indent = old
            for j in (nxt[i], prv[i]):
                if j is not None and lines[j][2] == old:
                    indent = lines[j][3]
                    break
            out.append(indent + body)
    return out


def _signature(tokens, kw: frozenset[int]) -> list[tuple[int, str]]:
    out = []
    for tok in tokens:
        if tok.type == EOF:
            break
        out.append((tok.type, tok.text.upper() if tok.type in kw else tok.text))
    return out


def _verify(tokens, before: str, after: str, bundle: ParserBundle) -> None:
    """The formatted text lexes to the same tokens as the input (`tokens`, its lexed stream),
    each with the same text (keywords up to case): comments, strings, literals and names are
    untouched, and no two tokens were glued or split."""
    if before == after:
        return
    kw = keyword_types(bundle)
    if _signature(tokens, kw) != _signature(lex(after, bundle), kw):
        raise FormatSafetyError("formatting would change the token stream; the text is left as it is")
