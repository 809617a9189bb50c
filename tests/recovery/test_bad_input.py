"""Bad input: encodings, line endings and unparseable files each get a classified row."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from krl.syntax.parse import parse_text
from krl.syntax.source import read_source
from recovery.scan import scan, scan_one

VALID = "DEF t()\n  ; Grüße, Maß\n  x = 1\nEND\n"


def test_utf8_with_bom(tmp_path: Path) -> None:
    p = tmp_path / "a.src"
    p.write_bytes(b"\xef\xbb\xbf" + VALID.encode("utf-8"))
    src = read_source(p)
    assert (src.encoding, src.text) == ("utf-8-sig", VALID)
    assert parse_text(src.text).ok


def test_cp1252_fallback_keeps_every_byte(tmp_path: Path) -> None:
    p = tmp_path / "a.src"
    data = VALID.encode("cp1252") + b"; undefined in cp1252: \x81\x9d\n"
    p.write_bytes(data)
    src = read_source(p)
    assert src.encoding == "cp1252"
    assert "Grüße" in src.text
    assert src.text.endswith("\x81\x9d\n")        # decoded as Latin-1, nothing lost
    assert src.text.encode("cp1252", errors="ignore")  # still text
    assert parse_text(src.text).ok


def test_mixed_line_endings(tmp_path: Path) -> None:
    p = tmp_path / "a.src"
    p.write_bytes(b"DEF t()\r\n  x = 1\n  y = 2\r  z = 3\r\nEND")
    assert parse_text(read_source(p).text).ok


def test_classified_rows(tmp_path: Path) -> None:
    (tmp_path / "empty.src").write_bytes(b"\r\n  \r\n")
    (tmp_path / "bin.dat").write_bytes(b"DEFDAT x\x00\x00\x01ENDDAT")
    (tmp_path / "big.SRC").write_bytes(b"DEF t()\n" + b"x = 1\n" * 10 + b"END\n")
    (tmp_path / "ok.Sub").write_bytes(VALID.encode())
    (tmp_path / "notes.txt").write_bytes(b"not KRL")
    rows = {r.path: r for r in scan(tmp_path, "g", jobs=1, use_cache=False, progress=False)}
    assert set(rows) == {"empty.src", "bin.dat", "big.SRC", "ok.Sub"}
    assert rows["empty.src"].status == "empty"
    assert rows["bin.dat"].status == "binary"
    assert rows["ok.Sub"].ok and rows["big.SRC"].ok
    assert read_source(tmp_path / "big.SRC", max_bytes=20).status == "too_large"


def test_timeout_is_a_row_not_a_hang(tmp_path: Path) -> None:
    # About 1.5 MB of deeply nested expressions: parsing takes well over one second.
    p = tmp_path / "slow.src"
    body = "x = " + "(" * 400 + "1" + ")" * 400 + "\n"
    p.write_text("DEF t()\n" + body * 400 + "END\n")
    from recovery import scan as scan_mod

    scan_mod._init_worker(None)
    row = scan_one((str(p), "slow.src", "sha", 1))
    assert row.status == "timeout", (row.status, row.seconds, row.issues[:1])


def test_parse_json_output_and_exit_codes(tmp_path: Path) -> None:
    good = tmp_path / "good.src"
    good.write_text(VALID)
    bad = tmp_path / "bad.src"
    bad.write_text("DEF t()\n  IF x THEN\nEND\n")
    krl = [sys.executable, "-m", "krl.cli"]
    ok = subprocess.run([*krl, "parse", str(good)], capture_output=True, text=True)
    assert ok.returncode == 0
    out = subprocess.run([*krl, "parse", "--json", str(good), str(bad)], capture_output=True, text=True)
    assert out.returncode == 1
    objs = [json.loads(line) for line in out.stdout.splitlines()]
    assert [o["ok"] for o in objs] == [True, False]
    err = objs[1]["errors"][0]
    assert set(err) >= {"line", "column", "message", "offending", "expected", "rule_stack"}
    assert err["line"] == 3 and "ENDIF" in err["expected"]
    assert err["rule_stack"][0] == "module"
