"""The DAP wire framing (interp/debug/wire.py): Content-Length header, CRLF, JSON body."""

from __future__ import annotations

import io

import pytest

from interp.debug.wire import ProtocolError, encode_message, read_message
from krl.limits import MAX_DAP_MESSAGE_BYTES


def test_round_trip_counts_utf8_bytes():
    msg = {"seq": 1, "type": "request", "command": "evaluate", "arguments": {"expression": "Ä"}}
    data = encode_message(msg)
    body = b'{"seq":1,"type":"request","command":"evaluate","arguments":{"expression":"\xc3\x84"}}'
    assert data == b"Content-Length: %d\r\n\r\n" % len(body) + body     # Ä is 2 bytes in UTF-8
    stream = io.BytesIO(data + data)
    assert read_message(stream) == msg
    assert read_message(stream) == msg
    assert read_message(stream) is None


def test_extra_headers_and_case():
    body = b'{"a":1}'
    stream = io.BytesIO(b"content-length: 7\r\nContent-Type: application/vscode-jsonrpc\r\n\r\n" + body)
    assert read_message(stream) == {"a": 1}


@pytest.mark.parametrize("data, text", [
    (b"Content-Type: x\r\n\r\n{}", "without Content-Length"),
    (b"Content-Length: abc\r\n\r\n{}", "bad Content-Length"),
    (b"Content-Length: 10\r\n\r\n{}", "end of stream inside a message body"),
    (b"Content-Length: 2\r\n\r\n[]", "not a JSON object"),
    (b"Content-Length: 3\r\n\r\n{x}", "not JSON"),
    (b"Content-Length: %d\r\n\r\n" % (MAX_DAP_MESSAGE_BYTES + 1), "exceeds the limit"),
    (b"X" * 2000 + b"\r\n", "header line too long"),
    (b"Content-Length: 2\r\n", "end of stream inside a message header"),
])
def test_malformed(data, text):
    with pytest.raises(ProtocolError, match=text):
        read_message(io.BytesIO(data))
