"""No untrusted data whole in a log (issue 61; net/netlog.py): for each partner, what it sent
reaches an event's text, a controller message or a library's stderr line clipped to
MAX_NET_LOG_CHARS; the recording of the message (an `in` event's `data`) stays whole for the
replay. The hub clips every partner's text in one place (net/hub.py ``trace``, ``net_message``);
these tests send each partner's own kind of oversized text through it, and through the stderr
handler the protocol libraries' loggers get (asyncua's own record: tests/net/test_opcua.py)."""

from __future__ import annotations

import io
import logging

import pytest

from krl.limits import MAX_NET_LOG_CHARS
from net.hub import Network
from net.netlog import clip, clip_library_logs, redirect
from robot.trace import TraceWriter

HUGE = "z" * 100_000


class _Ctl:
    """The controller as the hub sees it: a trace, a clock, a message window (its event log's
    ``message``, robot/events.py)."""

    def __init__(self) -> None:
        self.trace = TraceWriter(keep=True)
        self.time = 0.0
        self.messages: list[str] = []
        self.log = self

    def message(self, text: str, number=None) -> None:
        self.messages.append(text)


@pytest.mark.parametrize("iface, text", [
    ("eki", f"EKI01024 Error while reading received XML data: channel X, {HUGE}"),
    ("rsi", f"an answer with IPOC {'9' * 4000} that no packet was sent with"),
    ("varproxy", f"SPEED: value assignment inadmissible: SPEED = {HUGE}"),
    ("plc", f"OPC UA write refused: $IN[3]: {HUGE}"),
])
def test_each_partners_text_is_clipped_and_its_recording_kept(iface, text):
    hub = Network()
    ctl = _Ctl()
    hub.ctl = ctl
    hub.trace(iface, "error", text=text)
    hub.trace(iface, "in", data=HUGE)
    hub.net_message(text)
    error, recorded = ctl.trace.events[-2:]
    assert len(error["text"]) == MAX_NET_LOG_CHARS and error["text"].endswith("…")
    assert error["text"][:50] == text[:50]
    assert recorded["data"] == HUGE                       # the recording a replay feeds again
    assert len(ctl.messages[-1]) == MAX_NET_LOG_CHARS


@pytest.mark.parametrize("library", ["pymodbus", "asyncua"])
def test_library_log_lines_are_clipped(library):
    clip_library_logs(library)
    stream = io.StringIO()
    redirect(stream)
    try:
        logging.getLogger(f"{library}.server").error("request %s refused", HUGE)
    finally:
        redirect(None)
    line = stream.getvalue().rstrip("\n")
    assert "\n" not in line and line.endswith("…")
    assert len(line) <= MAX_NET_LOG_CHARS + len(f"{library}.server: error: ")


def test_clip_keeps_short_text_whole():
    assert clip("12.5") == "12.5"
    assert clip("x" * MAX_NET_LOG_CHARS) == "x" * MAX_NET_LOG_CHARS
