"""The pendant's operations are one table (pendant/server.py ``OPERATIONS``, issue 62): every
operation has its handler, every handler is entered under an operation, and the page's web
client (pendant/web/src/main.js) sends exactly these operations. The check is a function run
here on the real server and on broken tables, so that it is seen to fail."""

from __future__ import annotations

import asyncio
import inspect
import re
from pathlib import Path

import pytest

from pendant import server
from pendant.engine import EngineError
from pendant.server import OPERATIONS, OPS, Pendant

CLIENT = Path(server.__file__).resolve().parent / "web" / "src" / "main.js"


def page_operations(text: str) -> set[str]:
    """The operations the page's source sends: the first argument of its ``send('op', ...)``
    and ``act('op', ...)`` calls."""
    return set(re.findall(r"\b(?:send|act)\(\s*'([A-Za-z]+)'", text))


def handler_methods(cls: type) -> dict[str, object]:
    """The methods of `cls` shaped as handlers: coroutine functions taking (self, act)."""
    out = {}
    for name, fn in vars(cls).items():
        if inspect.iscoroutinefunction(fn) and list(inspect.signature(fn).parameters) == ["self", "act"]:
            out[name] = fn
    return out


def problems(table: dict, ops: tuple, handlers: dict, page: set[str]) -> list[str]:
    """What is missing on some side: an operation without a handler of the class, a handler
    entered under no operation, OPS not the table's keys, an operation the page sends that the
    server does not know, one the server knows that the page never sends."""
    out = []
    out += [f"operation {op!r} has no handler" for op, fn in table.items() if fn not in handlers.values()]
    out += [f"handler {name} has no operation" for name, fn in handlers.items() if fn not in table.values()]
    if tuple(table) != tuple(ops):
        out.append("OPS is not the table's keys")
    out += [f"the page sends {op!r}, which has no handler" for op in sorted(page - set(table))]
    out += [f"operation {op!r} is never sent by the page" for op in sorted(set(table) - page)]
    return out


def test_every_operation_has_its_handler_and_the_page_sends_each():
    page = page_operations(CLIENT.read_text(encoding="utf-8"))
    assert len(page) == 23 and {"hello", "jog", "touchup", "open", "logbook", "chooseRobot"} <= page
    assert problems(OPERATIONS, OPS, handler_methods(Pendant), page) == []


def test_the_check_fails_for_a_missing_side():
    handlers = handler_methods(Pendant)
    page = set(OPS)
    lacking = {k: v for k, v in OPERATIONS.items() if k != "jog"}      # a handler without its operation
    assert problems(lacking, tuple(lacking), handlers, page) == [
        "handler _jog has no operation", "the page sends 'jog', which has no handler"]
    extra = dict(OPERATIONS, park=lambda pendant, act: None)            # an operation without a handler
    assert problems(extra, tuple(extra), handlers, page | {"park"}) == ["operation 'park' has no handler"]
    assert problems(OPERATIONS, OPS, handlers, page - {"open"}) == ["operation 'open' is never sent by the page"]
    assert problems(OPERATIONS, OPS[:-1], handlers, page) == ["OPS is not the table's keys"]


def test_an_operation_is_entered_once():
    with pytest.raises(ValueError, match="two handlers"):
        server._operation("hello")(Pendant._hello)


def test_an_unknown_operation_is_refused(tmp_path):
    pendant = Pendant(tmp_path)
    for msg in ({"op": "park"}, {"op": ["hello"]}, {}):
        with pytest.raises(EngineError, match="unknown action"):
            asyncio.run(pendant.handle(None, msg))
