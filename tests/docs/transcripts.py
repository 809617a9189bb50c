"""The examples of README.md and docs/*.md that show output, run and compared (issue 49).

**Which blocks.** A fenced code block holding a line that starts with ``$ `` is a *transcript*,
as a reader sees in any manual: each ``$ `` line is a command (a line ending in ``\\`` goes on
on the next line), and the lines up to the next ``$ `` line are what it prints (none: it prints
nothing). Blocks without a ``$ `` line are not run (lists of commands to type, file formats). A
transcript that cannot run here (it needs a second terminal, a network partner) is preceded by
an HTML comment ``<!-- not run: why -->``, which a reader of the rendered page does not see.

**How they run.** The transcripts of one document run in order, in one fresh folder that looks
like a checkout: ``WORK/krl-tools`` holds a symbolic link to each top-level entry of the
repository (so ``conformance/cases/...`` and ``.venv`` are there) and ``WORK/shared`` links to
the shared folder (so ``../shared/krl-corpus/...`` is the corpus). What a command writes
(``new-backup``, ``out/``) lands in that folder, never in the repository. Each command runs in
``bash -c`` with the repository's ``.venv/bin`` first on ``PATH``, ``HOME`` in the folder,
``NO_COLOR=1`` and ``TERM=dumb``; standard output and standard error are read together, as a
terminal shows them. The test session (tests/docs/conftest.py) puts one folder before it on
``PATH`` (:func:`run_document` ``first_on_path``), holding a ``krl`` that is a fork of the
suite's fork server (tests/forkserver.py: the command line as typed, without the import of the
project at each start); ``python -m tests.docs.transcripts`` runs the virtualenv's own
``krl``. The exit status is not compared (``krl diff`` exits 1 when something changed); what
the command printed is.

**Normalisation** (:func:`normalise`, the only one): trailing spaces of each line and trailing
blank lines are dropped, and a figure of clock time -- a number followed by ``s wall``, ``s CPU``,
``ms wall`` or ``ms CPU`` -- reads ``N``. Simulated times, counts, paths and messages are
compared as they are.

**Updating.** After a deliberate change of what a command prints::

    .venv/bin/python -m tests.docs.transcripts --update README.md docs/diff.md

runs the transcripts of the named documents and writes each command's output in place of the
lines shown (commands and everything outside transcripts untouched); ``--check`` (the default)
prints the differences and exits 1 when there are any. tests/docs/test_transcripts.py runs the
check on every document with a transcript.
"""

from __future__ import annotations

import argparse
import difflib
import os
import re
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SHARED = REPO.parent / "shared"
#: the documents whose transcripts are run
DOCUMENTS = ("README.md", "docs/*.md")
#: seconds one command may take
COMMAND_TIMEOUT_S = 1200

_FENCE = re.compile(r"^(\s*)(`{3,}|~{3,})(.*)$")
_NOT_RUN = re.compile(r"^\s*<!--\s*not run\b.*-->\s*$")
_CLOCK = re.compile(r"\b\d+(?:\.\d+)?(?=\s?m?s (?:wall|CPU)\b)")


@dataclass
class Command:
    """One ``$`` command of a transcript: its text (continuations joined), the line of its
    ``$`` in the document (1-based), and the output lines shown (their document lines
    ``first``..``last``, exclusive; ``first == last`` for none)."""
    text: str
    line: int
    shown: list[str]
    first: int
    last: int


@dataclass
class Transcript:
    path: Path
    line: int                 # the opening fence's line
    commands: list[Command] = field(default_factory=list)


def documents(repo: Path = REPO) -> list[Path]:
    """README.md and docs/*.md of `repo`, in that order."""
    out: list[Path] = []
    for pattern in DOCUMENTS:
        out += sorted(repo.glob(pattern))
    return [p for p in out if p.is_file()]


def transcripts(path: Path) -> list[Transcript]:
    """The transcripts of the Markdown document `path` (module docstring), in order."""
    lines = path.read_text(encoding="utf-8").splitlines()
    out: list[Transcript] = []
    i = 0
    while i < len(lines):
        m = _FENCE.match(lines[i])
        if m is None:
            i += 1
            continue
        fence = m.group(2)
        start = i
        j = i + 1
        while j < len(lines) and not lines[j].strip().startswith(fence[0] * len(fence)):
            j += 1
        body = lines[start + 1:j]
        prev = next((lines[k] for k in range(start - 1, -1, -1) if lines[k].strip()), "")
        if any(b.startswith("$ ") for b in body) and not _NOT_RUN.match(prev):
            out.append(_parse(path, start + 1, body))
        i = j + 1
    return out


def _parse(path: Path, fence_line: int, body: list[str]) -> Transcript:
    t = Transcript(path, fence_line)
    k = 0
    while k < len(body):
        if not body[k].startswith("$ "):
            k += 1            # text before the first command: not compared
            continue
        line = fence_line + 1 + k
        text = body[k][2:]
        while text.endswith("\\") and k + 1 < len(body):
            k += 1
            text = text + "\n" + body[k]         # bash reads backslash-newline as one line
        k += 1
        first = k
        while k < len(body) and not body[k].startswith("$ "):
            k += 1
        t.commands.append(Command(text, line, body[first:k], fence_line + 1 + first, fence_line + 1 + k))
    return t


def normalise(lines: list[str]) -> list[str]:
    """The one normalisation of the comparison (module docstring)."""
    out = [_CLOCK.sub("N", ln.rstrip()) for ln in lines]
    while out and not out[-1]:
        out.pop()
    return out


def workspace(root: Path, repo: Path = REPO, shared: Path = SHARED) -> Path:
    """A folder that looks like a checkout beside the shared folder (module docstring); returns
    the checkout's folder, the commands' working folder."""
    work = root / "krl-tools"
    work.mkdir(parents=True)
    for entry in repo.iterdir():
        if entry.name != ".git":
            (work / entry.name).symlink_to(entry)
    (root / "shared").symlink_to(shared)
    (root / "home").mkdir()
    return work


def run(command: str, cwd: Path, repo: Path = REPO, first_on_path: Path | None = None) -> list[str]:
    """What `command` prints (standard output and error together), as lines; `first_on_path`:
    a folder searched before the virtualenv's (module docstring)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTEST", "COV_"))}
    path = f"{repo / '.venv' / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    if first_on_path is not None:
        path = f"{first_on_path}{os.pathsep}{path}"
    env.update({"PATH": path, "HOME": str(cwd.parent / "home"),
                "NO_COLOR": "1", "TERM": "dumb", "COLUMNS": "100", "PYTHONDONTWRITEBYTECODE": "1"})
    try:
        r = subprocess.run(["bash", "-c", command], cwd=cwd, env=env, stdin=subprocess.DEVNULL,
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=COMMAND_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        return [f"(the command took more than {COMMAND_TIMEOUT_S} s)"]
    return r.stdout.decode("utf-8", errors="replace").splitlines()


@dataclass
class Result:
    command: Command
    printed: list[str]

    @property
    def same(self) -> bool:
        return normalise(self.printed) == normalise(self.command.shown)

    def diff(self, path: Path) -> str:
        where = f"{path.name}:{self.command.line}"
        return "\n".join(difflib.unified_diff(normalise(self.command.shown), normalise(self.printed),
                                              f"{where} shown", f"{where} printed", lineterm=""))


def run_document(path: Path, root: Path, first_on_path: Path | None = None) -> list[Result]:
    """Every command of the document's transcripts, run in order in a workspace under `root`
    (`first_on_path`: :func:`run`)."""
    work = workspace(root)
    return [Result(c, run(c.text, work, first_on_path=first_on_path)) for t in transcripts(path) for c in t.commands]


def update(path: Path, results: list[Result]) -> bool:
    """Write each command's printed output in place of the lines shown; True if the file changed."""
    lines = path.read_text(encoding="utf-8").splitlines(keepends=True)
    newline = "\r\n" if lines and lines[0].endswith("\r\n") else "\n"
    changed = False
    for r in sorted(results, key=lambda r: r.command.first, reverse=True):
        if r.same:
            continue
        printed = [ln + newline for ln in normalise(r.printed)]
        lines[r.command.first - 1:r.command.last - 1] = printed
        changed = True
    if changed:
        path.write_text("".join(lines), encoding="utf-8", newline="")
    return changed


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tests.docs.transcripts",
                                 description="Run the transcripts ($ blocks) of the docs and compare or update them.")
    ap.add_argument("documents", nargs="*", help="Markdown files (default: README.md and docs/*.md)")
    mode = ap.add_mutually_exclusive_group()
    mode.add_argument("--check", action="store_true", help="print the differences, exit 1 when any (default)")
    mode.add_argument("--update", action="store_true", help="write what the commands print into the documents")
    args = ap.parse_args(argv)
    paths = [Path(p).resolve() for p in args.documents] or documents()
    status = 0
    for path in paths:
        if not transcripts(path):
            continue
        with tempfile.TemporaryDirectory(prefix="krl-docs-") as tmp:
            results = run_document(path, Path(tmp))
        bad = [r for r in results if not r.same]
        print(f"{path.relative_to(REPO) if path.is_relative_to(REPO) else path}: "
              f"{len(results)} commands, {len(bad)} differ")
        if args.update:
            if update(path, results):
                print(f"  updated {len(bad)} output(s)")
        else:
            for r in bad:
                print(r.diff(path))
            status = 1 if bad else status
    return status


if __name__ == "__main__":
    sys.exit(main())
