"""Parse engines behind one interface (docs/architecture.md, "Parse engines").

- ``python``: krl/syntax/parse.py on the ANTLR Python runtime; the reference and the fallback.
- ``java``: the same grammar, generated for the ANTLR 4.13.2 Java runtime and run in a
  long-lived worker process (krl/syntax/engines/java.py); 10-30 times faster. It returns the
  same ParseResult, and on request the same parse tree (sent as data and rebuilt into the
  Python runtime's objects, krl/syntax/engines/tree.py).
- ``auto`` (the default): java when it can run here (java, javac and the ANTLR jar present),
  else python.

Whatever the engine, a file goes to the Python engine when a check that the fast engine does
not run could fire: a post-parse token check (krl/syntax/checks.py ``may_fail``), a nesting or
expression-size limit (krl/syntax/blocks.py ``may_pass_limit``). So the result is always the
Python engine's result, tree included (tests/syntax/test_engines.py).

`KRL_ENGINE` (python|java|auto) sets the default for this process and its children
(:func:`set_default`, used by the ``--engine`` options).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from pathlib import Path

import click

from krl.syntax.parse import (ParseResult, ParserBundle, default_bundle, parse_source as _py_parse_source,
                              prepare_text, result_from_raw)
from krl.source import SourceText, source_from_bytes
from krl.syntax.blocks import may_pass_limit
from krl.syntax.checks import may_fail
from krl.syntax.engines.java import EngineUnavailable, WorkerError, load_answer, unavailable_reason, worker_for
from krl.syntax.engines.tree import TreeDataError, tree_from_raw

ENGINES = ("auto", "python", "java")
REPO_GRAMMAR = Path(__file__).resolve().parents[3] / "grammar" / "KRL.g4"

__all__ = ["ENGINES", "EngineUnavailable", "available", "grammar_text", "java_answers", "parse_piece", "resolve",
           "result_from_answer", "set_default", "use_engine", "parse_file", "parse_source", "parse_sources",
           "unavailable_reason"]


def set_default(name: str) -> None:
    """Make `name` the default engine of this process and of the processes it starts."""
    if name not in ENGINES:
        raise ValueError(f"unknown parse engine {name!r}; one of {', '.join(ENGINES)}")
    os.environ["KRL_ENGINE"] = name


def use_engine(name: str | None) -> str:
    """For the --engine options: resolve `name` (None: KRL_ENGINE, else auto), make it the
    default of this process and its children, and return the engine that will run. An
    unavailable "java" is a message on stderr and exit status 2, never a traceback."""
    name = name or os.environ.get("KRL_ENGINE") or "auto"
    try:
        chosen = resolve(name)
    except EngineUnavailable as exc:
        click.echo(f"error: {exc}; use --engine python (or auto)", err=True)
        raise SystemExit(2) from None
    set_default(name)
    return chosen


def available() -> list[str]:
    """The engines that can run here, reference first."""
    return ["python"] + (["java"] if unavailable_reason() is None else [])


def resolve(name: str | None = None) -> str:
    """"python" or "java" for an engine name (None: KRL_ENGINE, default auto).

    Raises EngineUnavailable for "java" when it cannot run (the reason in words)."""
    name = name or os.environ.get("KRL_ENGINE") or "auto"
    if name not in ENGINES:
        raise ValueError(f"unknown parse engine {name!r}; one of {', '.join(ENGINES)}")
    if name == "python":
        return "python"
    reason = unavailable_reason()
    if reason is None:
        return "java"
    if name == "java":
        raise EngineUnavailable(f"the java parse engine is unavailable: {reason}")
    return "python"


_GRAMMARS: dict[str, str] = {}


def grammar_text(bundle: ParserBundle) -> str:
    """The text of the grammar a parser bundle was generated from (cached per file)."""
    return _grammar_text(bundle)


def _grammar_text(bundle: ParserBundle) -> str:
    """The grammar a bundle was generated from (its directory's KRL.g4; the working tree's)."""
    directory = bundle.directory
    g4 = Path(directory) / "KRL.g4" if directory is not None else REPO_GRAMMAR
    key = str(g4)
    if key not in _GRAMMARS:
        _GRAMMARS[key] = g4.read_text(encoding="utf-8")
    return _GRAMMARS[key]


_NEEDS: dict[tuple[int, int], bool] = {}


def _needs_python(text: str) -> bool:
    """True when a Python-only check could change the result of `text` (grammar-independent,
    so remembered per text for the many grammar versions of `krl growth`)."""
    key = (hash(text), len(text))
    found = _NEEDS.get(key)
    if found is None:
        if len(_NEEDS) > 100_000:
            _NEEDS.clear()
        found = _NEEDS[key] = may_fail(text) or may_pass_limit(text)
    return found


def parse_sources(sources: Iterable[SourceText], engine: str | None = None,
                  bundle: ParserBundle | None = None, threads: int = 1,
                  keep_tree: bool = False) -> Iterator[ParseResult]:
    """Parse decoded files with one engine; yields one ParseResult per source, in order.

    The java engine pipelines the files through one worker (`threads` parse threads); a file
    the worker cannot parse (it failed inside) and every file that needs a Python-only check
    is parsed by the Python engine. `keep_tree`: the results carry parse trees (the java
    engine's are rebuilt from its data, krl/syntax/engines/tree.py). Never raises for bad
    input; EngineUnavailable when "java" was asked for and cannot run."""
    bundle = bundle or default_bundle()
    sources = list(sources)
    if resolve(engine) == "python":
        for src in sources:
            yield _py_parse_source(src, bundle, keep_tree=keep_tree)
        return
    results: list[ParseResult | None] = [None] * len(sources)
    for i, src, raw in java_answers(enumerate(sources), bundle, threads, keep_tree):
        results[i] = result_from_answer(src, raw, bundle, keep_tree)
    yield from results


def java_answers(items: Iterable[tuple[object, SourceText]], bundle: ParserBundle | None = None,
                 threads: int = 1, trees: bool = False, stall: float | None = None,
                 decode: bool = True) -> Iterator[tuple[object, SourceText, dict | bytes | None]]:
    """The java engine's answers for (key, source) items, as they come: (key, source, raw).

    raw is None for a source the Python engine must parse (not decoded text, a Python-only
    check could fire, the grammar does not build for Java, the worker failed or went `stall`
    seconds without answering); such sources come first, or last when the worker gave up.
    `decode=False`: raw is the answer's JSON line (bytes), for :func:`result_from_answer` in
    another process. Never raises for bad input."""
    bundle = bundle or default_bundle()
    items = list(items)
    try:
        worker = worker_for(_grammar_text(bundle), threads)
    except EngineUnavailable:   # no JDK, or this grammar version does not build for Java
        worker = None
    to_java: list[int] = []
    texts: list[str] = []
    if worker is not None:
        for i, (_key, src) in enumerate(items):
            if src.status == "ok":
                text = prepare_text(src.text)
                if not _needs_python(text):
                    to_java.append(i)
                    texts.append(text)
    answered = [False] * len(items)
    for i in sorted(set(range(len(items))) - set(to_java)):
        answered[i] = True
        yield (*items[i], None)
    if texts:
        try:
            for k, raw in worker.parse_raw(texts, trees=trees, stall=stall, decode=decode):
                i = to_java[k]
                answered[i] = True
                yield (*items[i], raw)
        except WorkerError:
            pass    # the worker died or stalled (it is restarted next time): the Python engine
    for i, done in enumerate(answered):
        if not done:
            yield (*items[i], None)


def result_from_answer(source: SourceText, raw: dict | bytes | None, bundle: ParserBundle | None = None,
                       keep_tree: bool = False, parents: bool = True) -> ParseResult:
    """The ParseResult of one :func:`java_answers` item (its parse tree rebuilt when
    `keep_tree`, without ``parentCtx`` links when not `parents`: krl/syntax/engines/tree.py
    ``tree_from_raw``); the Python engine's result when raw is None or unusable."""
    bundle = bundle or default_bundle()
    if raw is not None:
        if isinstance(raw, bytes):
            try:
                raw = load_answer(raw)
            except ValueError:
                raw = None
    if raw is None or "fail" in raw:
        return _py_parse_source(source, bundle, keep_tree=keep_tree)
    text = prepare_text(source.text)
    tree = None
    if keep_tree:
        try:
            tree = tree_from_raw(raw, text, bundle, parents)
        except TreeDataError:
            return _py_parse_source(source, bundle, keep_tree=True)
    res = result_from_raw(raw, text, source.path, source.encoding, bundle, tree)
    res.size = source.size
    return res


def parse_piece(text: str, path: str, first_line: int, threads: int = 1,
                bundle: ParserBundle | None = None) -> ParseResult | None:
    """A piece of a file (its first line is line `first_line` of the file) parsed by the java
    engine with its tree, as ``parse_text(text, path, first_line=first_line, recover=False)``
    parses it: a ParseResult with the tree when it parses, a not-ok result without errors when
    it does not. None when the java engine cannot answer (not running here, a Python-only check
    could fire, the worker failed): then the Python engine must parse it. `threads`: the worker's
    (one worker per thread count)."""

    if unavailable_reason() is not None:
        return None
    bundle = bundle or default_bundle()
    text = prepare_text(text)
    if _needs_python(text):
        return None
    try:
        worker = worker_for(_grammar_text(bundle), threads)
        [(_k, raw)] = list(worker.parse_raw([text], trees=True, first_line=first_line))
    except (EngineUnavailable, WorkerError, ValueError):
        return None
    if "fail" in raw:
        return None
    if raw["stage"] != "sll":
        return ParseResult(path, False, "", "syntax_error", [], None, "ll")
    try:
        tree = tree_from_raw(raw, text, bundle)
    except TreeDataError:
        return None
    return ParseResult(path, True, "", "ok", [], tree, "sll")


def parse_source(source: SourceText, bundle: ParserBundle | None = None, keep_tree: bool = False,
                 engine: str | None = None) -> ParseResult:
    """One decoded file with the chosen engine."""
    return next(parse_sources([source], engine, bundle, keep_tree=keep_tree))


def parse_file(data: bytes | str | SourceText, path: str = "<string>", engine: str | None = None,
               bundle: ParserBundle | None = None, keep_tree: bool = False) -> ParseResult:
    """Parse one file's bytes (decoded as krl/source.py does), text or SourceText with the
    chosen engine ("python", "java", "auto"; None: KRL_ENGINE or auto). Returns the same
    ParseResult whatever the engine (with its parse tree when `keep_tree`)."""
    if isinstance(data, SourceText):
        source = data
    elif isinstance(data, bytes):
        source = source_from_bytes(path, data)
    else:
        source = SourceText(path, data, "", len(data.encode("utf-8", "surrogatepass")))
    return parse_source(source, bundle, keep_tree, engine)
