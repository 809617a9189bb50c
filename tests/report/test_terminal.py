"""krl/terminal.py: untrusted text never reaches the terminal with its control characters."""

from __future__ import annotations

import os

from krl.terminal import printable, printable_path


def test_escape_and_csi_become_visible():
    # ESC [2J clears the screen; ESC ]0;title BEL sets the window title.
    assert printable("a\x1b[2Jb") == "a\\x1b[2Jb"
    assert printable("\x1b]0;pwned\x07") == "\\x1b]0;pwned\\x07"


def test_c1_controls_and_del():
    # U+009B is the one-character CSI, U+0085 NEL a line break for Unicode.
    assert printable("x\x9b31my") == "x\\x9b31my"
    assert printable("\x85\x7f") == "\\x85\\x7f"


def test_line_breaks_and_cr():
    assert printable("one\ntwo\rthree") == "one\\x0atwo\\x0dthree"
    assert printable("one\ntwo\rthree", keep_newlines=True) == "one\ntwo\\x0dthree"
    assert printable("a\u2028b\u2029c") == "a\\u2028b\\u2029c"


def test_bidi_overrides():
    assert printable("abc\u202edef\u2066") == "abc\\u202edef\\u2066"


def test_ordinary_text_is_unchanged():
    text = "IF $IN[3] THEN ; Prüfung\tÖl ° µ € 100%"
    assert printable(text) == text


def test_every_control_is_replaced():
    controls = [chr(c) for c in range(0x20) if c != 9] + [chr(c) for c in range(0x7F, 0xA0)]
    out = printable("".join(controls))
    assert not any(ch in out for ch in controls)
    assert out.count("\\x") == len(controls)


def test_path_with_undecodable_bytes():
    name = os.fsdecode(b"Pr\xfcfung\x1b.src")
    assert printable_path(name) == "Pr\\xfcfung\\x1b.src"
