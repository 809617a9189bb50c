"""Text to parse tree: source decoding, the generated ANTLR parser and its error handling.

This package and `krl.ast` are the only places that touch ANTLR types.
"""

from krl.source import SourceText, read_source
from krl.syntax.parse import ParseResult, SyntaxIssue, parse_source, parse_text

__all__ = ["SourceText", "read_source", "ParseResult", "SyntaxIssue", "parse_source", "parse_text"]
