"""`krl construct new NAME --from CLUSTER`: a new grammar construct's folder, from a cluster of
the recovery report (the maintainer's loop of README "Growing the grammar").

What it writes, under the project root (``--root``, default: this checkout):

* ``grammar/constructs/NAME/ok_<n>.<ext>``: one positive example per example of the cluster
  (the report keeps three), each the smallest cut of its corpus file that still shows the
  construct: the cluster's line alone, then inside a bare routine or data list, then its
  enclosing routine or data list, then the whole file; the first cut whose parse with the
  current grammar fails with the cluster's own signature wins. Each example starts with a
  comment naming its origin (corpus path:line and cluster id);
* ``ok_<n>.expect``: the statement-kind list to write by hand from the reference (one
  ``LINE KIND`` line per header, declaration and statement: recovery/validate.py); the
  template lists the example's lines, so `krl validate` fails until it is filled in;
* ``bad_template.<ext>``: the negative near-miss to write by hand (a comment says how);
* a row at the end of ``grammar/CHANGES.md`` naming the cluster and the corpus's files_ok
  before the change (the "after" to measure with ``krl recover``);
* ``conformance/cases/<next>_<NAME>/``: a conformance case stub (``status: pending``) with
  the first example as its program, to turn into a real case once the construct runs.

Corpus files are untrusted: they are read with krl.source (size limit, decoding), written
back only as text inside the project's folder, and never executed. Errors (unknown cluster,
report or corpus missing, construct already there, a name that is no folder name) are
:class:`ConstructError` with a message; the command exits 2 on them.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

from krl.durable import write_bytes
from krl.source import read_source
from recovery.cluster import clusters_of_file
from recovery.scan import _init_worker, parse_row

REPO_ROOT = Path(__file__).resolve().parents[1]
NAME = re.compile(r"[a-z][a-z0-9_]{0,47}")
BLOCK_START = re.compile(r"^\s*(GLOBAL\s+)?(DEF|DEFFCT|DEFDAT)\b", re.IGNORECASE)
BLOCK_END = re.compile(r"^\s*(END|ENDFCT|ENDDAT)\b", re.IGNORECASE)


class ConstructError(Exception):
    """The construct cannot be created (the message says why, in the user's words)."""


@dataclass(frozen=True)
class Example:
    """One positive example: ``text`` cut from ``origin`` (corpus path) at ``line``."""
    origin: str
    line: int
    text: str
    suffix: str
    cut: str          # which cut showed the construct: line, wrapped, block, file


def _shows(text: str, suffix: str, cluster_id: str) -> bool:
    row = parse_row("example" + suffix, text.encode("utf-8"), "")
    return cluster_id in clusters_of_file(row)


def _cuts(lines: list[str], index: int, suffix: str) -> list[tuple[str, str]]:
    """Candidate cuts around line ``index`` (0-based), smallest first."""
    line = lines[index]
    data = suffix == ".dat"
    wrapped = (f"DEFDAT example\n{line}\nENDDAT\n" if data else f"DEF example()\n{line}\nEND\n")
    cuts = [("line", line + "\n"), ("wrapped", wrapped)]
    start = next((i for i in range(index, -1, -1) if BLOCK_START.match(lines[i])), None)
    if start is not None:
        end = next((i for i in range(index + 1, len(lines)) if BLOCK_END.match(lines[i])), len(lines) - 1)
        cuts.append(("block", "\n".join(lines[start:end + 1]) + "\n"))
    cuts.append(("file", "\n".join(lines) + "\n"))
    return cuts


def cut_example(corpus: Path, origin: str, line: int, cluster_id: str) -> Example:
    """The smallest cut of ``corpus/origin`` around ``line`` (1-based) that shows the cluster."""
    path = corpus / origin
    src = read_source(path)
    if src.status != "ok":
        raise ConstructError(f"{origin}: cannot be read ({src.status}{': ' + src.detail if src.detail else ''})")
    lines = src.text.splitlines()
    if not 1 <= line <= len(lines):
        raise ConstructError(f"{origin}:{line}: no such line (the file has {len(lines)})")
    suffix = path.suffix.lower() if path.suffix.lower() in (".src", ".dat", ".sub") else ".src"
    for cut, text in _cuts(lines, line - 1, suffix):
        if _shows(text, suffix, cluster_id):
            return Example(origin, line, text, suffix, cut)
    raise ConstructError(f"{origin}:{line}: the file no longer shows cluster {cluster_id} "
                         "(the grammar changed since the report: run krl recover again)")


def _cluster(report: Path, cluster_id: str) -> tuple[dict, dict]:
    summary = report / "summary.json"
    try:
        data = json.loads(summary.read_text(encoding="utf-8"))
    except OSError:
        raise ConstructError(f"{summary}: no recovery report there (run krl recover first)") from None
    except ValueError:
        raise ConstructError(f"{summary}: not a recovery report (not JSON)") from None
    for c in data.get("clusters", []):
        if isinstance(c, dict) and c.get("id") == cluster_id:
            return data, c
    known = ", ".join(c.get("id", "?") for c in data.get("clusters", [])[:10])
    raise ConstructError(f"no cluster {cluster_id} in {summary} (ranked clusters: {known or 'none'})")


def _next_case(cases: Path) -> int:
    numbers = [int(m.group(1)) for p in cases.iterdir() if (m := re.match(r"(\d+)_", p.name))] if cases.is_dir() else []
    return max(numbers, default=0) + 1


def _expect_template(ex: Example) -> str:
    body = ex.text.splitlines()
    rows = [f"# {i} ?   {body[i - 1].strip()[:60]}" for i in range(2, len(body) + 1) if body[i - 1].strip()]
    return ("# statement kinds in order, written by hand from the example and the reference (krl/ast/kinds.py):\n"
            "# one 'LINE KIND' line per header, declaration and statement; replace each '# LINE ?' below\n"
            + "\n".join(rows) + "\n")


def new_construct(name: str, cluster_id: str, report: Path, corpus: Path | None = None,
                  root: Path = REPO_ROOT) -> list[Path]:
    """Create construct ``name`` from cluster ``cluster_id`` of the recovery report folder
    ``report``; returns the files written. Raises ConstructError."""
    if not NAME.fullmatch(name):
        raise ConstructError(f"{name!r}: a construct name is lower case letters, digits and _ (at most 48)")
    folder = root / "grammar" / "constructs" / name
    if folder.exists():
        raise ConstructError(f"{folder}: the construct exists already")
    data, cluster = _cluster(report, cluster_id)
    corpus = corpus or Path(str(data.get("corpus", "")))
    if not corpus.is_dir():
        raise ConstructError(f"{corpus}: the report's corpus is not there (give --corpus)")
    _init_worker(None)
    examples = [cut_example(corpus, str(e["path"]), int(e["line"]), cluster_id) for e in cluster.get("examples", [])]
    if not examples:
        raise ConstructError(f"cluster {cluster_id} has no examples in the report")
    folder.mkdir(parents=True)
    written = []
    for n, ex in enumerate(examples, 1):
        head = f"; origin: {ex.origin}:{ex.line} (cluster {cluster_id}, cut: {ex.cut})\n"
        ok = folder / f"ok_{n}{ex.suffix}"
        ok.write_text(head + ex.text, encoding="utf-8")
        exp = folder / f"ok_{n}.expect"
        exp.write_text(_expect_template(Example(ex.origin, ex.line, head + ex.text, ex.suffix, ex.cut)),
                       encoding="utf-8")
        written += [ok, exp]
    bad = folder / f"bad_template{examples[0].suffix}"
    bad.write_text("; a near miss of the construct that KRL must reject (reference section ...): write it by hand,\n"
                   "; rename the file bad_<what>.src, and make sure `krl validate " + name + "` rejects it\n",
                   encoding="utf-8")
    written.append(bad)
    changes = root / "grammar" / "CHANGES.md"
    row = (f"| {name}: (describe the construct, the rule added or changed) | (reference section) | {cluster_id} "
           f"({cluster.get('files', '?')} files: `{cluster.get('signature', '')}`) | {data.get('files_ok', '?')} -> "
           f"(measure with krl recover) | grammar: {name.replace('_', ' ')} |\n")
    old = changes.read_bytes() if changes.exists() else None
    text = old.decode("utf-8") if old is not None else "# Grammar changes\n"
    changes.parent.mkdir(parents=True, exist_ok=True)
    write_bytes(changes, (text.rstrip("\n") + "\n" + row).encode("utf-8"), expect=old)
    written.append(changes)
    cases = root / "conformance" / "cases"
    case = cases / f"{_next_case(cases):03d}_{name}"
    case.mkdir(parents=True)
    (case / "program.src").write_text(examples[0].text if examples[0].suffix == ".src" else
                                      f"DEF {case.name[:20]}()\nEND\n", encoding="utf-8")
    (case / "expect.yaml").write_text(
        f"title: {name.replace('_', ' ')} (stub made by krl construct new from cluster {cluster_id})\n"
        f"reference: \"(the reference section)\"\ncovers: [{name}]\nstatus: pending\n"
        f"reason: \"stub: write the program and its expected flow, I/O and motion by hand\"\n"
        f"end: {{reason: completed}}\n", encoding="utf-8")
    written += [case / "program.src", case / "expect.yaml"]
    return written
