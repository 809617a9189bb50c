"""tests/pytest_caches.py writes the caches pytest itself writes for the test modules it
rewrites, and pytest reads them instead of rewriting again. The expected caches are pytest's
own: a subprocess's pytest run on the same files."""

from __future__ import annotations

import marshal
import os
import subprocess
import sys
from pathlib import Path

from _pytest.assertion.rewrite import PYC_TAIL

from tests import pytest_caches

MODULE = "def helper():\n    return 2\n\n\ndef test_sum():\n    x = helper()\n    assert x + 1 == 4\n"
CONFTEST = "import pytest\n\n\n@pytest.fixture\ndef three():\n    assert True\n    return 3\n"


def _tree(root: Path) -> None:
    (root / "sub").mkdir(parents=True)
    (root / "test_one.py").write_text(MODULE, encoding="utf-8")
    (root / "sub" / "conftest.py").write_text(CONFTEST, encoding="utf-8")
    (root / "sub" / "check_test.py").write_text("def test_three(three):\n    assert three == 3\n", encoding="utf-8")
    (root / "helper.py").write_text("VALUE = 1\n", encoding="utf-8")            # not rewritten by pytest
    for skipped in ("node_modules", ".hidden", "build"):
        (root / skipped).mkdir()
        (root / skipped / "test_no.py").write_text("def test_no():\n    assert False\n", encoding="utf-8")


def _cache(path: Path) -> Path:
    return path.parent / "__pycache__" / (path.name[:-3] + PYC_TAIL)


def _pytest(root: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": ""}
    return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist",
                           "-p", "no:randomly", "--rootdir", str(root), str(root / "test_one.py"), str(root / "sub")],
                          cwd=root, env=env, capture_output=True, text=True, timeout=120)


def test_the_files_pytest_rewrites(tmp_path):
    _tree(tmp_path)
    assert pytest_caches.modules(tmp_path) == [tmp_path / "sub" / "check_test.py", tmp_path / "sub" / "conftest.py",
                                               tmp_path / "test_one.py"]


def test_caches_are_pytests_own_and_read_by_it(tmp_path):
    _tree(tmp_path)
    rewritten = pytest_caches.modules(tmp_path)
    assert pytest_caches.main([str(tmp_path)]) == 0
    ours = {p: _cache(p).read_bytes() for p in rewritten}
    stamps = {p: _cache(p).stat().st_mtime_ns for p in rewritten}
    assert not (tmp_path / "node_modules" / "__pycache__").exists()
    assert not _cache(tmp_path / "helper.py").exists()
    # pytest reads them: it leaves every cache as it is, and its assertion messages are the rewritten ones
    res = _pytest(tmp_path)
    assert "1 failed, 1 passed" in res.stdout, res.stdout + res.stderr
    assert "assert (2 + 1) == 4" in res.stdout           # the rewritten assert shows its values
    assert {p: _cache(p).stat().st_mtime_ns for p in rewritten} == stamps
    # and pytest, left to write them itself, writes the same header and code
    for p in rewritten:
        _cache(p).unlink()
    _pytest(tmp_path)
    for p in rewritten:
        theirs = _cache(p).read_bytes()
        assert theirs[:16] == ours[p][:16]
        assert marshal.loads(theirs[16:]) == marshal.loads(ours[p][16:])


def test_a_valid_cache_is_left_and_a_stale_one_written(tmp_path):
    _tree(tmp_path)
    module = tmp_path / "test_one.py"
    assert pytest_caches.write(module) is True
    assert pytest_caches.write(module) is False
    module.write_text(MODULE.replace("4", "3"), encoding="utf-8")
    assert pytest_caches.write(module) is True


def test_a_module_that_does_not_parse_is_left_to_pytest(tmp_path):
    broken = tmp_path / "test_broken.py"
    broken.write_text("def test(:\n", encoding="utf-8")
    assert pytest_caches.write(broken) is False
    assert not _cache(broken).exists()


def test_the_pass_hook_setting_is_read_from_pyproject(tmp_path):
    pyproject = tmp_path / "pyproject.toml"
    pyproject.write_text("[tool.pytest.ini_options]\nenable_assertion_pass_hook = true\n", encoding="utf-8")
    assert pytest_caches.pass_hook_enabled(pyproject)
    pyproject.write_text("[tool.pytest.ini_options]\ntimeout = 600\n", encoding="utf-8")
    assert not pytest_caches.pass_hook_enabled(pyproject)
    assert not pytest_caches.pass_hook_enabled()


def test_nothing_is_written_with_the_pass_hook(tmp_path):
    _tree(tmp_path)
    pyproject = tmp_path / "pyproject.toml"
    pyproject.write_text("[tool.pytest.ini_options]\nenable_assertion_pass_hook = true\n", encoding="utf-8")
    assert pytest_caches.main([str(tmp_path)], pyproject) == 0
    assert not any(_cache(p).exists() for p in pytest_caches.modules(tmp_path))
    pyproject.write_text("[tool.pytest.ini_options]\n", encoding="utf-8")
    assert pytest_caches.main([str(tmp_path)], pyproject) == 0
    assert all(_cache(p).exists() for p in pytest_caches.modules(tmp_path))
