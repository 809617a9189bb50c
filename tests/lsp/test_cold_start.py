"""Workspace symbols before any document is open: the folder the editor opened is read."""

from __future__ import annotations

import pytest
import pytest_lsp
from lsprotocol import types as L
from pytest_lsp import LanguageClient

from tests.lsp.conftest import BACKUP, init_params, server_config, where


@pytest_lsp.fixture(config=server_config())
async def cold(lsp_client: LanguageClient):
    await lsp_client.initialize_session(init_params(BACKUP))
    yield
    await lsp_client.shutdown_session()


@pytest.mark.asyncio
async def test_workspace_symbols_without_open_documents(cold):
    got = await cold.workspace_symbol_async(L.WorkspaceSymbolParams(query="pose"))
    assert sorted((s.name, s.kind, where(s.location)) for s in got) == [
        ("pose_t", L.SymbolKind.Struct, ("tools.dat", 1, 15, 1, 21))]
