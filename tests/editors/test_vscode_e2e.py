"""The extension in a real VS Code: code-server (VS Code served to a browser, from the npm registry,
editors/vscode/test/e2e) with the .vsix that `make vsix` builds installed, driven by headless
Debian Chromium through Playwright. It opens a backup with an undeclared name and checks what a
user sees: the file's language is KRL (also for an upper-case .SRC), the server's diagnostic is
underlined and listed in the Problems panel with its code and message.

Slow (make nightly): a cold install of code-server builds its native modules (about 6 minutes
on the shared machine). What the install needs, found by trying it here (the README's "VS Code
extension" section says so too):
- Node.js 20 exactly: code-server 4.99.4's postinstall.sh refuses any other major version;
- Debian's build headers for its native modules: libkrb5-dev (kerberos: 'gssapi/gssapi.h: No such
  file or directory' without it), libx11-dev, libxkbfile-dev (native-keymap), libsecret-1-dev,
  pkg-config;
- ripgrep: @vscode/ripgrep 1.15.11 downloads its binary from GitHub in its postinstall
  ('getaddrinfo ENOTFOUND api.github.com' here); it first looks in its download cache
  (os.tmpdir()/vscode-ripgrep-cache-1.15.11/), which is filled from Debian's ripgrep;
- npm_config_yes=true (node-pty's postinstall runs `npx node-gyp`, which a `yes=false` npm
  configuration cancels) and npm_config_unsafe_perm=true (its postinstall refuses root without).
"""

from __future__ import annotations

import os
import platform
import shutil
import signal
import socket
import subprocess
import sys
import tarfile
import tempfile
import time
import urllib.request
from pathlib import Path

import pytest

from tests.system_tools import NIGHTLY_PACKAGES, install_command, missing_packages, require
from tests.conftest import REPO_ROOT
from tests.editors.npm import EXTENSION, build_vsix, node_or_fail, npm_install
from tests.lsp.conftest import BACKUP

pytestmark = pytest.mark.slow

E2E = EXTENSION / "test" / "e2e"
CODE_SERVER_NODE_MAJOR = "20"
# @vscode/ripgrep 1.15.11 (code-server 4.99.4's lib/vscode/npm-shrinkwrap.json): lib/postinstall.js
# VERSION and the asset name it looks for in its cache folder before any download
RIPGREP_PACKAGE = "1.15.11"
RIPGREP_RELEASE = "v13.0.0-10"
RIPGREP_TARGET = {"x86_64": "x86_64-unknown-linux-musl", "aarch64": "aarch64-unknown-linux-musl"}
INSTALL_TIMEOUT_S = 1800
CHROMIUM = "/usr/bin/chromium"
FLAGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync"]
UI_TIMEOUT_MS = 120_000


def _fail_or_skip(why: str):
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(why)
    pytest.skip(why)


def _fill_ripgrep_cache() -> None:
    target = RIPGREP_TARGET.get(platform.machine())
    rg = shutil.which("rg")
    if target is None or rg is None:
        _fail_or_skip(f"no ripgrep for @vscode/ripgrep's cache (machine {platform.machine()}, rg {rg})")
    cache = Path(tempfile.gettempdir()) / f"vscode-ripgrep-cache-{RIPGREP_PACKAGE}"
    cache.mkdir(exist_ok=True)
    archive = cache / f"ripgrep-{RIPGREP_RELEASE}-{target}.tar.gz"
    if not archive.exists():
        with tarfile.open(archive, "w:gz") as tar:
            tar.add(rg, arcname="rg")


@pytest.fixture(scope="module")
def code_server() -> Path:
    node_or_fail()
    major = subprocess.run(["node", "-p", "process.versions.node.split('.')[0]"], capture_output=True,
                           text=True, check=False).stdout.strip()
    if major != CODE_SERVER_NODE_MAJOR:
        _fail_or_skip(f"code-server 4.99.4 installs only with Node.js {CODE_SERVER_NODE_MAJOR} (found {major})")
    missing = missing_packages(NIGHTLY_PACKAGES)      # make nightly installs them (tests/system_tools.py)
    if missing:
        pytest.fail(f"Debian packages missing for code-server's install: {install_command(missing)}", pytrace=False)
    _fill_ripgrep_cache()
    env = dict(os.environ, npm_config_yes="true", npm_config_unsafe_perm="true")
    npm_install(E2E, env=env, timeout=INSTALL_TIMEOUT_S)
    binary = E2E / "node_modules" / ".bin" / "code-server"
    assert binary.exists()
    return binary


@pytest.fixture(scope="module")
def chromium() -> str:
    return require("chromium")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _workspace(tmp_path: Path) -> tuple[Path, Path, Path]:
    root = tmp_path / "KRC"
    shutil.copytree(BACKUP, root)
    main = root / "R1" / "Program" / "main.src"
    # line 9 (1-based) `  countr = 0`: an undeclared name (E101)
    main.write_text(main.read_text().replace("  counter = 0\n", "  countr = 0\n"))
    upper = root / "R1" / "Program" / "CELL2.SRC"
    upper.write_text("DEF CELL2( )\nEND\n")
    return root, main, upper


def _open(page, name: str) -> None:
    page.keyboard.press("Control+P")
    box = page.locator(".quick-input-widget .quick-input-box input")
    box.wait_for(timeout=UI_TIMEOUT_MS)
    box.fill(name)
    page.locator(".quick-input-list .monaco-list-row").first.wait_for(timeout=UI_TIMEOUT_MS)
    page.keyboard.press("Enter")
    page.locator(f".tabs-container .tab.active:has-text('{name}')").wait_for(timeout=UI_TIMEOUT_MS)


def test_the_extension_in_code_server(code_server: Path, chromium: str, tmp_path: Path, pw):

    root, _main, _upper = _workspace(tmp_path)
    vsix = build_vsix(tmp_path / "krl.vsix")
    user, exts, config = tmp_path / "user", tmp_path / "extensions", tmp_path / "config"
    (user / "User").mkdir(parents=True)
    krl = Path(sys.executable).parent / "krl"
    (user / "User" / "settings.json").write_text(
        '{"krl.server.path": "%s", "workbench.startupEditor": "none", "security.workspace.trust.enabled": false,'
        ' "telemetry.telemetryLevel": "off", "extensions.autoCheckUpdates": false, "extensions.autoUpdate": false}'
        % krl)
    env = dict(os.environ, XDG_CONFIG_HOME=str(config), PYTHONPATH=str(REPO_ROOT))
    base = [str(code_server), "--extensions-dir", str(exts), "--user-data-dir", str(user)]
    install = subprocess.run([*base, "--install-extension", str(vsix)], capture_output=True, text=True, env=env,
                             timeout=300, check=False)
    assert install.returncode == 0 and "successfully installed" in install.stdout, install.stdout + install.stderr
    port = _free_port()
    server = subprocess.Popen([*base, "--auth", "none", "--bind-addr", f"127.0.0.1:{port}", "--disable-telemetry",
                               "--disable-update-check", "--disable-workspace-trust", str(root)],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, env=env, start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while True:
            try:
                urllib.request.urlopen(f"http://127.0.0.1:{port}/healthz", timeout=5)
                break
            except OSError:
                assert time.monotonic() < deadline and server.poll() is None, "code-server did not start"
                time.sleep(0.5)
        with tempfile.TemporaryDirectory() as profile:
            ctx = pw.chromium.launch_persistent_context(profile, executable_path=chromium, headless=True,
                                                        args=FLAGS, viewport={"width": 1400, "height": 900})
            page = ctx.new_page()
            try:
                page.goto(f"http://127.0.0.1:{port}/?folder={root}")
                page.locator(".monaco-workbench").wait_for(timeout=UI_TIMEOUT_MS)
                _open(page, "main.src")
                # the server's E101 on `countr` (line 9): underlined in the editor ...
                page.locator(".monaco-editor .squiggly-error").first.wait_for(timeout=UI_TIMEOUT_MS)
                status = page.locator(".statusbar")
                assert "KRL" in status.inner_text()
                # ... highlighted by the TextMate grammar (a keyword has a theme colour of its own) ...
                line = page.locator(".monaco-editor .view-line:has-text('INTERRUPT ON 3')")
                spans = line.locator("span span")
                classes = {spans.nth(i).inner_text(): spans.nth(i).get_attribute("class") for i in range(spans.count())}
                assert classes["INTERRUPT"] != classes["3"]
                # ... and listed in the Problems panel with its code and message
                page.keyboard.press("Control+Shift+M")
                markers = page.locator(".markers-panel .monaco-list-row:has-text('countr')").first
                markers.wait_for(timeout=UI_TIMEOUT_MS)
                text = markers.inner_text()
                assert "'countr' is not declared" in text and "E101" in text
                # an upper-case extension is KRL too (VS Code compares extensions without case):
                # opened from the Explorer, as a user does
                page.locator(".explorer-folders-view .monaco-list-row:has-text('CELL2.SRC')").click()
                page.locator(".tabs-container .tab.active:has-text('CELL2.SRC')").wait_for(timeout=UI_TIMEOUT_MS)
                page.wait_for_function("document.querySelector('.statusbar').innerText.includes('KRL')",
                                       timeout=UI_TIMEOUT_MS)
            finally:
                page.screenshot(path=str(tmp_path / "code-server.png"))   # for a look when it fails
                ctx.close()
    finally:
        os.killpg(server.pid, signal.SIGTERM)
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)
            server.wait()
