"""Syntax errors in KRL words: a parse result becomes diagnostics with stable codes.

The parser's error data (krl/syntax/errors.py: offending token, expected tokens, the tokens of the
line up to the error) and the block scan (krl/syntax/blocks.py) are turned into messages a KRL
programmer reads without knowing the grammar:

==========  ===========================================================================
E010        ``missing ENDIF for the IF at line 4`` (at the IF; a note where it was noticed)
E011        ``ENDFOR does not close the WHILE at line 24; use ENDWHILE``, ``ELSE outside an IF block``
E012        ``IF needs THEN after the condition``, ``FOR needs TO``
E013        ```==` compares; to assign use `=```, ```=` assigns; to compare use `==```
E014        ``declarations must come before the first statement``
E015        ``this `(` is not closed``, ``string not closed before the end of the line``
E016        ```i` after the end of the statement: ENDFOR stands alone on its line``
E017        ```!` is not KRL; for "not" use NOT``
E018/E019   ``nesting too deep ...``, ``expression too long ...`` (krl/limits.py)
E020        ``unexpected end of file``
E002        any other: ``unexpected `X`; expected a statement, ENDIF or end of line``
==========  ===========================================================================

Lists of alternatives are grouped ("a statement", "an expression", "a name") and hold at most
six entries; tokens are quoted one by one (never glued as ANTLR's "no viable alternative at
input 'INTERRUPT5'"). Every message is at most :data:`krl.limits.MAX_MESSAGE_CHARS` characters long.
"""

from __future__ import annotations

import re
from pathlib import Path

from krl.diagnostics import Diagnostic, Note
from krl.diagnostics.codes import E001, E002, E012, E013, E014, E015, E016, E017, E018, E020
from krl.source import read_source
from krl.terminal import clip
from krl.syntax.blocks import CLOSER, OPENER_OF, MIDDLE, BlockScan, lines_of, scan
from krl.syntax.parse import default_bundle
from krl.syntax.tokens import lex
from krl.syntax.engines import parse_source

MAX_ALTERNATIVES = 6
# `CHAR sReg_01[` of an open array declared in a data list: (type, name)
_OPEN_ARRAY = re.compile(r"\b([A-Za-z_$][A-Za-z0-9_$]*)\s+([A-Za-z_$][A-Za-z0-9_$]*)\s*\[\s*\]")

_STATEMENT = {"ANIN", "ANOUT", "ASYPTP", "BRAKE", "BRAKE_F", "CIRC", "CIRC_REL", "CONFIRM", "CONTINUE",
              "EXIT", "FOR", "GOTO", "HALT", "IF", "INTERRUPT", "LIN", "LIN_REL", "LOOP", "MOVE_EMI",
              "ON_ERROR_PROCEED", "PTP", "PTP_REL", "PTP_SPLINE", "REPEAT", "RESUME", "RETURN", "SCIRC",
              "SCIRC_REL", "SLIN", "SLIN_REL", "SPLINE", "SPTP", "SPTP_REL", "SWITCH", "TRIGGER", "WAIT",
              "WHILE", "SPL", "ASYCANCEL", "ASYCONT", "ASYSTOP"}
_TYPES = {"INT", "REAL", "BOOL", "CHAR", "AXIS", "E3AXIS", "E6AXIS", "FRAME", "POS", "E3POS", "E6POS"}
_DECL = {"DECL", "CONST", "STRUC", "ENUM", "SIGNAL", "EXT", "EXTFCT", "EXTFCTP", "EXTP", "IMPORT",
         "CHANNEL", "GLOBAL"} | _TYPES
_VALUE = {"INTLITERAL", "REALLITERAL", "HEXLITERAL", "BINLITERAL", "STRINGLITERAL", "ENUMLITERAL",
          "TRUE", "FALSE"}
_EXPR_START = _VALUE | {"(", "NOT", "B_NOT", "+", "-", "{", "IDENTIFIER", "SYSNAME"}
_OPERATOR = {"AND", "OR", "EXOR", "B_AND", "B_OR", "B_EXOR", "==", "<>", "<=", ">=", "<", ">", "+", "-",
             "*", "/", ":", ".", "["}
# keywords that are also names where a name is expected (soft keywords)
_SOFT = {"DISTANCE", "IN", "OFF", "ON", "OUT", "PATH", "SEC", "STEP", "DELAY", "PRIO", "TIME_BLOCK",
         "MINIMUM", "MAXIMUM", "ONSTART", "CA", "IS", "ENABLE", "DISABLE", "DIGIN", "CONST_VEL"}
# statements that take nothing after their keyword
_BARE = {"ENDIF", "ENDFOR", "ENDWHILE", "ENDLOOP", "ENDSWITCH", "ELSE", "LOOP", "REPEAT", "EXIT", "HALT",
         "CONTINUE", "RESUME", "END", "ENDFCT", "ENDDAT", "DEFAULT", "ON_ERROR_PROCEED"}
_CLOSERS = set(CLOSER.values()) | set(MIDDLE) | {"UNTIL"}
# statement keyword -> the keywords it needs, in the order they come
_NEEDS = {"IF": ("THEN",), "FOR": ("=", "TO", "STEP"), "WHILE": (), "INTERRUPT": ("DECL", "WHEN", "DO"),
          "TRIGGER": ("WHEN", "DISTANCE", "PATH", "=", "DELAY", "DO", "PRIO"), "WAIT": ("FOR", "SEC"),
          "CIRC": (",", "CA"), "SWITCH": (), "ANIN": ("ON", "OFF", "="), "ANOUT": ("ON", "OFF", "=")}
_WHAT = {"THEN": "after the condition", "TO": "before the end value", "DO": "before the action",
         "WHEN": "before the condition", "DELAY": "after the position", ("FOR", "="): "after the counter"}
# statement keyword -> the words that may come second
_SECOND = {"WAIT": ("FOR", "SEC"), "INTERRUPT": ("DECL", "ON", "OFF", "ENABLE", "DISABLE"),
           "TRIGGER": ("WHEN",), "ANIN": ("ON", "OFF"), "ANOUT": ("ON", "OFF")}
_TOKEN_WORDS = {"INTLITERAL": "an integer", "REALLITERAL": "a number", "STRINGLITERAL": "a string",
                "ENUMLITERAL": "an ENUM value (#NAME)", "HEXLITERAL": "a number", "BINLITERAL": "a number",
                "SYSNAME": "a system variable ($...)", "IDENTIFIER": "a name"}
_LEXER_HINTS = {"!": "`!` is not KRL; for \"not\" use NOT, for \"not equal\" use `<>`",
                "&": "`&` is not KRL; for \"and\" use AND (or B_AND on bits)",
                "|": "`|` is not KRL; for \"or\" use OR (or B_OR on bits)",
                "%": "`%` is not KRL: there is no remainder operator (write `a - (a/b)*b`)",
                "^": "`^` is not KRL: there is no power operator",
                "#": "`#` must be followed directly by the ENUM value's name (`#RED`)",
                "\"": "string not closed before the end of the line",
                "'H": "a number like 'H1F' must be closed with `'` and use only hex digits",
                "'B": "a number like 'B101' must be closed with `'` and use only 0 and 1",
                "'": "`'` is not KRL here: strings use double quotes (\"text\")"}


def q(text: str) -> str:
    """A token quoted for a message: `TEXT`, at most 30 characters."""
    text = text.replace("`", "'")
    if len(text) > 30:
        text = text[:27] + "..."
    return f"`{text}`"


def _shown_token(issue) -> str:
    if issue.offending in ("<EOL>", ""):
        return "end of line"
    if issue.offending == "<EOF>":
        return "end of file"
    return q(issue.offending)


def expected_phrase(expected: list[str]) -> str:
    """Expected tokens as at most MAX_ALTERNATIVES grouped phrases: 'THEN', 'a statement', ..."""
    exp = set(expected)
    groups: list[str] = []
    rest = set(exp)
    if "IDENTIFIER" in exp or "SYSNAME" in exp:
        rest -= _SOFT
    if len(exp & _STATEMENT) >= 3:
        groups.append("a statement")
        rest -= _STATEMENT | {"IDENTIFIER", "SYSNAME", "GLOBAL"}
    if len((exp & _DECL) - _TYPES) >= 2:
        groups.append("a declaration")
        rest -= _DECL | {"IDENTIFIER", "SYSNAME"}
    elif len(exp & _TYPES) >= 3:
        groups.append("a type")
        rest -= _TYPES
    if len(exp & _EXPR_START) >= 4:
        groups.append("an expression")
        rest -= _EXPR_START
    elif exp & _VALUE and len(exp & _VALUE) >= 3:
        groups.append("a value")
        rest -= _VALUE | {"+", "-", "{"}
    if "IDENTIFIER" in rest or "SYSNAME" in rest:
        groups.append("a name" if "IDENTIFIER" in rest else "a system variable ($...)")
        rest -= {"IDENTIFIER", "SYSNAME"}
    if len(rest & _OPERATOR) >= 4:
        groups.append("an operator")
        rest -= _OPERATOR
    keywords = sorted(t for t in rest if t not in ("NEWLINE", "<EOF>", "<end of rule>"))
    # closers first: they say which block is open
    keywords.sort(key=lambda t: (t not in _CLOSERS, t))
    words = []
    for k in keywords:
        w = _TOKEN_WORDS.get(k, q(k))
        if w not in words and w not in groups:
            words.append(w)
    groups += words
    if "NEWLINE" in rest:
        groups.append("end of line")
    if "<EOF>" in rest:
        groups.append("end of file")
    if len(groups) > MAX_ALTERNATIVES:
        groups = groups[:MAX_ALTERNATIVES - 1] + ["..."]
    if not groups:
        return ""
    if len(groups) == 1:
        return groups[0]
    return ", ".join(groups[:-1]) + " or " + groups[-1]


class _File:
    """The line tokens and block scan of one file, made only when it has syntax errors."""

    def __init__(self, text: str, bundle, tokens: list | None = None) -> None:
        self.lines = {ln.number: ln for ln in lines_of(lex(text, bundle) if tokens is None else tokens, bundle)}
        self.scan: BlockScan = scan(list(self.lines.values()))


def syntax_diagnostics(result, text: str, bundle=None, tokens: list | None = None) -> list[Diagnostic]:
    """The diagnostics of a ParseResult's syntax errors (cascades left out), in KRL words.

    `text` is the decoded source the result was parsed from; `tokens`: its token stream when
    the caller has it (krl/syntax/engines/tree.py ``stream_tokens``), else it is lexed here.
    Never raises: a message that cannot be worded better keeps the generic E002 form.
    """
    issues = [e for e in result.errors if not e.cascade]
    if not issues:
        return []
    path = result.path
    out: list[Diagnostic] = []
    for e in issues:
        if e.kind == "limit":
            # a limit the block scan found before parsing (krl/syntax/parse.py): its code and words
            out.append(Diagnostic(path, e.line, e.column + 1, e.offending_type or E018, e.message))
    if out:
        return out
    try:
        f = _File(text, bundle or default_bundle(), tokens)
    except Exception:  # noqa: BLE001 - fall back to the parser's words
        f = None
    taken_lines: set[int] = set()
    if f is not None:
        for b in f.scan.blocks:
            notes = [Note(path, b.note[0], b.note[1], b.note[2])] if b.note else []
            out.append(Diagnostic(path, b.line, b.column, b.code, clip(b.message),
                                  end_line=b.line if b.end_column else 0, end_column=b.end_column,
                                  notes=notes, help=b.help))
            taken_lines.add(b.closer_line)
    for e in issues:
        if e.line in taken_lines or (e.offending == "<EOF>" and -1 in taken_lines):
            continue  # the block scan says it better, at the opener
        if f is not None and _closer_follow_on(e, f):
            continue
        try:
            d = _describe(path, e, f)
        except Exception:  # noqa: BLE001
            d = Diagnostic(path, e.line, e.column + 1, *E002(detail=clip(e.message)))
        out.append(d)
    out.sort(key=lambda d: (d.line, d.column))
    return out


def _closer_follow_on(e, f: _File) -> bool:
    """An error on a block closer (ENDIF, ...) that the block scan matched with its opener:
    the opener's own line failed, and that error is the one to read."""
    first = e.line_shape[0] if e.line_shape else ""
    return len(e.line_shape) == 1 and (first in OPENER_OF or first in MIDDLE) and e.line in f.scan.matched


def _describe(path: str, e, f: _File | None) -> Diagnostic:
    col = e.column + 1
    tok = e.offending
    shape = [s for s in e.line_shape]
    line = f.lines.get(e.line) if f is not None else None
    kw = line.keyword if line is not None else (shape[0] if shape else "")
    exp = set(e.expected)
    end = col + len(tok) if tok not in ("<EOL>", "<EOF>", "") else col + 1

    def diag(code: str, message: str, column: int = col, end_column: int = end, help: str = "") -> Diagnostic:
        return Diagnostic(path, e.line, column, code, clip(message), end_line=e.line,
                          end_column=end_column, help=help)

    if e.kind == "lexer":
        ch = tok[:1]
        if ch == "'":
            after = e.message.partition("at: '")[2][1:2].upper()
            ch = "'" + after if after in ("H", "B") else ch
        if ch in _LEXER_HINTS:
            hint = _LEXER_HINTS[ch]
            return diag(*(E015(detail=hint) if ch == '"' else E017("hint", detail=hint)), end_column=col + 1)
        return diag(*E017(char=q(ch) if ch.isprintable() and ch.strip() else repr(ch)), end_column=col + 1)
    upper = tok.upper()
    prev = shape[-2] if len(shape) >= 2 else ""
    # `==` / `=` confused
    if tok == "==" and len(shape) >= 2 and kw not in ("IF", "WHILE", "UNTIL", "WAIT"):
        return diag(*E013())
    if tok in ("<>", "<", ">", "<=", ">=") and len(shape) == 2 and shape[0] in ("id", "$sys"):
        return diag(*E013("comparison", op=q(tok)))
    if tok == "=" and kw in ("IF", "WHILE", "UNTIL", "SWITCH", "CASE") or (
            tok == "=" and shape[:2] == ["WAIT", "FOR"]):
        return diag(*E013("condition"))
    if tok == "=" and prev == ":":
        return diag(*E013("pascal"), column=col - 1)
    if tok == "+" and len(shape) == 2 and shape[0] in ("id", "$sys"):
        return diag(*E013("increment"))
    # declarations after statements
    if upper in _DECL and len(shape) == 1 and ("a statement" in expected_phrase(e.expected)
                                                or exp & {"ENDSPLINE", "SPL", "SLIN"}):
        return diag(*E014(),
                    help="move the declaration up, above the routine's first statement")
    # an array declared in a data list without its size (`CHAR sReg_01[]`): KRL gives a size to
    # every array but a parameter's (reference 3.3 [D]: "sizes are integer constants"); the
    # controller's compiler rejects it in .dat files as in .src files (issue 63, grammar/CHANGES.md)
    if tok == "]" and prev == "[" and "dataList" in e.rule_stack and shape and shape[0] in _DECL:
        m = _OPEN_ARRAY.search(e.line_text or "")
        if m is not None:
            example = f"{m.group(1)} {m.group(2)}[24]" if m.group(1).upper() in _TYPES else f"{m.group(2)}[24]"
            return diag(*E002("open_array", name=q(m.group(2)), example=q(example)))
    # unclosed / unbalanced brackets on the line
    if line is not None:
        b = _bracket_problem(line, e)
        if b is not None:
            return b if b.path else Diagnostic(path, b.line, b.column, b.code, b.message,
                                               end_line=b.line, end_column=b.column + 1)
    # a failed semantic predicate of the grammar: its message is already in KRL words
    if " takes " in e.message and not e.message.startswith(("extraneous", "mismatched", "no viable")):
        return diag(*E012(detail=e.message.split(" ", 2)[2] if e.message.startswith("rule ") else e.message))
    # the second word of a statement
    position = len(shape) - 1 - (1 if shape and shape[0] == "GLOBAL" else 0)
    if kw in _SECOND and position == 1 and upper not in _SECOND[kw]:
        words = _SECOND[kw]
        listed = words[0] if len(words) == 1 else ", ".join(words[:-1]) + " or " + words[-1]
        return diag(*E012("second_word", kw=kw, listed=listed, found=_shown_token(e)))
    # a keyword the statement needs
    needs = _NEEDS.get(kw, ())
    missing = [k for k in needs if k in exp and k != upper]
    if missing and not (exp & _STATEMENT and len(exp & _STATEMENT) > 3):
        k = missing[0]
        what = _WHAT.get((kw, k), _WHAT.get(k, ""))
        if kw == "WAIT" and set(missing) >= {"FOR", "SEC"}:
            return diag(*E012("wait"))
        found = "" if tok in ("<EOL>", "") else f", found {_shown_token(e)}"
        return diag(*E012("keyword", kw=kw, keyword=k if k.isalpha() else q(k), what=f" {what}" if what else "",
                          found=found))
    if tok == "<EOF>":
        phrase = expected_phrase(e.expected)
        return diag(*E020(expected=f"; expected {phrase}" if phrase else ""))
    # text after a complete statement
    if exp <= {"NEWLINE", "<EOF>"} and exp and tok not in ("<EOL>",):
        if kw in _BARE and len(shape) >= 2 and shape[0] == kw:
            return diag(*E016("alone", token=_shown_token(e), kw=kw))
        return diag(*E016(token=_shown_token(e)))
    # two words written as one: INTERRUPT5, GLOBALSTRUC (the lexer reads one name)
    if line is not None and line.toks and line.toks[0].word == "IDENTIFIER" and e.line == line.toks[0].line:
        glued = _glued(line.toks[0].text)
        if glued is not None:
            t = line.toks[0]
            code, message = E002("glued", text=q(t.text), fix=q(glued[0] + ' ' + glued[1]))
            return Diagnostic(path, e.line, t.column, code, clip(message),
                              end_line=e.line, end_column=t.column + len(t.text),
                              help=f"KRL needs a space after {glued[0]}")
    # a bare name on its own line: a call without parentheses (withdrawn, grammar/CHANGES.md) or
    # a placeholder such as TODO
    if (tok == "<EOL>" and line is not None and len(line.toks) == 1 and shape[:1] == ["id"]
            and line.toks[0].word == "IDENTIFIER"):
        t = line.toks[0]
        code, message = E012("bare_name", name=q(t.text), call=q(t.text + '()'))
        return Diagnostic(path, e.line, t.column, code, clip(message),
                          end_line=e.line, end_column=t.column + len(t.text),
                          help=f"if it is a note (like TODO), make it a comment: `;{t.text}`")
    # a missing expression
    phrase = expected_phrase(e.expected)
    if tok == "<EOL>":
        if phrase == "an expression" or "an expression" in phrase:
            after = q(shape[-2]) if len(shape) >= 2 and shape[-2].isupper() else "here"
            return diag(*(E012("expression_after", after=after) if after != "here" else E012("expression")))
        return diag(*E002("ends_early", expected=f"; expected {phrase}" if phrase else ""))
    if "a statement" in phrase and position > 0:
        phrase = ""  # the parser gave up on the whole line: its list is the line-start set
    after = ""
    if len(shape) >= 2 and shape[-2] not in ("id", "num", "str", "$sys", "#enum") and "…" not in shape[-2]:
        after = f" after {q(shape[-2])}"
    return diag(*E002("unexpected", token=_shown_token(e), after=after, expected=f"; expected {phrase}" if phrase else ""))


_GLUE_KEYWORDS = sorted(_STATEMENT | _DECL | {"DEF", "DEFFCT", "DEFDAT", "DECL"}, key=len, reverse=True)


def split_glued(text: str) -> tuple[str, str] | None:
    """(keyword, rest) of a keyword glued to a number or a keyword (see :func:`_glued`): the
    language server's quick fix inserts the space the E002 help asks for."""
    return _glued(text)


def _glued(text: str) -> tuple[str, str] | None:
    """(keyword, rest) when `text` is a keyword glued to a number or to another keyword
    (``INTERRUPT5`` -> INTERRUPT 5, ``GLOBALSTRUC`` -> GLOBAL STRUC), else None."""
    upper = text.upper()
    for k in _GLUE_KEYWORDS:
        rest = upper[len(k):]
        if upper.startswith(k) and rest and (rest.isdigit() or rest in _STATEMENT or rest in _DECL):
            return text[:len(k)], text[len(k):]
    return None


def _bracket_problem(line, e) -> Diagnostic | None:
    """An unclosed or extra bracket on the error's line, before or at the error."""
    pairs = {"(": ")", "[": "]", "{": "}"}
    closing = {v: k for k, v in pairs.items()}
    stack = []
    limit_col = e.column + 1
    for t in line.toks:
        if t.column > limit_col:
            break
        if t.word in pairs:
            stack.append(t)
        elif t.word in closing:
            if stack and stack[-1].word == closing[t.word]:
                stack.pop()
            elif t.column == limit_col:
                return Diagnostic("", t.line, t.column, *E015("no_opening", bracket=q(t.text),
                                                               opening=q(closing[t.word])))
    unclosed = []
    for t in line.toks:
        if t.word in pairs:
            unclosed.append(t)
        elif t.word in closing and unclosed and unclosed[-1].word == closing[t.word]:
            unclosed.pop()
    if unclosed and stack and unclosed[-1] in stack:
        t = unclosed[-1]
        return Diagnostic("", t.line, t.column, *E015("not_closed", bracket=q(t.text), closing=q(pairs[t.word]),
                                                       token=_shown_token(e)))
    return None


def file_diagnostics(path: Path, keep_tree: bool = True):
    """(ParseResult, decoded text, diagnostics) of one file; never raises for bad content.
    The default parse engine (krl/syntax/engines) parses it; with keep_tree the result has its
    parse tree (the java engine's is rebuilt from its data, the same tree)."""

    src = read_source(path)
    result = parse_source(src, keep_tree=keep_tree)
    return result, src.text, source_diagnostics(src, result)


def source_diagnostics(src, result, worded: list[Diagnostic] | None = None) -> list[Diagnostic]:
    """The diagnostics `krl parse` prints for a decoded file (SourceText) and its ParseResult:
    the syntax errors in KRL words (krl/syntax/messages.py; `worded` when the caller already
    has them for this result), else, when the file was not parsed, one E001 naming why
    (``file not parsed: binary``, ``... too_large (N bytes > M)``). Never raises."""
    diags = worded if worded is not None else syntax_diagnostics(result, src.text)
    if not result.ok and not diags:
        detail = f" ({src.detail})" if src.detail else ""
        diags = [Diagnostic(src.path, 1, 1, *E001(why=f"{result.status}{detail}"))]
    return diags
