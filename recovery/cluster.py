"""Clustering parse failures into missing constructs.

A cluster is a construct the grammar lacks, not a file. Its signature is built from the
first syntax error of each statement (follow-on errors are marked by the parser and left
out): the parser rule at the error, the offending token type, and the shape of the line up
to the offending token, with keywords kept and names, numbers, strings and system variables
normalised. Lexer errors (unknown characters) form clusters of their own. Clusters are
ranked by the number of files they affect, then by occurrences.
"""

from __future__ import annotations

import hashlib
import re
from collections import defaultdict
from dataclasses import dataclass, field

from recovery.scan import FileResult, IssueRecord

WINDOW = 2
EXAMPLES = 3


@dataclass(slots=True)
class Cluster:
    id: str
    signature: str
    files: int = 0
    occurrences: int = 0
    leading_keyword: str = ""
    expected: list[str] = field(default_factory=list)
    examples: list[dict] = field(default_factory=list)
    paths: list[str] = field(default_factory=list)
    shape: list[str] = field(default_factory=list)   # the line up to the offending token (first example)

    @property
    def line_shape(self) -> str:
        """The line's shape in KRL words: ``IF ‹name› = ‹number›``."""
        return shape_words(self.shape)

    @property
    def keyword(self) -> str:
        """The leading keyword in KRL words (a name stands as ‹name›)."""
        if self.leading_keyword == "(lexer)":
            return shape_words(self.shape) or "a character"
        return shape_words([self.leading_keyword]) if self.leading_keyword else "?"

    @property
    def is_lexer(self) -> bool:
        return self.signature.startswith("lexer |")

    @property
    def where(self) -> str:
        """Where in the grammar the line fails, in KRL words."""
        return context_words(self.signature)

    @property
    def stopped_at(self) -> str:
        """The token the parser could not take (the last of the shape), in KRL words."""
        return shape_words(self.shape[-1:]) if self.shape else ""

    def to_json(self) -> dict:
        return {"id": self.id, "signature": self.signature, "files": self.files,
                "occurrences": self.occurrences, "leading_keyword": self.leading_keyword,
                "line_shape": self.line_shape, "where": self.where,
                "expected": self.expected, "examples": self.examples}


def local_shape(shape: list[str]) -> list[str]:
    """The offending token and the token before it.

    The rule at the error already says which construct the parser was in; the whole line
    would split one construct by what precedes it (`DEF` or `GLOBAL DEF`, the first or the
    second parameter).
    """
    return list(shape[-WINDOW:])


# A line that cannot even start fails in whichever list rule happens to be reading lines
# (the routine's declaration part, a statement list, ...). Those are one position.
_LINE_LISTS = {"routineBody": "line-start", "statementList": "line-start", "statementLine": "line-start",
               "declarationLine": "line-start", "dataList": "data-line-start",
               "dataItemLine": "data-line-start", "module": "file-line-start"}


def error_context(issue: IssueRecord) -> str:
    """The parser rule at the error; at the start of a line, the kind of line list."""
    if not issue.rule_stack:
        return "?"
    if len(issue.shape) == 1:
        for rule in reversed(issue.rule_stack):
            if rule in _LINE_LISTS:
                return _LINE_LISTS[rule]
    return issue.rule_stack[-1]


def signature(issue: IssueRecord) -> str:
    if issue.kind == "lexer":
        return "lexer | " + " ".join(issue.shape)
    if issue.kind == "internal":
        return "internal | parser failure"
    context = error_context(issue)
    return f"{context} | {issue.offending_type} | {' '.join(local_shape(issue.shape))}"


# ---------------------------------------------------------------- KRL words for a cluster
_PLACEHOLDERS = {"id": "‹name›", "$sys": "‹system variable›", "num": "‹number›", "str": "‹string›",
                 "#enum": "‹#enum value›", "<EOL>": "‹end of line›", "<EOF>": "‹end of file›"}
_CONTEXTS = {"line-start": "a statement or declaration line cannot start like this",
             "data-line-start": "a data-list line cannot start like this",
             "file-line-start": "a module line (outside DEF/DEFDAT) cannot start like this",
             "?": "(no parser rule recorded)"}
_KEYWORD_WORDS = {"if", "for", "while", "loop", "repeat", "switch", "interrupt", "trigger", "spline", "ptp",
                  "lin", "circ", "def", "deffct", "defdat", "signal", "struc", "enum", "decl", "wait",
                  "goto", "halt", "brake", "const", "import", "ext", "extfct"}


def shape_words(shape: list[str]) -> str:
    """Normalised shape tokens in KRL words: ``["IF", "id", "=", "num"]`` ->
    ``IF ‹name› = ‹number›``; a lexer shape names the character class."""
    words = []
    for tok in shape:
        if tok.startswith("lexer:"):
            cls = tok[len("lexer:"):]
            words.append({"eol": "‹end of line›", "space": "‹white space›",
                          "non-ascii": "‹a non-ASCII character›"}.get(cls, f"the character {cls}"))
        else:
            words.append(_PLACEHOLDERS.get(tok, tok))
    return " ".join(words)


def rule_words(rule: str) -> str:
    """A grammar rule name in words: ``ifStatement`` -> ``IF statement``,
    ``withClause`` -> ``with clause``."""
    parts = re.findall(r"[A-Z]?[a-z0-9]+|[A-Z]+(?![a-z])", rule)
    return " ".join(w.upper() if w.lower() in _KEYWORD_WORDS else w.lower() for w in parts) or rule


def context_words(sig: str) -> str:
    """The first part of a cluster signature in words."""
    head = sig.split(" | ", 1)[0]
    if head == "lexer":
        return "a character the KRL lexer does not accept"
    if head == "internal":
        return "the parser failed (internal error)"
    if head in _CONTEXTS:
        return _CONTEXTS[head]
    return f"in the {rule_words(head)}"


def cluster_id(sig: str) -> str:
    return "C" + hashlib.sha1(sig.encode("utf-8")).hexdigest()[:7]


def _leading_keyword(issue: IssueRecord) -> str:
    if issue.kind == "lexer":
        return "(lexer)"
    first = issue.shape[0] if issue.shape else ""
    return first


def counted_issues(result: FileResult) -> list[IssueRecord]:
    """The issues of a file that define constructs: not follow-on errors."""
    return [i for i in result.issues if not i.cascade]


class ClusterBuilder:
    """Clusters built one file at a time, in any order (files finish in any order in a
    parallel scan): each file comes with its index in the corpus walk, and every choice that
    depends on order (the first example, the expected tokens, the leading keyword and the line
    shape shown for a cluster, its three examples) is made by the smallest walk index. So the
    clusters are the same whatever order the files arrive in; only paths and counts are kept
    per file, not the files' issues."""

    def __init__(self) -> None:
        self._by_sig: dict[str, Cluster] = {}
        self._first: dict[str, tuple] = {}              # sig -> (index, position) of the representative
        self._files: dict[str, set[str]] = defaultdict(set)
        self._examples: dict[str, list[tuple]] = defaultdict(list)   # sig -> [(index, example)]

    def add(self, index: int, res: FileResult) -> None:
        """Add the counted issues of one file, `index` its place in the corpus walk."""
        for pos, issue in enumerate(counted_issues(res)):
            sig = signature(issue)
            cl = self._by_sig.get(sig)
            if cl is None:
                cl = self._by_sig[sig] = Cluster(cluster_id(sig), sig)
            if sig not in self._first or (index, pos) < self._first[sig]:
                self._first[sig] = (index, pos)
                cl.leading_keyword = _leading_keyword(issue)
                cl.expected = list(issue.expected)
                cl.shape = list(issue.shape)
            cl.occurrences += 1
            if res.path not in self._files[sig]:
                self._files[sig].add(res.path)
                ex = self._examples[sig]
                ex.append((index, {"path": res.path, "line": issue.line,
                                   "text": issue.line_text.strip()[:200]}))
                ex.sort(key=lambda item: item[0])
                del ex[EXAMPLES:]

    def clusters(self) -> list[Cluster]:
        """The clusters so far, ranked by files, then occurrences."""
        for sig, cl in self._by_sig.items():
            cl.files = len(self._files[sig])
            cl.paths = sorted(self._files[sig])
            cl.examples = [e for _, e in self._examples[sig]]
        return sorted(self._by_sig.values(), key=lambda c: (-c.files, -c.occurrences, c.signature))


def cluster_results(results: list[FileResult]) -> list[Cluster]:
    """Group the counted issues of all files (in walk order) into ranked clusters."""
    builder = ClusterBuilder()
    for index, res in enumerate(results):
        builder.add(index, res)
    return builder.clusters()


def clusters_of_file(result: FileResult) -> list[str]:
    """Cluster ids of one file, in order of first appearance."""
    seen: list[str] = []
    for issue in counted_issues(result):
        cid = cluster_id(signature(issue))
        if cid not in seen:
            seen.append(cid)
    return seen
