"""Run the coverage-guided fuzzers: ``python -m tests.fuzz.run [TARGET ...] --seconds N --out DIR``.

One atheris process per target (tests/fuzz/targets.py), seeded from the real corpus
(../shared/krl-corpus, when present), the embedded corpus, the negative corpus, the
conformance cases and the committed crash files, for ``--seconds`` each. A finding (an
input that breaks the target's property: a crash, a timeout, an out-of-memory) is minimized
by libFuzzer and written to ``DIR/<target>/``; with ``--keep`` it is also copied to
``tests/fuzz/crashes/<target>/`` where tests/fuzz/test_crashes.py turns it into a regression
test of `make test` (fix the cause, then commit the file). ``DIR/summary.json``:
``{"targets": {name: {"seconds", "runs", "findings", "exit"}}, "runs", "findings"}``.
Exit 0 without findings, 1 with findings, 2 when a target could not run.

``make nightly`` runs every target for ``FUZZ_SECONDS``; `make test` runs each for a few
seconds (tests/fuzz/test_fuzz_short.py) so that the harness cannot rot.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from tests.fuzz.targets import MAX_INPUT, TARGETS

REPO = Path(__file__).resolve().parents[2]
CRASHES = Path(__file__).resolve().parent / "crashes"
SHARED = REPO.parent / "shared" / "krl-corpus"
MAX_SEEDS = 400
KRL_SUFFIXES = (".src", ".dat", ".sub")


def seed_files(target: str, most: int = MAX_SEEDS) -> list[Path]:
    """The seed inputs of ``target`` (at most ``most`` files of at most MAX_INPUT bytes, spread
    over the sources; the committed crash files always)."""
    if target == "stimuli":
        roots = [REPO / "conformance" / "cases", REPO / "corpus" / "cells"]
        found = [p for r in roots if r.is_dir() for p in sorted(r.rglob("*.yaml"))]
    else:
        roots = [REPO / "conformance" / "cases", REPO / "corpus", REPO / "tests" / "negative", SHARED]
        found = [p for r in roots if r.is_dir() for p in sorted(r.rglob("*"))
                 if p.suffix.lower() in KRL_SUFFIXES and not p.is_symlink()]
    small = [p for p in found if p.is_file() and p.stat().st_size <= MAX_INPUT]
    step = max(1, len(small) // max(1, most))
    crashes = sorted((CRASHES / target).glob("*")) if (CRASHES / target).is_dir() else []
    return small[::step][:most] + crashes


def _stats(output: str) -> int:
    m = re.findall(r"stat::number_of_executed_units:\s*(\d+)", output) or re.findall(r"#(\d+)\s+DONE", output)
    return int(m[-1]) if m else 0


def run_target(target: str, seconds: int, out: Path, keep: bool = False, seeds: int = MAX_SEEDS,
               runs: int = -1) -> dict:
    """Fuzz one target for ``seconds`` (and at most ``runs`` inputs, -1: no bound) from at most
    ``seeds`` seed files; returns its summary entry."""
    art = out / target
    art.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    with tempfile.TemporaryDirectory(prefix=f"krl-fuzz-{target}-") as tmp:
        seed_dir = Path(tmp)
        for i, p in enumerate(seed_files(target, seeds)):
            shutil.copyfile(p, seed_dir / f"{i:04d}{p.suffix}")
        cmd = [sys.executable, "-m", "tests.fuzz.atheris_main", target, str(seed_dir),
               f"-max_total_time={seconds}", f"-runs={runs}", f"-max_len={MAX_INPUT}", "-timeout=60", "-rss_limit_mb=4096",
               f"-artifact_prefix={art}/", "-print_final_stats=1"]
        res = subprocess.run(cmd, cwd=REPO, env=env, capture_output=True, text=True,
                             timeout=seconds + 600, check=False)
    # atheris prints an uncaught exception's traceback on stdout, libFuzzer its report on stderr
    (art / "fuzz.log").write_text((res.stdout[-100_000:] + res.stderr[-200_000:]), encoding="utf-8")
    # libFuzzer's slow-unit files (an input over 10 s) are load on a shared machine, not a finding;
    # a timeout (-timeout=60), a crash and an out-of-memory are
    findings = sorted(p for p in art.iterdir() if p.name.startswith(("crash-", "timeout-", "oom-")))
    slow = sorted(p.name for p in art.iterdir() if p.name.startswith("slow-unit-"))
    kept = []
    for p in findings:
        small = p.with_name("min-" + p.name)
        subprocess.run([sys.executable, "-m", "tests.fuzz.atheris_main", target, "-minimize_crash=1",
                        "-max_total_time=60", f"-exact_artifact_path={small}", str(p)],
                       cwd=REPO, env=env, capture_output=True, timeout=900, check=False)
        data = (small if small.is_file() else p).read_bytes()
        if keep:
            dest = CRASHES / target / (hashlib.sha256(data).hexdigest()[:16] + ".bin")
            dest.parent.mkdir(parents=True, exist_ok=True)
            dest.write_bytes(data)
            kept.append(str(dest.relative_to(REPO)))
    status = res.returncode if not findings else 1
    return {"seconds": seconds, "runs": _stats(res.stderr), "findings": len(findings),
            "files": [p.name for p in findings], "slow": slow, "kept": kept, "exit": status}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("targets", nargs="*", choices=[[], *TARGETS], default=[], metavar="TARGET",
                    help=f"targets (default: all): {', '.join(TARGETS)}")
    ap.add_argument("--seconds", type=int, default=60, help="time budget per target (s)")
    ap.add_argument("--out", type=Path, default=Path("reports/fuzz"), help="summary and findings")
    ap.add_argument("--keep", action="store_true", help="copy minimized findings to tests/fuzz/crashes/")
    ap.add_argument("--seeds", type=int, default=MAX_SEEDS, help="seed files per target at most")
    ap.add_argument("--runs", type=int, default=-1, help="inputs per target at most (-1: the time decides)")
    a = ap.parse_args(argv)
    names = a.targets or list(TARGETS)
    a.out.mkdir(parents=True, exist_ok=True)
    summary = {"targets": {}, "runs": 0, "findings": 0}
    for name in names:
        entry = run_target(name, a.seconds, a.out, a.keep, a.seeds, a.runs)
        summary["targets"][name] = entry
        summary["runs"] += entry["runs"]
        summary["findings"] += entry["findings"]
        print(f"{name:13s} {entry['runs']:8d} runs  {entry['findings']} finding(s)  exit {entry['exit']}")
    (a.out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    if summary["findings"]:
        return 1
    return 2 if any(e["exit"] not in (0,) for e in summary["targets"].values()) else 0


if __name__ == "__main__":
    sys.exit(main())
