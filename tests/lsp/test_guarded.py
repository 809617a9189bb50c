"""An exception in a handler is logged and answered with an empty result (krl/lsp/server.py)."""

from __future__ import annotations

import asyncio
import logging

from krl.lsp.server import guarded


def test_a_handler_that_raises_is_logged_and_answered(caplog):
    class Fake:
        reported: list = []

        def _report(self, message):
            self.reported.append(message)

    @guarded(list)
    async def broken(ls, params):
        raise ZeroDivisionError("boom")

    ls = Fake()
    with caplog.at_level(logging.ERROR, logger="krl.lsp"):
        assert asyncio.run(broken(ls, None)) == []
    assert ls.reported == ["krl lsp: broken failed: ZeroDivisionError: boom"]
    assert "handler broken failed" in caplog.text
