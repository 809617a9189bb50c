"""Document names of the language server: a file path or, for a buffer that is not a file, a
URI (``untitled:Untitled-1``). Its own module so that the analysis and the session
(krl/lsp/analysis.py, krl/lsp/project.py) share it without importing each other."""

from __future__ import annotations

import os
import re
from pathlib import Path

_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.-]+:")


def norm(path: str | Path) -> str:
    """One spelling per file: absolute, normalised (symbolic links kept). A document that is
    not a file (``untitled:...``) keeps its URI as its name."""
    p = str(path)
    if is_uri(p):
        return p
    return os.path.normpath(os.path.abspath(p))


def is_uri(name: str) -> bool:
    """True for a document name that is a URI, not a file path (``untitled:Untitled-1``)."""
    return bool(_SCHEME.match(name)) and not os.path.isabs(name)


__all__ = ["is_uri", "norm"]
