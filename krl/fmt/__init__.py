"""`krl fmt`: the KRL formatter (krl/fmt/core.py describes what it changes and what it keeps).

Public API, also used by the language server for document formatting::

    format_text(text: str, options: FormatOptions | None = None) -> str

Raises :class:`FormatSyntaxError` (a :class:`FormatError`) for text that does not parse.
"""

from krl.fmt.core import (FormatError, FormatOptions, FormatSafetyError, FormatSyntaxError, SyntaxProblem,
                          format_text)

__all__ = ["FormatError", "FormatOptions", "FormatSafetyError", "FormatSyntaxError", "SyntaxProblem",
           "format_text"]
