"""Parsing KRL text with the generated ANTLR parser.

Two stages, the standard ANTLR strategy: SLL prediction with a bail-out error strategy
first (fast, and enough for almost every valid file), then full LL with a line-oriented
error recovery only when the first stage fails. The second stage reports every syntax
error with its line, column, offending token, the expected tokens and the rule stack.

The parser classes come from a `ParserBundle`, so that `krl growth` can load the parsers
generated from older versions of grammar/KRL.g4.
"""

from __future__ import annotations

import importlib.util
import sys
from dataclasses import dataclass, field
from pathlib import Path
from types import ModuleType

from antlr4 import CommonTokenStream, InputStream, Token
from antlr4.atn.PredictionMode import PredictionMode
from antlr4.error.ErrorStrategy import BailErrorStrategy
from antlr4.error.ErrorListener import ErrorListener
from antlr4.error.Errors import ParseCancellationException

from krl.diagnostics.codes import E018
from krl.syntax.checks import may_fail, run_checks
from krl.syntax.blocks import first_past_limit
from krl.syntax.errors import CollectingErrorListener, LineErrorStrategy, SyntaxIssue, line_end_lexer
from krl.source import SourceText, read_source

GENERATED_DIR = Path(__file__).parent / "generated"


@dataclass(slots=True)
class ParseResult:
    path: str
    ok: bool
    encoding: str
    status: str = "ok"            # "ok", "syntax_error", or a SourceText classification
    errors: list[SyntaxIssue] = field(default_factory=list)
    tree: object | None = None
    stage: str = "sll"            # which stage produced the result: "sll" or "ll"
    size: int = 0

    def as_json(self) -> dict:
        return {"path": self.path, "ok": self.ok, "encoding": self.encoding,
                "errors": [e.as_json() for e in self.errors]}


class ParserBundle:
    """The lexer and parser classes generated from one version of KRL.g4."""

    def __init__(self, lexer_cls: type, parser_cls: type, directory: Path | None = None):
        self.directory = directory    # the generated code's directory (None: krl/syntax/generated)
        self.lexer_cls = line_end_lexer(lexer_cls)   # a lexer error never takes a line end
        self.parser_cls = parser_cls
        self.symbolic = list(parser_cls.symbolicNames)
        self.literal = list(parser_cls.literalNames)

    @classmethod
    def from_directory(cls, directory: str | Path, tag: str = "") -> "ParserBundle":
        """Load KRLLexer.py and KRLParser.py from a directory of generated code."""
        directory = Path(directory)
        mods: dict[str, ModuleType] = {}
        for name in ("KRLLexer", "KRLParser"):
            modname = f"_krl_gen_{tag or abs(hash(str(directory)))}_{name}"
            spec = importlib.util.spec_from_file_location(modname, directory / f"{name}.py")
            if spec is None or spec.loader is None:
                raise ImportError(f"no generated {name} in {directory}")
            mod = importlib.util.module_from_spec(spec)
            sys.modules[modname] = mod
            spec.loader.exec_module(mod)
            mods[name] = mod
        return cls(mods["KRLLexer"].KRLLexer, mods["KRLParser"].KRLParser, directory)

    def token_name(self, ttype: int) -> str:
        if ttype == Token.EOF:
            return "<EOF>"
        if 0 < ttype < len(self.symbolic) and self.symbolic[ttype] != "<INVALID>":
            return self.symbolic[ttype]
        if 0 < ttype < len(self.literal):
            return self.literal[ttype]
        return str(ttype)

    def display_name(self, ttype: int) -> str:
        """A token type as a user reads it: the literal ('THEN', ':') where there is one."""
        if ttype == Token.EOF:
            return "<EOF>"
        if ttype == -2:  # Token.EPSILON
            return "<end of rule>"
        if 0 < ttype < len(self.literal) and self.literal[ttype] != "<INVALID>":
            return self.literal[ttype].strip("'")
        return self.token_name(ttype)


_default_bundle: ParserBundle | None = None


def default_bundle() -> ParserBundle:
    """The parser generated from the working tree's grammar/KRL.g4 (by `make parser`)."""
    global _default_bundle
    if _default_bundle is None:
        if not (GENERATED_DIR / "KRLParser.py").exists():
            raise RuntimeError("the generated parser is missing: run `make parser` "
                               "(it generates krl/syntax/generated from grammar/KRL.g4)")
        # deferred: tools/startup_bench.py, krl check --reach +8 ms at the top (2026-11-26)
        from krl.syntax.generated.KRLLexer import KRLLexer  # noqa: PLC0415
        # deferred: tools/startup_bench.py, krl run +14 ms at the top (2026-11-26)
        from krl.syntax.generated.KRLParser import KRLParser  # noqa: PLC0415
        _default_bundle = ParserBundle(KRLLexer, KRLParser)
    return _default_bundle


def _keyword_types(bundle: ParserBundle) -> frozenset[int]:
    """Token types of reserved words: those whose lexer rule is a word literal ('IF', 'E6POS')."""
    out = set()
    for ttype, sym in enumerate(bundle.symbolic):
        if ttype == 0 or sym in ("<INVALID>", "HEADER", "FOLD", "ENDFOLD", "COMMENT", "NEWLINE", "WS",
                                 "IDENTIFIER", "SYSNAME") or sym.endswith("LITERAL"):
            continue
        if sym.replace("_", "").isalnum() and sym[:1].isalpha():
            out.add(ttype)
    return frozenset(out)


#: id(bundle) -> (the bundle, kept alive here so that its id is not another's, its keywords)
_KW_CACHE: dict[int, tuple[ParserBundle, frozenset[int]]] = {}


def keyword_types(bundle: ParserBundle) -> frozenset[int]:
    """Token types of the reserved words of `bundle`'s grammar (cached per bundle)."""
    got = _KW_CACHE.get(id(bundle))
    if got is None or got[0] is not bundle:
        got = _KW_CACHE[id(bundle)] = (bundle, _keyword_types(bundle))
    return got[1]


def prepare_text(text: str) -> str:
    # A newline ends every statement; give an unterminated last line its newline.
    if text and not text.endswith(("\n", "\r")):
        text += "\n"
    return text


def parse_text(text: str, path: str = "<string>", bundle: ParserBundle | None = None,
               keep_tree: bool = True, encoding: str = "", first_line: int = 1,
               recover: bool = True) -> ParseResult:
    """Parse KRL text with the start rule `module`.

    Returns a ParseResult; ok is True when there is no lexer or syntax error.
    Never raises for bad input. `first_line`: the line number of the text's first line (a
    piece of a file, krl/lsp/parsing.py); the lines of tokens and spans count from it.
    `recover=False`: when the fast stage fails, return a not-ok result at once, without the
    errors (the caller only needs to know that the text does not parse).
    """
    bundle = bundle or default_bundle()
    text = prepare_text(text)

    # Stage 1: SLL with bail-out. Lexer errors are collected here too.
    lex_listener = CollectingErrorListener(bundle, kind="lexer")
    lexer = bundle.lexer_cls(InputStream(text))
    if first_line != 1:
        lexer.line = first_line
    lexer.removeErrorListeners()
    lexer.addErrorListener(lex_listener)
    tokens = CommonTokenStream(lexer)
    tokens.fill()
    past = first_past_limit(tokens.tokens, bundle)  # nesting budget, expression size (krl/limits.py)
    if past is not None:
        return _past_limit(path, encoding, past)
    parser = bundle.parser_cls(tokens)
    parser.removeErrorListeners()
    parser._interp.predictionMode = PredictionMode.SLL
    parser._errHandler = BailErrorStrategy()
    try:
        tree = parser.module()
        if not lex_listener.issues and not lex_listener._lexer_raw:
            failures = run_checks(tree, bundle.parser_cls) if may_fail(text) else []
            if not failures:
                return ParseResult(path, True, encoding, "ok", [], tree if keep_tree else None, "sll")
            listener = CollectingErrorListener(bundle, kind="syntax", tokens=tokens, text=text)
            issues = [listener.check_issue(f) for f in failures]
            listener.mark_cascades(issues)
            return ParseResult(path, False, encoding, "syntax_error", issues,
                               tree if keep_tree else None, "sll")
    except ParseCancellationException:
        if not recover:
            return ParseResult(path, False, encoding, "syntax_error", [], None, "sll")

    # Stage 2: full LL with line-oriented recovery, collecting every error.
    tokens.seek(0)
    parser = bundle.parser_cls(tokens)
    parser.removeErrorListeners()
    listener = CollectingErrorListener(bundle, kind="syntax", tokens=tokens, text=text)
    parser.addErrorListener(listener)
    parser._interp.predictionMode = PredictionMode.LL
    parser._errHandler = LineErrorStrategy()
    tree = parser.module()
    check_issues = ([listener.check_issue(f) for f in run_checks(tree, bundle.parser_cls)]
                    if may_fail(text) else [])
    return _finish(path, encoding, text, lex_listener, listener, check_issues,
                   tree if keep_tree else None, "ll")


def _finish(path, encoding, text, lex_listener, listener, check_issues, tree, stage) -> ParseResult:
    """Stage 2's result, whatever engine collected the errors: lexer, syntax and check issues
    in place order, follow-on errors marked."""
    lex_issues = lex_listener.finish_lexer(text)
    issues = sorted(lex_issues + listener.issues + check_issues, key=lambda i: (i.line, i.column))
    listener.mark_cascades(issues)
    ok = not issues
    return ParseResult(path, ok, encoding, "ok" if ok else "syntax_error", issues, tree, stage)


@dataclass(slots=True)
class _RawToken:
    type: int
    text: str


def result_from_raw(raw: dict, text: str, path: str, encoding: str,
                    bundle: ParserBundle | None = None, tree: object | None = None) -> ParseResult:
    """The ParseResult of a parse engine's raw record (krl/syntax/engines): the same records,
    shapes and cascade marks as :func:`parse_text` makes, from the same code. `text` is the
    text the engine parsed (after :func:`prepare_text`); `tree`: the parse tree rebuilt from
    the record (krl/syntax/engines/tree.py), or None."""
    bundle = bundle or default_bundle()
    if raw["stage"] == "sll":
        return ParseResult(path, True, encoding, "ok", [], tree, "sll")
    lex_listener = CollectingErrorListener(bundle, kind="lexer")
    lex_listener._lexer_raw = [tuple(e) for e in raw["lex"]]
    listener = CollectingErrorListener(bundle, kind="syntax", text=text)
    for e in raw["syn"]:
        listener.add_raw(e["line"], e["column"], e["msg"], e["type"], e["text"], e["expected"],
                         e["stack"][::-1], [_RawToken(t, x) for t, x in e["line_tokens"]])
    return _finish(path, encoding, text, lex_listener, listener, [], tree, "ll")


def _past_limit(path: str, encoding: str, past) -> ParseResult:
    """A file past a limit of krl/limits.py: not parsed; status "too_deep" (nesting) or
    "too_long" (expression size), with one issue (kind "limit") at the place."""
    status = "too_deep" if past.code == E018 else "too_long"
    issue = SyntaxIssue(line=past.line, column=past.column - 1, message=past.message, offending="",
                        expected=[], rule_stack=[], kind="limit", offending_type=past.code)
    return ParseResult(path, False, encoding, status, [issue], None, "limit")


def parse_source(source: SourceText, bundle: ParserBundle | None = None,
                 keep_tree: bool = True) -> ParseResult:
    """Parse a decoded file; classified bad input (binary, empty, ...) is not parsed."""
    if source.status != "ok":
        return ParseResult(source.path, False, source.encoding, source.status, [], None, "", source.size)
    result = parse_text(source.text, source.path, bundle, keep_tree, source.encoding)
    result.size = source.size
    return result


def parse_file(path: str | Path, bundle: ParserBundle | None = None, keep_tree: bool = True) -> ParseResult:
    return parse_source(read_source(path), bundle, keep_tree)


@dataclass(slots=True)
class ExpressionParse:
    """One KRL expression parsed on its own (:func:`parse_expression`): the parse tree of rule
    ``expression``, or the first problem as ``(column, message)`` (column 1-based)."""

    tree: object | None
    error: tuple[int, str] | None = None


class _FirstError(ErrorListener):
    def __init__(self) -> None:
        self.first: tuple[int, str] | None = None

    def syntaxError(self, recognizer, offendingSymbol, line, column, msg, e):  # noqa: N802
        if self.first is None:
            self.first = (column + 1, msg)


def parse_expression(text: str, max_tokens: int, bundle: ParserBundle | None = None) -> ExpressionParse:
    """Parse `text` as one KRL expression (grammar rule ``expression``, reference §4), never a
    statement: the front end's expression API (krl/semantics/expression.py). The text must
    be one line; more than `max_tokens` tokens, or nesting and terms past krl/limits.py, are
    refused before parsing. Never raises for bad input: the result's ``error`` gives the
    column and a message."""
    bundle = bundle or default_bundle()
    if "\n" in text or "\r" in text:
        return ExpressionParse(None, (1, "an expression is one line"))
    listener = _FirstError()
    lexer = bundle.lexer_cls(InputStream(text))
    lexer.removeErrorListeners()
    lexer.addErrorListener(listener)
    tokens = CommonTokenStream(lexer)
    tokens.fill()
    visible = [t for t in tokens.tokens if t.channel == Token.DEFAULT_CHANNEL and t.type != Token.EOF]
    if listener.first is not None:
        return ExpressionParse(None, listener.first)
    if not visible:
        return ExpressionParse(None, (1, "empty expression"))
    if len(visible) > max_tokens:
        return ExpressionParse(None, (1, f"{len(visible)} tokens, more than the limit of {max_tokens}"))
    past = first_past_limit(tokens.tokens, bundle)       # nesting and terms, as in a program
    if past is not None:
        return ExpressionParse(None, (past.column or 1, past.message))
    parser = bundle.parser_cls(tokens)
    parser.removeErrorListeners()
    parser.addErrorListener(listener)
    parser._interp.predictionMode = PredictionMode.LL
    parser._errHandler = BailErrorStrategy()
    try:
        tree = parser.expression()
    except ParseCancellationException:
        tok = tokens.LT(1)
        col = tok.column + 1 if tok is not None else 1
        shown = tok.text if tok is not None and tok.type != Token.EOF else "the end"
        return ExpressionParse(None, listener.first or (col, f"not a KRL expression at {shown!r}"))
    rest = tokens.LT(1)
    if rest is not None and rest.type != Token.EOF:
        return ExpressionParse(None, (rest.column + 1, f"unexpected {rest.text!r} after the expression"))
    return ExpressionParse(tree)
