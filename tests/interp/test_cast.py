"""CAST_TO / CAST_FROM (reference §4.8): byte layout and round trips (interp/runtime/natives/cast.py)."""

from __future__ import annotations

import struct

from .helpers import run_krl

DAT = """
DEFDAT prog
DECL CHAR BUF[32]
DECL INT NOFS, NOFS2, N, N2
DECL REAL R, R2
DECL BOOL B, B2
DECL FRAME F, F2
DECL INT A[3], A2[3]
ENDDAT
"""


def test_cast_round_trip_and_layout(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      N = -2
      R = 0.1
      B = TRUE
      A[1] = 1
      A[2] = 2
      A[3] = 300
      NOFS = 0
      CAST_TO(BUF[], NOFS, N, R, B, A[])
      NOFS2 = 0
      CAST_FROM(BUF[], NOFS2, N2, R2, B2, A2[])
    END
    """, DAT)
    assert r.result.reason == "completed", r.result
    # 4 (INT) + 4 (REAL) + 1 (BOOL) + 3 * 4 (INT array) bytes, little-endian (KUKA's EthernetKRL
    # 2.2 manual p. 33: INT, REAL, BOOL, CHAR of its CAST_TO example make a 10-byte record)
    assert r.var("prog", "NOFS") == 21 and r.var("prog", "NOFS2") == 21
    raw = bytes(ord(c) for c in r.var("prog", "BUF").data[:21])
    assert raw == struct.pack("<if?3i", -2, 0.1, True, 1, 2, 300)
    assert r.var("prog", "N2") == -2
    assert r.var("prog", "R2") == struct.unpack("<f", struct.pack("<f", 0.1))[0]  # single precision
    assert r.var("prog", "B2") is True
    assert r.var("prog", "A2").data == [1, 2, 300]


def test_cast_struct_and_too_small_buffer(tmp_path):
    r = run_krl(tmp_path, """
    DEF prog()
      F = {X 1.5, Y -2, Z 3, A 0, B 90, C 180}
      NOFS = 0
      CAST_TO(BUF[], NOFS, F)
      NOFS2 = 0
      CAST_FROM(BUF[], NOFS2, F2)
      NOFS = 10
      CAST_TO(BUF[], NOFS, F)
    END
    """, DAT)
    assert r.var("prog", "NOFS2") == 24
    f2 = r.var("prog", "F2")
    assert [f2.f[k] for k in ("X", "Y", "Z", "A", "B", "C")] == [1.5, -2.0, 3.0, 0.0, 90.0, 180.0]
    # 10 + 24 bytes do not fit into 32: a run-time error on line 8
    assert r.result.reason == "error"
    assert r.result.line == 8 and "too small" in str(r.result.error)


def test_the_manuals_cast_to_example(tmp_path):
    """KUKA's EthernetKRL 2.2 manual, p. 33: ``CHAR Bytes[10]``,
    ``CAST_TO(Bytes[],OFFSET,91984754,913434.2,TRUE,"X")``, printed as ``"r?{ ? _I X"``."""
    r = run_krl(tmp_path, """
    DEF prog()
      NOFS = 0
      CAST_TO(BUF[], NOFS, 91984754, 913434.2, TRUE, "X")
    END
    """, DAT)
    assert r.result.reason == "completed", r.result
    assert r.var("prog", "NOFS") == 10
    raw = bytes(ord(c) for c in r.var("prog", "BUF").data[:10])
    shown = "".join(chr(b) if 0x21 <= b < 0x7F else "?" if b >= 0x7F else " " for b in raw)
    assert shown == "r?{ ? _I X"
