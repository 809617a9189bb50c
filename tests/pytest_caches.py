"""pytest's caches of the test modules' rewritten code, written once before ``make test``'s
workers start (``python -m tests.pytest_caches``, the Makefile's ``test`` target).

pytest rewrites the asserts of every test module and conftest.py it imports and keeps the
rewritten code in a cache of its own beside the source (``__pycache__/NAME.cpython-311-pytest-
VERSION.pyc``, a hash-based pyc: valid while the source's hash matches, whatever its modification
time). On a fresh clone no such cache exists, and the three workers, which each collect every
test module at once, each rewrote all of them: 16.5 instead of 9 s of CPU for a collection
(2026-11-29). Here they are written once, one process per core, by pytest's own functions
(``_pytest.assertion.rewrite``: the same rewrite, the same file a worker would write), so each
worker reads them. pytest's default ``python_files`` (test_*.py, *_test.py) and conftest.py
under tests/, outside the folders pytest does not enter (:data:`NOT_ENTERED`). A cache that does
not match (another pytest, another source) is written again by the worker, as before; with
``enable_assertion_pass_hook`` set in pyproject.toml (a rewrite this module does not make)
nothing is written.

Run with the project's virtualenv (pytest installed); imports only the standard library and
pytest's rewrite at its top.
"""

from __future__ import annotations

import fnmatch
import os
import sys
import tomllib
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

from _pytest.assertion.rewrite import PYC_TAIL, _read_pyc, _rewrite_test, _write_pyc, get_cache_dir

TESTS = Path(__file__).resolve().parent
REPO = TESTS.parent
#: the test modules' names (pytest's default ``python_files``; pyproject.toml sets none)
PATTERNS = ("test_*.py", "*_test.py", "conftest.py")
#: folders pytest does not collect from (its default ``norecursedirs``, and caches)
NOT_ENTERED = ("*.egg", ".*", "_darcs", "build", "CVS", "dist", "node_modules", "venv", "{arch}", "__pycache__")


def modules(root: Path = TESTS) -> list[Path]:
    """The files under `root` whose asserts pytest rewrites (:data:`PATTERNS`), sorted."""
    out = []
    for folder, dirs, files in os.walk(root):
        dirs[:] = [d for d in dirs if not any(fnmatch.fnmatch(d, p) for p in NOT_ENTERED)]
        out.extend(Path(folder) / f for f in files if any(fnmatch.fnmatch(f, p) for p in PATTERNS))
    return sorted(out)


class _Trace:
    """The stand-in for pytest's assertion state that ``_write_pyc`` reports a failed write to
    (ignored, as pytest ignores it: the worker then rewrites the module itself)."""

    @staticmethod
    def trace(message: str) -> None:
        pass


def write(path: Path) -> bool:
    """Write `path`'s rewritten-code cache unless a valid one is there; True if written. A file
    that does not parse is left to pytest, which reports it at collection."""
    pyc = get_cache_dir(path) / (path.name[:-3] + PYC_TAIL)
    if _read_pyc(path, pyc) is not None:
        return False
    try:
        source_hash, code = _rewrite_test(path, None)
    except SyntaxError:
        return False
    pyc.parent.mkdir(exist_ok=True)
    return _write_pyc(_Trace(), code, source_hash, pyc)


def pass_hook_enabled(pyproject: Path = REPO / "pyproject.toml") -> bool:
    """pyproject.toml sets pytest's ``enable_assertion_pass_hook`` (then the rewrite differs)."""
    options = tomllib.loads(pyproject.read_text(encoding="utf-8")).get("tool", {}).get("pytest", {})
    return str(options.get("ini_options", {}).get("enable_assertion_pass_hook", "false")).lower() == "true"


def main(argv: list[str] | None = None, pyproject: Path = REPO / "pyproject.toml") -> int:
    """Write the caches of tests/ (or of the folders in `argv`), one process per core; none
    where `pyproject` enables the assertion pass hook."""
    if pass_hook_enabled(pyproject):
        return 0
    roots = [Path(a).absolute() for a in (sys.argv[1:] if argv is None else argv)] or [TESTS]
    paths = [p for root in roots for p in modules(root)]
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    with ProcessPoolExecutor(cores) as pool:
        list(pool.map(write, paths, chunksize=8))
    return 0


if __name__ == "__main__":
    sys.exit(main())
