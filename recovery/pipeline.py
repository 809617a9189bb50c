"""The recovery job: scan, cluster, measure the negative corpus, write the report."""

from __future__ import annotations

import csv
import hashlib
import json
import time
from pathlib import Path

from krl import store
from krl.durable import write_text
from krl.limits import PARSE_TIMEOUT_S
from recovery.report import ReportStream, Summary, SummaryBuilder
from recovery.scan import FileResult, cache_dir, grammar_sha, scan, warn
from krl.project import find_backups
from krl.survey.report import check_report

REPO_ROOT = Path(__file__).resolve().parents[1]
GRAMMAR = REPO_ROOT / "grammar" / "KRL.g4"
NEGATIVE_DIR = REPO_ROOT / "tests" / "negative"
KNOWN_INVALID = REPO_ROOT / "corpus" / "known-invalid.csv"


def current_grammar_sha() -> str:
    return grammar_sha(GRAMMAR.read_text(encoding="utf-8"))


def negative_figures(gsha: str, jobs: int | None, use_cache: bool) -> dict | None:
    """How many programs of tests/negative the grammar rejects (the target is all)."""
    if not NEGATIVE_DIR.is_dir():
        return None
    results = scan(NEGATIVE_DIR, gsha, jobs=jobs, use_cache=use_cache, progress=False)
    accepted = [r.path for r in results if r.ok]
    return {"programs": len(results), "rejected": len(results) - len(accepted), "accepted": accepted}


def load_known_invalid(path: Path = KNOWN_INVALID) -> dict[str, str]:
    """corpus/known-invalid.csv: path (relative to the shared corpus) -> reason."""
    if not path.exists():
        return {}
    with path.open(newline="", encoding="utf-8") as fh:
        return {row["path"]: row["reason"] for row in csv.DictReader(fh) if row.get("path")}


def _known_invalid_figures(present: dict[str, bool]) -> dict | None:
    """Figures of the known-invalid files present: `present` maps their paths to whether they parse."""
    if not present:
        return None
    return {"listed": len(load_known_invalid()), "present": len(present),
            "still_failing": sum(not ok for ok in present.values()),
            "now_parsing": sorted(p for p, ok in present.items() if ok)}


def _front_end_code_sha() -> str:
    h = hashlib.sha256()
    for p in sorted((REPO_ROOT / "krl").rglob("*")):
        if p.is_file() and "generated" not in p.parts and p.suffix in (".py", ".yaml"):
            h.update(p.as_posix().encode())
            h.update(p.read_bytes())
    return h.hexdigest()


def static_check_figures(corpus: Path, fingerprints: list[str], gsha: str,
                         use_cache: bool, jobs: int | None = None,
                         timeout: float | None = PARSE_TIMEOUT_S) -> dict | None:
    """`krl check` over the KRC backups of the corpus (issue 4's report), cached by the
    grammar, the front end's code and the corpus files (`fingerprints`: "path:sha" of every
    scanned file). Files are parsed and built in `jobs`
    worker processes (the scan's pool, krl/pool.py), each stopped past `timeout` seconds."""

    if not find_backups(corpus):
        return None
    key = hashlib.sha256("|".join([gsha, _front_end_code_sha()] +
                                  sorted(fingerprints)).encode()).hexdigest()
    path = None
    if use_cache:       # --no-cache never touches the cache folder
        try:
            path = cache_dir() / "check" / f"{key[:32]}.json"
        except OSError:
            path = None  # the scan has already warned that the cache folder is not usable
    if path is not None and path.exists():
        try:
            cached = json.loads(path.read_text(encoding="utf-8"))
            if _valid_check_figures(cached):
                return cached
        except (OSError, ValueError, RecursionError):
            pass
        warn(f"cache file {path} is corrupt; ignored and rebuilt")

    data, markdown = check_report(corpus, timeout=timeout, jobs=jobs)
    figures = {"files": data["total"]["files"], "files_clean": data["total"]["files_clean"],
               "errors": data["total"]["errors"], "warnings": data["total"]["warnings"],
               "top_kinds": data["top_kinds"], "markdown": markdown}
    if path is not None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_text(path, json.dumps(figures))
        except OSError as exc:
            warn(f"cache file {path} not written ({exc.strerror or exc})")
    return figures


def _valid_check_figures(obj: object) -> bool:
    types = {"files": int, "files_clean": int, "errors": int, "warnings": int, "top_kinds": list,
             "markdown": str}
    return (isinstance(obj, dict) and set(obj) == set(types)
            and all(isinstance(obj[k], t) for k, t in types.items())
            and all(isinstance(k, dict) for k in obj["top_kinds"]))


def run_recovery(corpus: Path, out: Path, jobs: int | None = None, use_cache: bool = True,
                 timeout: float = PARSE_TIMEOUT_S, label: str | None = None,
                 scheduler: str | None = None) -> Summary:
    """Scan `corpus`, cluster, add the negative-corpus and static-check figures and write the
    report to `out`. `label`: how the report names the corpus when it is not the folder itself
    (a backup .zip extracted to a temporary folder: the report then names the archive and does
    not link to the vanished files). Rows stream to ``files.csv`` (in a temporary folder next to `out`) as files
    finish and only counts and clusters are kept, so memory stays flat with the corpus size;
    the folder replaces `out` atomically at the end (recovery/report.py). Raises ReportError
    when `out` holds files that are not a report."""
    if use_cache:
        return _run_recovery(corpus, out, jobs, use_cache, timeout, label, scheduler)
    with store.turned_off():       # --no-cache: nothing reads or writes the cache folder
        return _run_recovery(corpus, out, jobs, use_cache, timeout, label, scheduler)


def _run_recovery(corpus: Path, out: Path, jobs: int | None, use_cache: bool, timeout: float,
                  label: str | None, scheduler: str | None) -> Summary:
    start = time.perf_counter()
    gsha = current_grammar_sha()
    known = load_known_invalid()
    builder = SummaryBuilder(known)
    with ReportStream(Path(out)) as stream:
        def on_row(index: int, row: FileResult) -> None:
            builder.add(index, row)
            stream.add(index, row)

        scan(corpus, gsha, jobs=jobs, use_cache=use_cache, timeout=timeout, on_row=on_row, keep=False,
             scheduler=scheduler)
        summary = builder.summary(gsha, label or str(corpus), 0.0)
        summary.negative = negative_figures(gsha, jobs, use_cache)
        ki = _known_invalid_figures(builder.known_ok)
        if ki:
            summary.extra["known_invalid"] = ki
        check = static_check_figures(Path(corpus), builder.fingerprints, gsha, use_cache, jobs=jobs,
                                     timeout=timeout)
        if check:
            summary.extra["check"] = check
        summary.seconds = time.perf_counter() - start
        stream.commit(summary, builder.bad_input)
    return summary
