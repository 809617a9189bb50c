"""`krl lsp`: the language server on stdio (krl/lsp/server.py); registered by app/__init__.py."""

from __future__ import annotations

import click
from krl.lsp.server import serve


@click.command()
@click.option("--stdio", is_flag=True, help="Talk LSP on stdin/stdout (the default and only transport).")
@click.option("--log-file", default=None, metavar="FILE", help="Write the server's log to FILE (default: warnings on stderr).")
def lsp(stdio: bool, log_file: str | None) -> None:
    """Run the KRL language server on stdin/stdout (see docs/editors.md)."""
    serve(log_file)


commands = [lsp]
