"""``python -m krl.lsp``: the language server on stdio (same as ``krl lsp``)."""

from krl.lsp.server import serve

if __name__ == "__main__":      # not when a worker process of the server imports this module
    serve()
