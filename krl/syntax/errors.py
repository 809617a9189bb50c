"""Error collection and a line-oriented error recovery for the KRL parser.

KRL is line-oriented (reference 1.4), so the natural unit of recovery is the line: after a
syntax error the parser skips to the end of the line and carries on with the next one. This
keeps one missing construct from turning into a cascade of errors, and lets a scan see every
independent missing construct of a file.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from antlr4 import Token
from antlr4.atn.ATNState import ATNState
from antlr4.error.ErrorListener import ErrorListener
from antlr4.error.ErrorStrategy import DefaultErrorStrategy
from antlr4.error.Errors import InputMismatchException
from antlr4.IntervalSet import IntervalSet

from krl.diagnostics.render import split_lines


@dataclass(slots=True)
class SyntaxIssue:
    """One syntax or lexer error at line:column (1-based line, 0-based column as ANTLR)."""

    line: int
    column: int
    message: str
    offending: str
    expected: list[str]
    rule_stack: list[str]
    kind: str = "syntax"          # "syntax" or "lexer"
    offending_type: str = ""      # symbolic token name, "<EOF>" or "" for lexer errors
    line_shape: list[str] = field(default_factory=list)  # tokens of the line up to the offending one
    line_text: str = ""
    cascade: bool = False          # a follow-on error of an earlier one (not a construct of its own)

    def as_json(self) -> dict:
        return {"line": self.line, "column": self.column, "message": self.message,
                "offending": self.offending, "expected": self.expected,
                "rule_stack": self.rule_stack, "kind": self.kind, "cascade": self.cascade}


_LOOP_STATES = (ATNState.BLOCK_START, ATNState.STAR_BLOCK_START, ATNState.PLUS_BLOCK_START,
                ATNState.STAR_LOOP_ENTRY, ATNState.STAR_LOOP_BACK, ATNState.PLUS_LOOP_BACK)

# Block keywords: an error on a closer whose opener line failed earlier is a follow-on error.
_CLOSER_OF = {"ENDIF": "IF", "ELSE": "IF", "ENDFOR": "FOR", "ENDWHILE": "WHILE", "UNTIL": "REPEAT",
              "ENDLOOP": "LOOP", "ENDSWITCH": "SWITCH", "CASE": "SWITCH", "DEFAULT": "SWITCH",
              "ENDSPLINE": "SPLINE", "END": "DEF", "ENDFCT": "DEFFCT", "ENDDAT": "DEFDAT"}
_OPENER_ALIASES = {"PTP_SPLINE": "SPLINE", "GLOBAL": None}

_NORMALISED = {"IDENTIFIER": "id", "SYSNAME": "$sys", "INTLITERAL": "num", "REALLITERAL": "num",
               "HEXLITERAL": "num", "BINLITERAL": "num", "STRINGLITERAL": "str", "ENUMLITERAL": "#enum"}
_GROUPS = {"(": ")", "[": "]", "{": "}"}


def _newline_type(recognizer) -> int:
    return recognizer.symbolicNames.index("NEWLINE")


class LineErrorStrategy(DefaultErrorStrategy):
    """Report an error, then resynchronise at the end of the offending line."""

    def recoverInline(self, recognizer):
        # No single-token insertion or deletion: they hide errors and bend the tree.
        raise InputMismatchException(recognizer)

    def recover(self, recognizer, e):
        stream = recognizer.getTokenStream()
        if (self.lastErrorIndex == stream.index and self.lastErrorStates is not None
                and recognizer.state in self.lastErrorStates and stream.LA(1) != Token.EOF):
            recognizer.consume()  # no progress since the last error here: force it
        self.lastErrorIndex = stream.index
        if self.lastErrorStates is None:
            self.lastErrorStates = IntervalSet()
        self.lastErrorStates.addOne(recognizer.state)
        self._skip_line(recognizer)

    def sync(self, recognizer):
        if self.inErrorRecoveryMode(recognizer):
            return
        state = recognizer._interp.atn.states[recognizer.state]
        if state.stateType not in _LOOP_STATES:
            return
        stream = recognizer.getTokenStream()
        la = stream.LA(1)
        if la == Token.EOF:
            return
        next_tokens = recognizer.atn.nextTokens(state)
        if la in next_tokens:
            return
        if Token.EPSILON in next_tokens and la in recognizer.getExpectedTokens():
            return
        # A token that can neither continue nor end this list: report it, skip the line.
        self.beginErrorCondition(recognizer)
        token = recognizer.getCurrentToken()
        expecting = self.getExpectedTokens(recognizer)
        msg = ("extraneous input " + self.getTokenErrorDisplay(token) + " expecting "
               + expecting.toString(recognizer.literalNames, recognizer.symbolicNames))
        recognizer.notifyErrorListeners(msg, token, None)
        self._skip_line(recognizer)
        self.endErrorCondition(recognizer)

    def _skip_line(self, recognizer):
        newline = _newline_type(recognizer)
        stream = recognizer.getTokenStream()
        while stream.LA(1) not in (Token.EOF, newline):
            recognizer.consume()


def line_end_lexer(lexer_cls: type) -> type:
    """`lexer_cls` (a generated KRLLexer) whose error recovery keeps a line end a token.

    ANTLR's lexer, after a token recognition error, skips one character past those it read: when
    the token stopped at a line end (``51.'B0120'``: ``'B012``, then ``0'`` cut by the line end,
    no character literal holds one), that character is the NEWLINE, and the next line joins the
    broken one (the parser's line recovery then skips both). This lexer steps back over the last
    character read before that skip, so that the skip takes it and the line end stays a token;
    the error's message and place are unchanged. KrlWorker.java's ``keepLineEnd`` does the same
    for the Java engine.
    """

    def recover(self, re) -> None:
        stream = self._input
        start = getattr(re, "startIndex", None)
        if start is not None and stream.index > start and stream.LA(1) in (10, 13):
            self.column -= 1            # the skip counts the character again
            stream.seek(stream.index - 1)
        lexer_cls.recover(self, re)

    return type(lexer_cls.__name__, (lexer_cls,), {"recover": recover, "__module__": lexer_cls.__module__})


class CollectingErrorListener(ErrorListener):
    """Collects SyntaxIssue records instead of printing to stderr."""

    def __init__(self, bundle, kind: str, tokens=None, text: str = ""):
        self.bundle = bundle
        self.kind = kind
        self.tokens = tokens
        self.text = text
        self.issues = []
        self._lexer_raw: list[tuple[int, int, str]] = []
        self._lines: list[str] | None = None

    # ANTLR calls this for lexer and parser errors alike.
    def syntaxError(self, recognizer, offendingSymbol, line, column, msg, e):  # noqa: N802
        if self.kind == "lexer":
            self._lexer_raw.append((line, column, msg))
            return
        try:
            expected_set = recognizer.getExpectedTokens()
            expected = [t for iv in expected_set.intervals for t in iv] if expected_set.intervals else []
        except Exception:  # noqa: BLE001 - an odd ATN state must not abort a scan
            expected = []
        ttype = offendingSymbol.type if offendingSymbol is not None else Token.EOF
        offending_text = offendingSymbol.text if offendingSymbol is not None else "<EOF>"
        self.add_raw(line, column, msg, ttype, offending_text, expected,
                     list(reversed(recognizer.getRuleInvocationStack())), self._line_tokens(offendingSymbol))

    def add_raw(self, line: int, column: int, msg: str, ttype: int, offending_text: str | None,
                expected: list[int], stack: list[str], line_tokens: list) -> None:
        """Record one syntax error from its raw data (this listener, or a parse engine's record:
        krl/syntax/engines): expected token types, the rule stack outermost first, and the
        default-channel tokens of the line up to the offending one (objects with .type, .text)."""

        names = sorted({self.bundle.display_name(t) for t in expected})
        if offending_text is not None and offending_text in ("\n", "\r\n", "\r"):
            offending_text = "<EOL>"
        issue = SyntaxIssue(line=line, column=column, message=msg, offending=offending_text or "",
                            expected=names, rule_stack=stack, kind="syntax",
                            offending_type=self.bundle.token_name(ttype),
                            line_shape=self._shape_of(line_tokens),
                            line_text=self._line_text(line))
        self.issues.append(issue)

    def check_issue(self, failure) -> object:
        """A SyntaxIssue for a failed post-parse token check (krl.syntax.checks)."""

        token, check = failure.token, failure.check
        return SyntaxIssue(line=token.line, column=token.column,
                           message=f"{check.message}, not {token.text}", offending=token.text or "",
                           expected=list(check.allowed), rule_stack=list(failure.rule_stack),
                           kind="syntax", offending_type=self.bundle.token_name(token.type),
                           line_shape=self._shape(token), line_text=self._line_text(token.line))

    def finish_lexer(self, text: str) -> list:
        """Turn the collected lexer errors into SyntaxIssue records."""

        lines = split_lines(text)
        issues = []
        for line, column, msg in self._lexer_raw:
            line_text = lines[line - 1] if 0 < line <= len(lines) else ""
            char = line_text[column] if column < len(line_text) else ""
            issues.append(SyntaxIssue(line=line, column=column, message=msg, offending=char,
                                      expected=[], rule_stack=[], kind="lexer", offending_type="",
                                      line_shape=[f"lexer:{_char_class(char)}"], line_text=line_text))
        return issues

    def _text_lines(self) -> list[str]:
        if self._lines is None:
            self._lines = split_lines(self.text)
        return self._lines

    def _line_text(self, line: int) -> str:
        lines = self._text_lines()
        return lines[line - 1] if 0 < line <= len(lines) else ""

    def _line_tokens(self, token) -> list:
        """Default-channel tokens of the offending token's line, up to and including it."""
        if token is None or self.tokens is None:
            return []
        newline = self.bundle.symbolic.index("NEWLINE")
        toks = self.tokens.tokens
        i = token.tokenIndex
        if i < 0:
            return [token]
        start = i
        while start > 0:
            prev = toks[start - 1]
            if prev.type == newline or prev.type == Token.EOF:
                break
            start -= 1
        return [t for t in toks[start:i + 1] if t.channel == Token.DEFAULT_CHANNEL]

    def _shape(self, token) -> list[str]:
        return self._shape_of(self._line_tokens(token))

    def _shape_of(self, toks: list) -> list[str]:
        """The line's shape: keywords kept, names and literals normalised, groups collapsed."""
        out: list[str] = []
        i = 0
        last = len(toks) - 1
        while i <= last:
            t = toks[i]
            text = t.text or ""
            if text in _GROUPS and i < last:
                # Collapse a bracketed group that closes before the offending token.
                depth, j = 0, i
                while j < last:
                    if toks[j].text in _GROUPS:
                        depth += 1
                    elif toks[j].text in _GROUPS.values():
                        depth -= 1
                        if depth == 0:
                            break
                    j += 1
                if j < last and depth == 0:
                    out.append(text + "…" + _GROUPS[text])
                    i = j + 1
                    continue
            out.append(_token_shape(self.bundle, t))
            i += 1
        return out

    def mark_cascades(self, issues: list) -> None:
        """Mark follow-on errors so that one missing construct counts once.

        - Only the first error of a line counts.
        - A line that fails at its first token right after a failed line continues the
          same unknown construct (the inner lines of an unknown block).
        - A block closer (ENDIF, ENDSPLINE, ...) whose opener line failed is a follow-on.
        """
        seen_lines: set[int] = set()
        failed_openers: dict[str, int] = {}
        previous_line = None
        for issue in issues:
            if issue.line in seen_lines:
                issue.cascade = True
                continue
            seen_lines.add(issue.line)
            shape = issue.line_shape
            first = shape[0] if shape else ""
            at_line_start = len(shape) == 1
            if issue.kind == "syntax":
                opener = _CLOSER_OF.get(first)
                if opener and failed_openers.get(opener, 0) > 0:
                    failed_openers[opener] -= 1
                    issue.cascade = True
                elif at_line_start and previous_line is not None and self._only_blank_between(
                        previous_line.line, issue.line):
                    issue.cascade = True
                if first in _CLOSER_OF.values() or first in _OPENER_ALIASES:
                    key = _OPENER_ALIASES.get(first, first)
                    if key:
                        failed_openers[key] = failed_openers.get(key, 0) + 1
            previous_line = issue

    def _only_blank_between(self, first: int, last: int) -> bool:
        """True when the lines strictly between `first` and `last` hold only blanks and comments."""
        lines = self._text_lines()
        for text in lines[first:last - 1]:
            stripped = text.strip()
            if stripped and not stripped.startswith(";"):
                return False
        return True


def _token_shape(bundle, token) -> str:
    if token.type == Token.EOF:
        return "<EOF>"
    name = bundle.token_name(token.type)
    if name in _NORMALISED:
        return _NORMALISED[name]
    if name == "NEWLINE":
        return "<EOL>"
    return (token.text or name).upper()


def _char_class(char: str) -> str:
    if not char:
        return "eol"
    if char.isspace():
        return "space"
    if ord(char) > 127:
        return "non-ascii"
    return char
