"""A synthetic KRL program of a chosen length: what the server parses to warm up (krl/lsp/server.py)
and what the benchmark edits (krl/lsp/bench.py)."""

from __future__ import annotations


def generate(lines: int = 3000) -> str:
    """A valid KRL program of about `lines` lines (CRLF, as on the controller)."""
    out = ["&ACCESS RVP", "&REL 1", "DEF bench( )", "  DECL INT n", ";FOLD INI;%{PE}", "  BAS(#INITMOV, 0)",
           ";ENDFOLD (INI)", "  n = 0", "  bench_1( )", "END", ""]
    k = 1
    while len(out) < lines:
        body = [f"DEF bench_{k}( )", "  DECL INT i, j", "  DECL REAL d", "  DECL E6POS p",
                ";FOLD PTP HOME Vel=100 % DEFAULT;%{PE}", "  PTP {A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}", ";ENDFOLD"]
        for s in range(8):
            body += [f"  ; step {s}", f"  $OUT[{s + 1}] = FALSE", f"  FOR i = 1 TO {s + 3}",
                     f"    d = i * 2.5 + {s}", "    IF d > 10.0 THEN", f"      $VEL.CP = 0.{s + 1}",
                     "      LIN {X 100.0, Y 200.0, Z 300.0, A 0.0, B 90.0, C 0.0} C_DIS", "    ELSE",
                     "      j = i", "    ENDIF", "  ENDFOR", f"  WAIT SEC 0.{s}", "  p = $POS_ACT",
                     "  p.X = p.X + 10.0", "  SWITCH j", "    CASE 1", "      PTP p", "    DEFAULT",
                     "      HALT", "  ENDSWITCH"]
        out += body + ["END", ""]
        k += 1
    return "\r\n".join(out) + "\r\n"
