"""The fuzz targets: every entry point that reads untrusted input, with its oracle.

Each target takes the fuzzer's bytes and returns normally when the property holds; it
raises :class:`Finding` (or lets any other exception escape) when it does not. The property
of every target: bad input ends in the entry point's documented, clear error, never in
another exception (docs/security.md, "Bad input gets a clear error"). Targets with a
stronger oracle say so:

* ``fmt``: ``krl fmt``'s own safety check (formatted text parses to an equal AST) must hold;
  a FormatSafetyError is a finding, and formatting the result again changes nothing;
* ``interp``: a program that checks cleanly runs on the tree interpreter and the VM for a
  bounded number of steps, and both give the same trace (conformance/harness.compare_runs).

Inputs longer than :data:`MAX_INPUT` bytes are cut (the fuzzer's -max_len too); the size
limits of krl/limits.py are tested elsewhere.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

from conformance import harness as H
from krl.ast.build import build_module
from krl.fmt.core import FormatSafetyError, FormatSyntaxError, format_text
from krl.lsp.project import Project
from krl.source import decode_bytes
from krl.syntax.parse import parse_text
from krl.workspace import check_texts
from robot.stimuli import StimulusError, load_stimuli

MAX_INPUT = 4096


class Finding(AssertionError):
    """The property of a target does not hold for an input."""


def _text(data: bytes) -> tuple[str, str]:
    return decode_bytes(data[:MAX_INPUT])


def decode_parse(data: bytes) -> None:
    """decode + parse: any bytes give a ParseResult, never an exception."""
    text, _ = _text(data)
    for path in ("f.src", "f.dat"):
        result = parse_text(text, path)
        if result.ok and result.errors:
            raise Finding("a parse that is ok carries errors")


def ast_build(data: bytes) -> None:
    """The AST builder on every tree the parser accepts: diagnostics, never an exception."""
    text, _ = _text(data)
    result = parse_text(text, "f.src")
    if result.ok:
        build_module(result)


def check(data: bytes) -> None:
    """krl check on a one-file workspace: diagnostics with places inside the file."""
    text, _ = _text(data)
    ws = check_texts({"f.src": text})
    lines = text.count("\n") + 2
    for d in ws.diagnostics:
        if d.line < 1 or d.line > lines + 1:
            raise Finding(f"diagnostic {d.code} at line {d.line} outside the file ({lines} lines)")


def fmt(data: bytes) -> None:
    """krl fmt: a file that parses formats to an equal AST, and formatting is idempotent."""
    text, _ = _text(data)
    try:
        once = format_text(text, path="f.src")
    except FormatSyntaxError:
        return
    except FormatSafetyError as exc:
        raise Finding(f"krl fmt changed the program: {exc}") from None
    if format_text(once, path="f.src") != once:
        raise Finding("krl fmt is not idempotent")


def lsp_change(data: bytes) -> None:
    """The language server's didChange: open a document, change it to the input, analyse."""
    text, _ = _text(data)
    with tempfile.TemporaryDirectory(prefix="krl-fuzz-lsp-") as tmp:
        path = str(Path(tmp) / "f.src")
        project = Project()
        project.open(path, "DEF f()\nEND\n")
        project.change(path, text)
        project.analyze(path, dict(project.docs))


def stimuli(data: bytes) -> None:
    """The stimuli/cell loader: StimulusError (with file:line) or a list of stimuli."""
    with tempfile.TemporaryDirectory(prefix="krl-fuzz-stim-") as tmp:
        p = Path(tmp) / "cell.yaml"
        p.write_bytes(data[:MAX_INPUT])
        try:
            load_stimuli(p)
        except StimulusError as exc:
            if not str(exc).startswith(str(p)):
                raise Finding(f"stimulus error without its file: {exc}") from None


def interp(data: bytes) -> None:
    """Tree interpreter and VM agree on a short run of a program that checks cleanly."""
    text, _ = _text(data)
    ws = check_texts({"program.src": text})
    if any(d.is_error for d in ws.diagnostics):
        return
    with tempfile.TemporaryDirectory(prefix="krl-fuzz-run-") as tmp:
        d = Path(tmp)
        (d / "program.src").write_text(text, encoding="utf-8")
        runs = {it: H.run_program(d / "program.src", it, workspace=d, max_sim_time=5.0, max_steps=2_000,
                                  wall_timeout=30.0) for it in ("tree", "vm")}
    bad = [c for c in H.compare_runs(runs["tree"], runs["vm"]) if not c.ok]
    if bad:
        raise Finding("tree != vm: " + "; ".join(f"[{c.name}] {c.detail}" for c in bad))


TARGETS = {f.__name__: f for f in (decode_parse, ast_build, check, fmt, lsp_change, stimuli, interp)}
