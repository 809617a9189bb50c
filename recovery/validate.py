"""`krl validate`: check each grammar construct's examples and its effect on the corpus.

grammar/constructs/<name>/ holds, per construct:
- ok_*.src|.dat|.sub: positive examples that must parse; a sibling ok_*.expect lists, one
  per line as ``LINE KIND``, every header, declaration and statement the example must build
  to, in order, in KRL words (krl/ast/kinds.py). The lists are written by hand from the
  reference, not copied from the parser's output;
- bad_*.src|.dat|.sub: negative near-misses that must be rejected.

With a corpus, validate also reports which corpus clusters the construct closed: it scans
the corpus with the grammar before and after the commit that introduced the construct (for a
construct not committed yet, `krl construct new`'s folder: HEAD's grammar against the working
tree's, so a maintainer sees the clusters closed and files gained before committing)
(parsers and results come from the growth cache; the versions are scanned in parallel, with
the fast parse engine when it can run: krl/syntax/engines).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import click

from krl.diagnostics import DiagnosticSink
from krl.files import SHARED_CORPUS as DEFAULT_CORPUS
from krl.syntax.parse import parse_file
from krl.source import is_krl_file, read_source
from recovery.cluster import cluster_results
from recovery.grammar_versions import GrammarToolError, _git, parser_dir_for
from recovery.progress import shown, steps
from recovery.scan import grammar_sha, scan
from krl.ast.build import build_module
from krl.ast.kinds import statement_kinds
from recovery.growth import scan_versions
from krl.syntax.engines import parse_source

REPO_ROOT = Path(__file__).resolve().parents[1]
CONSTRUCTS = REPO_ROOT / "grammar" / "constructs"


@dataclass(slots=True)
class ExampleResult:
    path: str
    kind: str          # "ok" or "bad"
    passed: bool
    detail: str = ""


@dataclass(slots=True)
class ConstructReport:
    name: str
    examples: list[ExampleResult] = field(default_factory=list)
    commit: str = ""
    grammar_changed: bool = False
    closed: list[dict] = field(default_factory=list)
    files_before: int | None = None
    files_after: int | None = None
    note: str = ""

    @property
    def passed(self) -> bool:
        return bool(self.examples) and all(e.passed for e in self.examples) and any(
            e.kind == "ok" for e in self.examples) and any(e.kind == "bad" for e in self.examples)


def expected_kinds(expect_file: Path) -> list[tuple[int, str]] | None:
    """The ``LINE KIND`` lines of an .expect file (None when there is none); ``#`` comments."""
    if not expect_file.exists():
        return None
    out = []
    for ln in expect_file.read_text(encoding="utf-8").splitlines():
        ln = ln.strip()
        if ln and not ln.startswith("#"):
            line, _, kind = ln.partition(" ")
            out.append((int(line), kind.strip()))
    return out


def built_kinds(result) -> list[tuple[int, str]]:
    """(line, kind) of the module the AST builder makes of a parse result."""
    return statement_kinds(build_module(result, DiagnosticSink()))


def check_example(path: Path) -> ExampleResult:
    kind = "ok" if path.name.startswith("ok_") else "bad"
    if kind == "ok":   # the statement kinds need the tree: the Python engine
        result = parse_file(path, keep_tree=True)
    else:

        result = parse_source(read_source(path))
    rel = path.relative_to(REPO_ROOT).as_posix()
    if kind == "bad":
        return ExampleResult(rel, kind, not result.ok, "" if not result.ok else "accepted")
    if not result.ok:
        first = next((e for e in result.errors if not e.cascade), None)
        where = f"{first.line}:{first.column + 1} {first.message}" if first else result.status
        return ExampleResult(rel, kind, False, f"rejected: {where}")
    expected = expected_kinds(path.with_suffix(".expect"))
    if expected is not None:
        got = built_kinds(result)
        if got != expected:
            diff = next((f"line {e[0]}: expected {e[1]!r}, built {g[1]!r} (line {g[0]})"
                         for e, g in zip(expected, got) if e != g),
                        f"{len(expected)} entries expected, {len(got)} built")
            return ExampleResult(rel, kind, False, "statement kinds differ: " + diff)
    return ExampleResult(rel, kind, True)


def _introducing_commit(directory: Path) -> str:
    rel = directory.relative_to(REPO_ROOT).as_posix()
    out = _git("log", "--diff-filter=A", "--format=%H", "--", rel).split()
    return out[-1] if out else ""


def _grammar_change(report: ConstructReport, directory: Path) -> tuple[str, str] | None:
    """The grammar before and after the commit that introduced the construct, or None (with
    report.note saying why) when there is no corpus effect to measure."""
    try:
        commit = _introducing_commit(directory)
    except GrammarToolError as exc:
        report.note = str(exc)
        return None
    if not commit:      # a construct in the making: HEAD's grammar against the working tree's
        try:
            before = _git("show", "HEAD:grammar/KRL.g4")
        except GrammarToolError as exc:
            report.note = f"not committed yet ({exc})"
            return None
        after = (REPO_ROOT / "grammar" / "KRL.g4").read_text(encoding="utf-8")
        if after == before:
            report.note = "not committed yet; grammar/KRL.g4 is unchanged in the working tree"
            return None
        report.commit = "working tree"
        report.grammar_changed = True
        return before, after
    report.commit = commit[:10]
    changed = _git("diff-tree", "--no-commit-id", "--name-only", "-r", commit).split()
    report.grammar_changed = "grammar/KRL.g4" in changed
    if not report.grammar_changed:
        report.note = "covered by the grammar already (examples only)"
        return None
    try:
        before = _git("show", f"{commit}^:grammar/KRL.g4")
    except GrammarToolError:
        report.note = "introduced with the first grammar"
        return None
    return before, _git("show", f"{commit}:grammar/KRL.g4")


def _corpus_effect(report: ConstructReport, pair: tuple[str, str], corpus: Path) -> None:
    scans = []
    for text in pair:
        pdir = parser_dir_for(text)
        scans.append(scan(corpus, grammar_sha(text), parser_dir=str(pdir), progress=False))
    clusters_before = {c.signature: c for c in cluster_results(scans[0])}
    after_sigs = {c.signature for c in cluster_results(scans[1])}
    report.closed = [{"id": c.id, "files": c.files, "signature": c.signature}
                     for sig, c in clusters_before.items() if sig not in after_sigs]
    report.files_before = sum(r.ok for r in scans[0])
    report.files_after = sum(r.ok for r in scans[1])


def validate_constructs(names: list[str], corpus: Path | None = None,
                        jobs: int | None = None) -> list[ConstructReport]:
    """Validate the named constructs (all when names is empty).

    With a corpus, the grammar versions before and after each construct are scanned first, in
    parallel (`jobs` versions at a time, recovery/growth.py), into the result cache."""
    dirs = sorted(d for d in CONSTRUCTS.iterdir() if d.is_dir()) if CONSTRUCTS.is_dir() else []
    if names:
        unknown = set(names) - {d.name for d in dirs}
        if unknown:
            raise click.UsageError(f"unknown construct(s): {', '.join(sorted(unknown))}")
        dirs = [d for d in dirs if d.name in names]
    reports = [ConstructReport(d.name) for d in dirs]
    pairs = [_grammar_change(rep, d) if corpus is not None else None for rep, d in zip(reports, dirs)]
    if corpus is not None:
        texts = list(dict.fromkeys(t for pair in pairs if pair for t in pair))
        if texts:
            scan_versions(corpus, texts, jobs, progress=shown())
    for rep, d, pair in steps(list(zip(reports, dirs, pairs)), "validating constructs", lambda x: x[1].name):
        for f in sorted(d.iterdir()):
            if is_krl_file(f) and f.name.startswith(("ok_", "bad_")):
                rep.examples.append(check_example(f))
        if pair is not None:
            _corpus_effect(rep, pair, corpus)
    return reports


def print_validation(reports: list[ConstructReport]) -> bool:
    all_ok = True
    for rep in reports:
        n_ok = sum(e.kind == "ok" for e in rep.examples)
        n_bad = sum(e.kind == "bad" for e in rep.examples)
        status = "PASS" if rep.passed else "FAIL"
        all_ok &= rep.passed
        click.echo(f"{status} {rep.name}: {n_ok} positive, {n_bad} negative examples")
        for e in rep.examples:
            if not e.passed:
                click.echo(f"    {e.path}: {e.detail}")
        if not n_ok or not n_bad:
            click.echo("    needs at least one positive and one negative example")
        if rep.files_before is not None:
            where = " (HEAD -> working tree)" if rep.commit == "working tree" else ""
            click.echo(f"    corpus{where}: {rep.files_before} -> {rep.files_after} files parse; closed "
                       + (", ".join(f"{c['id']} ({c['files']} files)" for c in rep.closed) or "no cluster"))
        elif rep.note:
            click.echo(f"    corpus: {rep.note}")
    click.echo(f"{sum(r.passed for r in reports)}/{len(reports)} constructs pass")
    return all_ok
