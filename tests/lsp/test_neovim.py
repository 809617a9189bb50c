"""A real editor: Neovim (Debian package `neovim`), headless, with its built-in LSP client
started on `krl lsp` from a Lua config; it opens a file with an error, waits for the
diagnostics and writes what vim.diagnostic.get() returns to a file."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.lsp.conftest import BACKUP

LUA = r"""
local out = os.getenv("KRL_NVIM_OUT")
local cmd = { os.getenv("KRL_PYTHON"), "-m", "krl.lsp" }
local root = os.getenv("KRL_ROOT")
vim.api.nvim_create_autocmd("VimEnter", { callback = function()
  local config = { name = "krl", cmd = cmd, root_dir = root }
  if vim.lsp.start then
    vim.lsp.start(config)
  else  -- Neovim 0.7 (Debian 12): no vim.lsp.start yet
    local id = vim.lsp.start_client(config)
    vim.lsp.buf_attach_client(0, id)
  end
  vim.wait(90000, function() return #vim.diagnostic.get(0) > 0 end, 100)
  local lines = {}
  for _, d in ipairs(vim.diagnostic.get(0)) do
    local code = d.code or (d.user_data and d.user_data.lsp and d.user_data.lsp.code) or ""
    table.insert(lines, string.format("%s|%d|%d|%s", code, d.lnum, d.col, d.message))
  end
  vim.fn.writefile(lines, out)
  vim.cmd("qa!")
end })
"""


def neovim() -> str | None:
    """nvim, installed with apt-get when missing (as the test set-up); None if that fails."""
    from tests.apt import apt_install  # noqa: PLC0415

    return apt_install("neovim", "nvim")


@pytest.mark.may_skip("Neovim is not installed and cannot be installed here (no apt-get, not root, or no package source)")
def test_neovim_reads_krl_diagnostics(tmp_path: Path):
    nvim = neovim()
    if nvim is None:
        pytest.skip("nvim missing and `apt-get install -y neovim` not possible")
    root = tmp_path / "KRC"
    shutil.copytree(BACKUP, root)
    main = root / "R1" / "Program" / "main.src"
    # line 9 (1-based) uses an undeclared name: E101 at 0-based line 8, column 2
    main.write_text(main.read_text().replace("  counter = 0\n", "  countr = 0\n"))
    init = tmp_path / "init.lua"
    init.write_text(LUA)
    out = tmp_path / "diagnostics.txt"
    env = dict(os.environ, KRL_NVIM_OUT=str(out), KRL_PYTHON=sys.executable, KRL_ROOT=str(root),
               XDG_CONFIG_HOME=str(tmp_path / "cfg"), XDG_DATA_HOME=str(tmp_path / "data"),
               XDG_STATE_HOME=str(tmp_path / "state"), XDG_CACHE_HOME=str(tmp_path / "cache"),
               PYTHONPATH=str(Path(__file__).resolve().parents[2]))
    proc = subprocess.run([nvim, "--headless", "-n", "-i", "NONE", "-u", str(init), str(main)],
                          env=env, capture_output=True, text=True, timeout=180, check=False)
    assert out.exists(), f"nvim wrote no diagnostics (exit {proc.returncode}): {proc.stderr[-2000:]}"
    rows = [line.split("|", 3) for line in out.read_text().splitlines() if line]
    assert rows == [["E101", "8", "2", "'countr' is not declared"]]
