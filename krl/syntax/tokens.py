"""The token stream and parse-tree nodes, for the stages that read them without ANTLR.

The formatter (krl/fmt) works on the token stream and the parse tree of one parse, the language
server (krl/lsp) lexes one line to find the token under the cursor; neither imports the ANTLR
runtime: ANTLR stays inside krl/syntax and krl/ast (docs/architecture.md, "Packages and
layers"; tests/test_layers.py proves it). A token has ``type``, ``channel``, ``text``,
``start``/``stop`` (code-point offsets), ``line``, ``column`` and ``tokenIndex``; a rule node has
``children``.
"""

from __future__ import annotations

from antlr4 import CommonTokenStream, InputStream, ParserRuleContext, Token
from antlr4.tree.Tree import TerminalNode

#: the type of the end-of-file token; the channel of code tokens (comments and folds are hidden)
EOF = Token.EOF
DEFAULT_CHANNEL = Token.DEFAULT_CHANNEL


def lex(text: str, bundle) -> list:
    """Every token of `text` (all channels, EOF last), lexer errors ignored; `bundle` the
    parser bundle (krl.syntax.parse.default_bundle)."""
    lexer = bundle.lexer_cls(InputStream(text))
    lexer.removeErrorListeners()
    stream = CommonTokenStream(lexer)
    stream.fill()
    return stream.tokens


def is_rule(node) -> bool:
    """True for a rule node of a parse tree (it has children)."""
    return isinstance(node, ParserRuleContext)


def is_token_node(node) -> bool:
    """True for a leaf of a parse tree (``node.symbol`` is its token)."""
    return isinstance(node, TerminalNode)


def rule_name(ctx) -> str:
    """The grammar rule of a rule node (``ifStatement``)."""
    name = type(ctx).__name__
    if name.endswith("Context"):
        name = name[:-7]
    return name[:1].lower() + name[1:]


__all__ = ["DEFAULT_CHANNEL", "EOF", "is_rule", "is_token_node", "lex", "rule_name"]
