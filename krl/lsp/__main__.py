"""``python -m krl.lsp``: the language server on stdio (same as ``krl lsp``)."""

from krl.lsp.server import serve

serve()
