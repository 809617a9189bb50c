"""Parse trees from the Java engine: the Python runtime's objects rebuilt from data.

The Java worker (worker/KrlWorker.java, requests with "t") answers with the tree its
generated parser built, as integers: the token stream and the nodes in preorder (the format
is in the worker's header). :func:`tree_from_raw` rebuilds the same objects the Python engine
builds — the generated ``KRLParser.<Name>Context`` classes, ``TerminalNodeImpl`` and
``ErrorNodeImpl`` nodes, ``CommonToken`` tokens with their type, channel, offsets, line and
column, label fields (``op``, ``frame``) — so that every consumer (the AST builder, the
checks) reads them unchanged. Nothing is parsed again: token texts are slices of the text
the worker parsed. tests/syntax/test_engines.py holds the rebuilt trees to the Python
engine's, node by node, on every file of the corpora.

Raises :class:`TreeDataError` for data that does not describe a tree of this parser (then
the caller parses the file with the Python engine).
"""

from __future__ import annotations

from antlr4 import InputStream
from antlr4.Token import CommonToken
from antlr4.CommonTokenStream import CommonTokenStream
from antlr4.error.Errors import RecognitionException
from antlr4.tree.Tree import ErrorNodeImpl, TerminalNodeImpl

from krl import collector

__all__ = ["TreeDataError", "is_acyclic", "stream_tokens", "tree_from_raw"]


class TreeDataError(ValueError):
    """The worker's tree data does not fit the parser or the text."""


class _Text:
    """The character stream a rebuilt token reads its text from: what ``InputStream`` offers
    tokens (``size``, ``getText(start, stop)`` over code points), without its per-character
    list."""

    __slots__ = ("strdata", "size")

    def __init__(self, text: str):
        self.strdata = text
        self.size = len(text)

    def getText(self, start: int, stop: int) -> str:  # noqa: N802 - the ANTLR runtime's name
        if stop >= self.size:
            stop = self.size - 1
        if start >= self.size:
            return ""
        return self.strdata[start:stop + 1]


# A rule that recovered from an error carries an exception (the builder and the checks only
# ask whether there is one); the rebuilt tree marks such rules with this one.
#: the integers of one token in the Java engine's token data
TOKEN_FIELDS = 6
RECOVERED = RecognitionException("a rule recovered from a syntax error (parsed by the Java engine)")

_PARSERS: dict[type, object] = {}
_CLASSES: dict[tuple[type, str], type] = {}


def _parser(bundle) -> object:
    """One parser instance per bundle, the ``parser`` of every rebuilt context (the AST
    builder reads the token names from it)."""
    p = _PARSERS.get(bundle.parser_cls)
    if p is None:
        lexer = bundle.lexer_cls(InputStream(""))
        p = _PARSERS[bundle.parser_cls] = bundle.parser_cls(CommonTokenStream(lexer))
    return p


def _context_class(parser_cls: type, name: str) -> type:
    key = (parser_cls, name)
    cls = _CLASSES.get(key)
    if cls is None:
        cls = getattr(parser_cls, name, None)
        if not isinstance(cls, type) or not name.endswith("Context"):
            raise TreeDataError(f"no context class {name!r} in the parser")
        _CLASSES[key] = cls
    return cls


def tree_from_raw(raw: dict, text: str, bundle, parents: bool = True):
    """The parse tree (the start rule's context) of a worker answer with tree data.

    `text`: the text the worker parsed (after :func:`krl.syntax.parse.prepare_text`);
    `bundle`: the ParserBundle generated from the same grammar version. `parents=False`: every
    node's ``parentCtx`` is left None, for a reader that never goes up the tree (the AST
    builder, the syntax messages): the tree then holds no cycle and reference counting frees
    it as soon as it is dropped (:func:`is_acyclic`). Raises TreeDataError."""
    # Millions of new objects and none freed: the cyclic collector's passes over the growing
    # heap would cost more than the building itself, so it waits until the tree is built.
    with collector.paused():
        try:
            return _build(raw["tokens"], raw["names"], raw["tree"], raw["labels"], text, bundle, parents)
        except TreeDataError:
            raise
        except (KeyError, IndexError, TypeError, ValueError, AttributeError) as exc:
            raise TreeDataError(f"malformed tree data: {type(exc).__name__}: {exc}") from None


class RebuiltToken(CommonToken):
    """A ``CommonToken`` of a rebuilt tree: its fields are read from the worker's token data
    (6 integers per token, see the module docstring) when asked for, so that making one costs
    two assignments. Read-only: type, channel, start, stop, line, column, tokenIndex, text,
    source."""

    __slots__ = ("_data", "_k")

    type = property(lambda self: self._data[0][self._k])
    channel = property(lambda self: self._data[0][self._k + 1])
    start = property(lambda self: self._data[0][self._k + 2])
    stop = property(lambda self: self._data[0][self._k + 3])
    line = property(lambda self: self._data[0][self._k + 4])
    column = property(lambda self: self._data[0][self._k + 5])
    tokenIndex = property(lambda self: self._k // 6)
    source = property(lambda self: self._data[1])

    @property
    def text(self) -> str:
        d, k = self._data, self._k
        tk = d[0]
        start, stop, stream = tk[k + 2], tk[k + 3], d[1][1]
        if start < stream.size and stop < stream.size:
            return stream.getText(start, stop)
        return "<EOF>"


_new = object.__new__
_set_symbol = TerminalNodeImpl.symbol.__set__
_set_term_parent = TerminalNodeImpl.parentCtx.__set__


def _build(tk: list[int], names: list[str], data: list[int], labels: list, text: str, bundle,
           parents_too: bool = True):
    parser = _parser(bundle)
    classes = [_context_class(bundle.parser_cls, n) for n in names]
    count = len(tk) // TOKEN_FIELDS
    if count * TOKEN_FIELDS != len(tk):
        raise TreeDataError(f"token data is not a multiple of {TOKEN_FIELDS} integers")
    shared = (tk, (None, _Text(text)))
    made: list = [None] * count

    def token(i: int):
        if i < 0:
            return None
        t = made[i]
        if t is None:
            t = made[i] = _new(RebuiltToken)
            t._data = shared
            t._k = 6 * i
        return t

    contexts = []
    add_context = contexts.append
    terminal, error = TerminalNodeImpl, ErrorNodeImpl
    root = None
    parents: list = []      # the open contexts ...
    left: list[int] = []    # ... and how many children each still takes
    pos, end = 0, len(data)
    while pos < end:
        kind = data[pos]
        if kind < 0:
            t = token(data[pos + 1])
            if t is None:
                raise TreeDataError("a terminal without a token")
            if kind == -1:
                node = _new(terminal)
            elif kind == -2:
                node = _new(error)
            else:
                raise TreeDataError(f"unknown node kind {kind}")
            _set_symbol(node, t)
            pos += 2
            parent = parents[-1]
            _set_term_parent(node, parent if parents_too else None)
            parent.children.append(node)
            left[-1] -= 1
            if not left[-1]:
                parents.pop()
                left.pop()
            continue
        node = _new(classes[kind])
        node.start = token(data[pos + 1])
        node.stop = token(data[pos + 2])
        node.invokingState = data[pos + 3]
        node.exception = RECOVERED if data[pos + 4] else None
        n = data[pos + 5]
        node.parser = parser
        add_context(node)
        pos += 6
        if parents:
            parent = parents[-1]
            node.parentCtx = parent if parents_too else None
            parent.children.append(node)
            left[-1] -= 1
            if not left[-1]:
                parents.pop()
                left.pop()
        elif root is None:
            node.parentCtx = None
            root = node
        else:
            raise TreeDataError("nodes after the root")
        if n:
            node.children = []
            parents.append(node)
            left.append(n)
        else:
            node.children = None
    if root is None or parents:
        raise TreeDataError("the tree data ends inside a context")
    for ordinal, field, kind, value in labels:
        ctx = contexts[ordinal]
        if kind == "t":
            setattr(ctx, field, token(value))
        elif kind == "c":
            setattr(ctx, field, ctx.children[value] if value >= 0 else None)
        elif kind == "T":
            setattr(ctx, field, [token(v) for v in value])
        elif kind == "C":
            setattr(ctx, field, [ctx.children[v] for v in value])
        else:
            raise TreeDataError(f"unknown label kind {kind!r}")
    return root


def is_acyclic(tree) -> bool:
    """True for a tree rebuilt with ``parents=False`` (no node points up: nothing to break
    before it is freed, krl/workspace.py ``release_tree``)."""
    if type(getattr(tree, "start", None)) is not RebuiltToken:
        return False        # the Python engine's tree, or none
    children = tree.children
    return not children or children[0].parentCtx is None


def stream_tokens(tree) -> list | None:
    """Every token of the stream a rebuilt tree was parsed from (all channels, in order, as
    :func:`krl.syntax.tokens.lex` gives them for the same text), or None for a tree the Python
    engine built (or no tree). The syntax messages read them instead of lexing the file again
    with the Python runtime's lexer (krl/syntax/messages.py ``syntax_diagnostics``)."""
    start = getattr(tree, "start", None)
    if type(start) is not RebuiltToken:
        return None
    shared = start._data
    out = []
    for k in range(0, len(shared[0]) - 5, 6):
        t = _new(RebuiltToken)
        t._data = shared
        t._k = k
        out.append(t)
    return out
