"""Right after start: workspace symbols before any document is open (the folder the editor opened
is read), and the request to watch KRL files on disk when the client can register it."""

from __future__ import annotations

import asyncio

import pytest
import pytest_lsp
from lsprotocol import types as L
from pytest_lsp import ClientServerConfig, LanguageClient, make_test_lsp_client

from tests.lsp.conftest import BACKUP, init_params, server_config, where


@pytest_lsp.fixture(config=server_config(real=True))
async def cold(lsp_client: LanguageClient):
    await lsp_client.initialize_session(init_params(BACKUP))
    yield
    await lsp_client.shutdown_session()


@pytest.mark.asyncio
async def test_workspace_symbols_without_open_documents(cold):
    got = await cold.workspace_symbol_async(L.WorkspaceSymbolParams(query="pose"))
    assert sorted((s.name, s.kind, where(s.location)) for s in got) == [
        ("pose_t", L.SymbolKind.Struct, ("tools.dat", 1, 15, 1, 21))]


def watching_client():
    client = make_test_lsp_client()
    client.registrations = []

    @client.feature(L.CLIENT_REGISTER_CAPABILITY)
    def register(params: L.RegistrationParams):
        client.registrations.extend(params.registrations)

    return client


@pytest_lsp.fixture(config=ClientServerConfig(server_command=server_config(real=True).server_command, client_factory=watching_client))
async def watching(lsp_client: LanguageClient):
    params = init_params(BACKUP)
    params.capabilities.workspace.did_change_watched_files = L.DidChangeWatchedFilesClientCapabilities(dynamic_registration=True)
    await lsp_client.initialize_session(params)
    yield
    await lsp_client.shutdown_session()


@pytest.mark.asyncio
async def test_the_server_asks_to_watch_krl_files(watching):
    for _ in range(600):
        if watching.registrations:
            break
        await asyncio.sleep(0.1)
    (reg,) = watching.registrations
    assert reg.method == L.WORKSPACE_DID_CHANGE_WATCHED_FILES
    assert {w["globPattern"] for w in reg.register_options["watchers"]} >= {"**/*.src", "**/*.dat", "**/*.sub"}
