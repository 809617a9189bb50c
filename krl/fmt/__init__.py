"""`krl fmt`: the KRL formatter (krl/fmt/core.py describes what it changes and what it keeps).

Public API, also used by the language server for document formatting::

    format_text(text: str, options: FormatOptions | None = None, path: str = "<fmt>") -> str

Raises :class:`FormatSyntaxError` (a :class:`FormatError`) for text that does not parse; it
carries the parse result (``result``) and its syntax errors as `krl parse` words them
(``diagnostics``, named by `path`), so nothing is parsed twice.
"""

from krl.fmt.core import (FormatError, FormatOptions, FormatSafetyError, FormatSyntaxError, SyntaxProblem,
                          format_text)

__all__ = ["FormatError", "FormatOptions", "FormatSafetyError", "FormatSyntaxError", "SyntaxProblem",
           "format_text"]
