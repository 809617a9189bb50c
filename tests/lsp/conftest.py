"""A pytest-lsp client driving `python -m krl.lsp` over stdio, and helpers to open files and
wait for their diagnostics. The fixture backup (fixtures/backup: R1/Program, R1/System/$config.dat)
is small enough that every expected position in the tests is counted by hand from its text."""

from __future__ import annotations

import asyncio
import shutil
import sys
from pathlib import Path
from urllib.parse import unquote, urlparse

import attrs
import pytest
import pytest_lsp
from lsprotocol import types as L
from pytest_lsp import ClientServerConfig, LanguageClient

from tests import forkserver

FIXTURES = Path(__file__).parent / "fixtures"
BACKUP = FIXTURES / "backup"
PROGRAM = BACKUP / "R1" / "Program"
SYSTEM = BACKUP / "R1" / "System"
WAIT_S = 60.0          # generous: the machine is shared; no test measures time


@attrs.define
class ForkedServer(ClientServerConfig):
    """`python -m krl.lsp` as a fork of the test worker's fork server (tests/forkserver.py: the
    project, pygls and lsprotocol imported once), started when the fixture starts the server:
    0.6-0.7 s of CPU less per server than a process that imports them (2026-11-27).
    ``server_command`` stays the real command line."""

    def get_server_command(self, devtools: str | None = None) -> list[str]:
        assert devtools is None, "lsp-devtools wraps a real command: use server_config(real=True)"
        return [str(forkserver.shared().launcher), *self.server_command[1:]]


def server_config(real: bool = False) -> ClientServerConfig:
    """The language server of a test: a fork (:class:`ForkedServer`), or with `real` a process of
    its own that imports everything as a user's editor starts it (tests/lsp/test_cold_start.py)."""
    command = [sys.executable, "-m", "krl.lsp"]
    return ClientServerConfig(server_command=command) if real else ForkedServer(server_command=command)


def init_params(root: Path) -> L.InitializeParams:
    caps = L.ClientCapabilities(
        workspace=L.WorkspaceClientCapabilities(
            did_change_watched_files=L.DidChangeWatchedFilesClientCapabilities(dynamic_registration=False),
            workspace_folders=True),
        text_document=L.TextDocumentClientCapabilities(
            document_symbol=L.DocumentSymbolClientCapabilities(hierarchical_document_symbol_support=True),
            publish_diagnostics=L.PublishDiagnosticsClientCapabilities(related_information=True)))
    return L.InitializeParams(capabilities=caps, root_uri=root.as_uri(),
                              workspace_folders=[L.WorkspaceFolder(uri=root.as_uri(), name=root.name)])


@pytest_lsp.fixture(scope="module", config=server_config())
async def client(lsp_client: LanguageClient):
    lsp_client.init_result = await lsp_client.initialize_session(init_params(BACKUP))
    yield
    await lsp_client.shutdown_session()


async def wait_diagnostics(client: LanguageClient, uri: str, hints: bool = False) -> list[L.Diagnostic]:
    """The next diagnostics published for `uri` (call after clearing client.diagnostics[uri]);
    without `hints`, those of ``krl check`` only (the never-read hints, severity Hint, are
    tested in test_unused.py)."""
    async def loop():
        while uri not in client.diagnostics:
            await client.wait_for_notification(L.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
        return [d for d in client.diagnostics[uri] if hints or d.severity != L.DiagnosticSeverity.Hint]
    return await asyncio.wait_for(loop(), WAIT_S)


async def open_doc(client: LanguageClient, path: Path, text: str | None = None, version: int = 1,
                   hints: bool = False) -> list[L.Diagnostic]:
    """Open `path` (with `text` as the unsaved buffer, else its content) and return its first
    checked diagnostics (with the never-read hints when `hints`). In a workspace of 20 files or
    more the server publishes the file's own parse diagnostics first: a documentSymbol request,
    answered once the analysis is done (after its diagnostics, which the server sends first),
    says when the checked ones are in."""
    uri = path.as_uri()
    client.diagnostics.pop(uri, None)
    if text is None:
        text = path.read_bytes().decode("utf-8", errors="replace")
    client.text_document_did_open(L.DidOpenTextDocumentParams(
        text_document=L.TextDocumentItem(uri=uri, language_id="krl", version=version, text=text)))
    await asyncio.wait_for(client.text_document_document_symbol_async(
        L.DocumentSymbolParams(text_document=L.TextDocumentIdentifier(uri=uri))), WAIT_S)
    return await wait_diagnostics(client, uri, hints)


async def change_doc(client: LanguageClient, path: Path, text: str, version: int) -> list[L.Diagnostic]:
    uri = path.as_uri()
    client.diagnostics.pop(uri, None)
    client.text_document_did_change(L.DidChangeTextDocumentParams(
        text_document=L.VersionedTextDocumentIdentifier(uri=uri, version=version),
        content_changes=[L.TextDocumentContentChangeWholeDocument(text=text)]))
    return await wait_diagnostics(client, uri)


def close_doc(client: LanguageClient, path: Path) -> None:
    client.text_document_did_close(L.DidCloseTextDocumentParams(text_document=L.TextDocumentIdentifier(uri=path.as_uri())))


def summary(diags) -> list[tuple[str, int, int, str]]:
    """(code, 0-based line, 0-based character, message), sorted."""
    return sorted((str(d.code), d.range.start.line, d.range.start.character, d.message) for d in diags)


def pos(line: int, character: int) -> L.Position:
    return L.Position(line=line, character=character)


def where(loc) -> tuple[str, int, int, int, int]:
    """(file name, start line, start char, end line, end char) of a Location."""
    r = loc.range
    return (Path(unquote(urlparse(loc.uri).path)).name, r.start.line, r.start.character, r.end.line, r.end.character)


@pytest.fixture
def backup_copy(tmp_path: Path) -> Path:
    """A writable copy of the fixture backup."""
    dst = tmp_path / "KRC"
    shutil.copytree(BACKUP, dst)
    return dst
