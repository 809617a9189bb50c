"""One night's figures and item statuses, read from its dated folder.

A *figure* is one number of the night (``conformance.passed``, ``bench.vm_vs_tree``); its
:class:`Figure` kind says how a change is judged: ``count`` (an exact number: every change
is flagged), ``ratio`` (a measured speed ratio: flagged outside the noise band of the
history, :mod:`.flags`) or ``info`` (charted, never flagged). An *item* is one named thing
with a status (``case``: a conformance case, pass/FAIL/pending; ``corpus_file``: a file of
the shared corpus, its recovery status; ``real_program``: a corpus program, how its run
ended). Missing files give missing figures, never an error: a night whose bench step failed
still records its conformance.

Files read (all written by the project's own tools; each one is untrusted only in the sense
that a damaged file is skipped with a note):
``recovery/summary.json`` and ``recovery/files.csv`` (krl recover), ``check/check_report.json``
(krl check --report), ``conformance/summary.json`` (krl conformance), ``bench.json``
(krl bench --json), ``bench-parse.json`` (krl bench parse --json), ``limits.jsonl``
(python -m robot.limits_bench), ``lsp-bench.json`` (python -m krl.lsp.bench --json),
``fuzz/summary.json`` (python -m tests.fuzz.run), ``whole-runs.json`` (tools/whole_run_bench.py:
every corpus entry point with ``--inputs auto``, 600 s simulated), ``whole-runs-history.json``
(the same over the backups of ../shared/krl-history) and ``variants.json`` (python -m
interp.variants: every generated variant of those backups, issue 59).
"""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: figure name prefix or name -> kind; the first matching entry wins
KINDS: tuple[tuple[str, str], ...] = (
    ("bench.parse_kb_per_s", "info"),     # an absolute rate: the machine's speed, not the code's
    ("bench.", "ratio"),
    ("lsp.", "ratio"),
    ("conformance.fuzz_programs", "info"),
    ("fuzz.runs", "info"),
    ("", "count"),
)

#: the figures every night is expected to have, in the order of the index page
CORE = ("conformance.cases", "conformance.passed", "conformance.tree_vm_agree", "conformance.fuzz_agree",
        "corpus.files_ok", "corpus.known_invalid", "check.errors", "check.warnings",
        "real.completed", "limits.breaches", "bench.parse_speedup", "bench.vm_vs_tree",
        "bench.sim_realtime_factor", "lsp.change_p50_ms")


def kind_of(name: str) -> str:
    """The kind (count, ratio, info) of figure ``name``."""
    for prefix, kind in KINDS:
        if name.startswith(prefix):
            return kind
    return "count"


@dataclass
class Night:
    """One night: ``figures`` name -> number, ``items`` (kind, name) -> status, ``notes``
    about files that were missing or unreadable, ``links`` item kind -> report path."""
    date: str
    figures: dict[str, float] = field(default_factory=dict)
    items: dict[tuple[str, str], str] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


def _json(path: Path, night: Night) -> Any:
    if not path.is_file():
        night.notes.append(f"{path.name}: not written this night")
        return None
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        night.notes.append(f"{path.name}: unreadable ({type(exc).__name__})")
        return None


def _num(value: Any) -> float | None:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def _put(night: Night, name: str, value: Any) -> None:
    v = _num(value)
    if v is not None:
        night.figures[name] = v


def _conformance(day: Path, night: Night) -> None:
    s = _json(day / "conformance" / "summary.json", night)
    if not isinstance(s, dict):
        return
    for key in ("cases", "passed", "tree_vm_agree", "fuzz_programs", "fuzz_agree", "real_programs", "real_agree"):
        _put(night, f"conformance.{key}", s.get(key))
    for name, status in (s.get("case_status") or {}).items():
        night.items[("case", str(name))] = str(status)
    causes = s.get("real_causes") or s.get("real_tree_reasons") or {}
    for cause, count in causes.items():
        _put(night, f"real.{cause}", count)
    for prog, status in (s.get("real_status") or {}).items():
        night.items[("real_program", str(prog))] = str(status)


def _recovery(day: Path, night: Night) -> None:
    s = _json(day / "recovery" / "summary.json", night)
    if isinstance(s, dict):
        _put(night, "corpus.files", s.get("files"))
        _put(night, "corpus.files_ok", s.get("files_ok"))
        ki = s.get("known_invalid") or {}
        _put(night, "corpus.known_invalid", ki.get("still_failing"))
        neg = s.get("negative") or {}
        _put(night, "negative.rejected", neg.get("rejected"))
        _put(night, "negative.programs", neg.get("programs"))
    files = day / "recovery" / "files.csv"
    if files.is_file():
        try:
            with files.open(encoding="utf-8", newline="") as fh:
                for row in csv.DictReader(fh):
                    if row.get("path"):
                        night.items[("corpus_file", row["path"])] = row.get("status", "")
        except (OSError, csv.Error, UnicodeDecodeError) as exc:
            night.notes.append(f"files.csv: unreadable ({type(exc).__name__})")


def _check(day: Path, night: Night) -> None:
    s = _json(day / "check" / "check_report.json", night)
    if not isinstance(s, dict):
        return
    total = s.get("total") or {}
    _put(night, "check.errors", total.get("errors"))
    _put(night, "check.warnings", total.get("warnings"))
    for b in s.get("backups") or []:
        if isinstance(b, dict) and b.get("backup"):
            _put(night, f"check.{b['backup']}.errors", b.get("errors"))
            _put(night, f"check.{b['backup']}.warnings", b.get("warnings"))


def _bench(day: Path, night: Night) -> None:
    b = _json(day / "bench.json", night)
    if isinstance(b, dict):
        for key in ("vm_vs_tree", "sim_realtime_factor", "parse_kb_per_s"):
            _put(night, f"bench.{key}", b.get(key))
    p = _json(day / "bench-parse.json", night)
    if isinstance(p, dict):
        _put(night, "bench.parse_speedup", p.get("speedup"))
    # the whole runs of the corpus's entry points, and of the history backups' (material that
    # is not the corpus: the nearest to a backup nobody here has seen)
    for name, tag in (("whole-runs.json", "whole_runs"), ("whole-runs-history.json", "whole_runs_history")):
        whole = _json(day / name, night)
        if isinstance(whole, dict) and isinstance(whole.get("summary"), dict):
            new = whole["summary"].get("new") or {}
            if isinstance(new, dict):
                # simulated s per CPU s of the whole runs together (a ratio), and how many entry
                # points took more than 3 s of CPU for 600 s (a count: issue 48's bound)
                _put(night, f"bench.{tag}_sim_per_cpu", new.get("sim_per_cpu"))
                _put(night, f"{tag}.over_3s", new.get("over_3s"))
    lsp = _json(day / "lsp-bench.json", night)
    if isinstance(lsp, dict):
        for key in ("change_p50_ms", "change_p95_ms", "first_diagnostics_s"):
            _put(night, f"lsp.{key}", lsp.get(key))


def _limits(day: Path, night: Night) -> None:
    path = day / "limits.jsonl"
    if not path.is_file():
        night.notes.append("limits.jsonl: not written this night")
        return
    breaches = worst = 0.0
    try:
        for line in path.read_text(encoding="utf-8").splitlines():
            if line.strip():
                row = json.loads(line)
                breaches += float(row.get("violations", 0))
                worst = max(worst, *(float(row.get(k, 0)) for k in ("path", "axis_speed", "axis_acc", "flange")))
    except (OSError, ValueError, TypeError) as exc:
        night.notes.append(f"limits.jsonl: unreadable ({type(exc).__name__})")
        return
    night.figures["limits.breaches"] = breaches
    night.figures["limits.worst_ratio"] = round(worst, 3)


def _fuzz(day: Path, night: Night) -> None:
    s = _json(day / "fuzz" / "summary.json", night)
    if isinstance(s, dict):
        _put(night, "fuzz.findings", s.get("findings"))
        _put(night, "fuzz.runs", s.get("runs"))


def _variants(day: Path, night: Night) -> None:
    """``variants.json`` (python -m interp.variants, issue 59): how many variants of the corpus's
    and the history's backups ran, how many runs, how many ended by each cause, and the runs that
    stopped on a name the checker classifies as installed software or failed internally (counts:
    every change is flagged)."""
    s = _json(day / "variants.json", night)
    if not isinstance(s, dict) or not isinstance(s.get("summary"), dict):
        return
    summary = s["summary"]
    for key in ("variants", "runs", "outside_stops", "internal"):
        _put(night, f"variants.{key}", summary.get(key))
    causes = summary.get("causes")
    if isinstance(causes, dict):
        for cause, n in causes.items():
            _put(night, f"variants.cause.{str(cause).replace(' ', '_')}", n)


def read_night(day: Path) -> Night:
    """The figures and items of the dated folder ``day`` (its name is the date)."""
    night = Night(day.name)
    for part in (_conformance, _recovery, _check, _bench, _limits, _fuzz, _variants):
        part(day, night)
    return night
