"""One name per document: a file's absolute, normalised path, or the URI of a document that is
not a file (``untitled:Untitled-1``)."""

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
