"""The VS Code extension's client against the real server, through node: editors/vscode/test/client/
diagnostics.js starts `krl lsp` as extension.js does (the default command and arguments of the
settings krl.server.path / krl.server.args, stdio) with the protocol library the client is built
on (vscode-languageserver-protocol), opens a file and prints the diagnostics it receives.

The expected diagnostics are counted by hand from the files' text."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

from tests.conftest import REPO_ROOT
from tests.editors.npm import EXTENSION, npm_ci
from tests.lsp.conftest import BACKUP

CLIENT = EXTENSION / "test" / "client" / "diagnostics.js"
RUN_TIMEOUT_S = 240


def krl_command() -> Path:
    """The `krl` command of the virtualenv that runs the tests (the extension's default is `krl`
    on PATH; here the same entry point, by its full path as the setting krl.server.path allows)."""
    krl = Path(sys.executable).parent / "krl"
    assert krl.exists(), f"{krl} missing: the project's console script (pyproject.toml) is not installed"
    return krl


def client_diagnostics(workspace: Path, *files: Path) -> dict:
    npm_ci()
    env = dict(os.environ, PYTHONPATH=str(REPO_ROOT))
    run = subprocess.run(["node", str(CLIENT), str(krl_command()), "", str(workspace), *map(str, files)],
                         capture_output=True, text=True, env=env, timeout=RUN_TIMEOUT_S, check=False)
    assert run.returncode == 0, f"exit {run.returncode}: {run.stderr[-3000:]}"
    return json.loads(run.stdout)


def rows(diagnostics: list[dict]) -> list[tuple]:
    return [(d["code"], d["range"]["start"]["line"], d["range"]["start"]["character"],
             d["range"]["end"]["line"], d["range"]["end"]["character"], d["severity"], d["message"])
            for d in diagnostics if d["severity"] != 4]     # hints (never-read variables) aside


def test_the_client_starts_krl_lsp_and_receives_a_diagnostic(tmp_path: Path):
    root = tmp_path / "KRC"
    shutil.copytree(BACKUP, root)
    main = root / "R1" / "Program" / "main.src"
    # line 9 (1-based) `  countr = 0`: an undeclared name at 0-based line 8, characters 2..8
    main.write_text(main.read_text().replace("  counter = 0\n", "  countr = 0\n"))
    out = client_diagnostics(root, main)
    assert out["exitCode"] == 0                      # shutdown + exit: the server ends cleanly
    caps = out["capabilities"]
    assert caps["textDocumentSync"]["openClose"] is True and caps["hoverProvider"] is True
    assert rows(out["diagnostics"][str(main)]) == [("E101", 8, 2, 8, 8, 1, "'countr' is not declared")]


def test_the_client_receives_the_diagnostics_of_a_real_corpus_file(shared_corpus: Path):
    # a real program (a folder with System/$config.dat: the server reads it as one backup)
    backup = shared_corpus / "ingeniado__KRC4-Robot-Palletizer"
    main = backup / "main.src"
    assert main.read_text(encoding="latin-1").splitlines()[3] == "DEF  CELL ( )"
    out = client_diagnostics(backup, main)
    # line 4 `DEF  CELL ( )` in main.src: the main routine is not named after the file (W111,
    # a warning: severity 2), on the keyword DEF (0-based line 3, characters 0..3)
    assert rows(out["diagnostics"][str(main)]) == [
        ("W111", 3, 0, 3, 3, 2, "main routine 'CELL' differs from the file name 'main'")]
