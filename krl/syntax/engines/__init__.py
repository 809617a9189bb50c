"""Parse engines behind one interface (docs/architecture.md, "Parse engines").

- ``python``: krl/syntax/parse.py on the ANTLR Python runtime; the reference and the fallback.
  It alone builds parse trees.
- ``java``: the same grammar, generated for the ANTLR 4.13.2 Java runtime and run in a
  long-lived worker process (krl/syntax/engines/java.py); 10-30 times faster. It returns the
  same ParseResult without a tree.
- ``auto`` (the default): java when it can run here (java, javac and the ANTLR jar present),
  else python.

Whatever the engine, a file goes to the Python engine when a check that the fast engine does
not run could fire: a post-parse token check (krl/syntax/checks.py ``may_fail``), a nesting or
expression-size limit (krl/syntax/blocks.py ``may_pass_limit``), or when a tree is wanted. So
the result is always the Python engine's result (tests/syntax/test_engines.py).

`KRL_ENGINE` (python|java|auto) sets the default for this process and its children
(:func:`set_default`, used by the ``--engine`` options).
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from pathlib import Path

from krl.syntax.parse import (ParseResult, ParserBundle, default_bundle, parse_source as _py_parse_source,
                              prepare_text, result_from_raw)
from krl.syntax.source import SourceText

ENGINES = ("auto", "python", "java")
REPO_GRAMMAR = Path(__file__).resolve().parents[3] / "grammar" / "KRL.g4"

__all__ = ["ENGINES", "EngineUnavailable", "available", "resolve", "set_default", "use_engine", "parse_file",
           "parse_source", "parse_sources", "unavailable_reason"]

from krl.syntax.engines.java import EngineUnavailable, WorkerError, unavailable_reason  # noqa: E402


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
        import click  # noqa: PLC0415

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
    from krl.syntax.blocks import may_pass_limit  # noqa: PLC0415
    from krl.syntax.checks import may_fail  # noqa: PLC0415

    key = (hash(text), len(text))
    found = _NEEDS.get(key)
    if found is None:
        if len(_NEEDS) > 100_000:
            _NEEDS.clear()
        found = _NEEDS[key] = may_fail(text) or may_pass_limit(text)
    return found


def parse_sources(sources: Iterable[SourceText], engine: str | None = None,
                  bundle: ParserBundle | None = None, threads: int = 1) -> Iterator[ParseResult]:
    """Parse decoded files with one engine; yields one ParseResult per source, in order.

    The java engine pipelines the files through one worker (`threads` parse threads); a file
    the worker cannot parse (it failed inside) and every file that needs a Python-only check
    is parsed by the Python engine. Never raises for bad input; EngineUnavailable when "java"
    was asked for and cannot run."""
    bundle = bundle or default_bundle()
    sources = list(sources)
    if resolve(engine) == "python":
        for src in sources:
            yield _py_parse_source(src, bundle, keep_tree=False)
        return
    from krl.syntax.engines.java import worker_for  # noqa: PLC0415

    try:
        worker = worker_for(_grammar_text(bundle), threads)
    except EngineUnavailable:   # this grammar version does not build for Java: the reference
        for src in sources:
            yield _py_parse_source(src, bundle, keep_tree=False)
        return
    results: list[ParseResult | None] = [None] * len(sources)
    texts: list[str] = []
    where: list[int] = []
    for i, src in enumerate(sources):
        if src.status != "ok":
            results[i] = _py_parse_source(src, bundle, keep_tree=False)
            continue
        text = prepare_text(src.text)
        if _needs_python(text):
            continue
        texts.append(text)
        where.append(i)
    answers: dict[int, dict] = {}
    try:
        for k, raw in worker.parse_raw(texts):
            answers[k] = raw
    except WorkerError:
        pass    # the worker died (it is restarted next time): the rest goes to the Python engine
    for k, i in enumerate(where):
        raw = answers.get(k)
        if raw is not None and "fail" not in raw:
            src = sources[i]
            res = result_from_raw(raw, texts[k], src.path, src.encoding, bundle)
            res.size = src.size
            results[i] = res
    for i, src in enumerate(sources):
        yield results[i] if results[i] is not None else _py_parse_source(src, bundle, keep_tree=False)


def parse_source(source: SourceText, bundle: ParserBundle | None = None, keep_tree: bool = False,
                 engine: str | None = None) -> ParseResult:
    """One decoded file with the chosen engine (keep_tree: always the Python engine)."""
    if keep_tree:
        return _py_parse_source(source, bundle, keep_tree=True)
    return next(parse_sources([source], engine, bundle))


def parse_file(data: bytes | str | SourceText, path: str = "<string>", engine: str | None = None,
               bundle: ParserBundle | None = None, keep_tree: bool = False) -> ParseResult:
    """Parse one file's bytes (decoded as krl/syntax/source.py does), text or SourceText with the
    chosen engine ("python", "java", "auto"; None: KRL_ENGINE or auto). Returns the same
    ParseResult whatever the engine (tree only with keep_tree, which uses the Python engine)."""
    if isinstance(data, SourceText):
        source = data
    elif isinstance(data, bytes):
        from krl.syntax.source import source_from_bytes  # noqa: PLC0415

        source = source_from_bytes(path, data)
    else:
        source = SourceText(path, data, "", len(data.encode("utf-8", "surrogatepass")))
    return parse_source(source, bundle, keep_tree, engine)
