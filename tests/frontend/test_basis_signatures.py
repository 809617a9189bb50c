"""The signatures of KUKA's BASIS routines (bas.src) as the checker knows them when a folder has
no bas.src of its own (issue 72 item 4): the types and modes KUKA's bas.src declares.

The false "E303: argument 1 of 'SORI_TYP': LDAT is not assignable to ORI_TYPE" of every KSS 8
spline inline form (``SLIN ... WITH $ORI_TYPE = SORI_TYP(LCPDAT1), $APO = SAPO(LCPDAT1)``) came
from a table that contradicted the project's bas.src. The expected signatures below are read
by hand from KUKA's own bas.src of a KR C4 (KSS 8.3; the corpus's ``khrzysio__KRC4_test``
``R1/System/bas.src`` lines 4-1494, the same in ``rawpython__kukaKRLmagic``,
``HugoDanielson__ChinaMilling`` and ``ingeniado__KRC4-Robot-Palletizer``): e.g. line 1208
``GLOBAL DEFFCT ORI_TYPE SORI_TYP (PARAMS :IN)`` / ``DECL LDAT PARAMS``.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from krl.semantics.builtins import load_builtins

from .helpers import check

#: name -> (return type or None, [(parameter type, open CHAR array, mode), ...]) as KUKA's bas.src
#: declares them (khrzysio__KRC4_test R1/System/bas.src, the line of each header)
KUKA = {
    "BAS": (None, [("BAS_COMMAND", False, "IN"), ("REAL", False, "IN")]),               # line 4
    "SVEL_CP": ("CP", [("REAL", False, "IN"), ("REAL", False, "IN"), ("LDAT", False, "IN")]),   # 773
    "SVEL_JOINT": ("REAL", [("REAL", False, "IN")]),                                     # 849
    "SACC_CP": ("CP", [("LDAT", False, "IN")]),                                          # 907
    "SACC_JOINT": ("REAL", [("PDAT", False, "IN")]),                                     # 981
    "SAPO": ("CONT", [("LDAT", False, "IN")]),                                           # 1039
    "SAPO_PTP": ("CONT", [("PDAT", False, "IN")]),                                       # 1047
    "STOOL": ("FRAME", [("INT", False, "IN")]),                                          # 1071
    "STOOL2": ("FRAME", [("FDAT", False, "IN")]),                                        # 1105
    "SLOAD": ("LOAD", [("INT", False, "IN")]),                                           # 1113
    "SBASE": ("FRAME", [("INT", False, "IN")]),                                          # 1143
    "SIPO_MODE": ("IPO_MODE", [("IPO_MODE", False, "IN")]),                              # 1204
    "SORI_TYP": ("ORI_TYPE", [("LDAT", False, "IN")]),                                   # 1208
    "SCIRC_TYP": ("CIRC_TYPE", [("LDAT", False, "IN")]),                                 # 1212
    "SCIRC_M": ("CIRC_MODE", [("LDAT", False, "IN")]),                                   # 1216
    "SGEAR_JERK": ("REAL", [("PDAT", False, "IN")]),                                     # 1220
    "SJERK": ("JERK_STRUC", [("LDAT", False, "IN")]),                                    # 1244
    "TRACESTART": (None, [("CHAR", True, "IN"), ("CHAR", True, "IN")]),                  # 1446
    "TRACESTOP": (None, []),                                                             # 1490
}


@pytest.mark.parametrize("name", sorted(KUKA))
def test_the_checker_knows_kukas_basis_signatures(name):
    sig = load_builtins().routines[name]
    got = (sig.returns, [(p.type_name, p.dims == (0,), p.mode) for p in sig.params])
    assert got == KUKA[name]


SPLINE_FORMS = Path(__file__).resolve().parents[2] / "corpus" / "programs"


def test_kss8_spline_inline_forms_check_clean_without_a_bas_src():
    """corpus/programs/spline_demo (KSS 8 SPTP/SLIN/SCIRC inline forms) in a folder without
    bas.src: no diagnostic at all (it had 5 false E303 on SORI_TYP, SCIRC_TYP and SAPO)."""
    ws = check((SPLINE_FORMS / "spline_demo.src").read_text(encoding="utf-8"),
               (SPLINE_FORMS / "spline_demo.dat").read_text(encoding="utf-8"))
    assert [f"{d.code} {d.message}" for d in ws.diagnostics if d.is_error] == []


def test_every_spline_helper_accepts_what_an_inline_form_passes():
    """Each WITH helper as KSS 8's inline forms call it (SPTP, SLIN, SCIRC, and STOOL with a tool
    number as STOOL2 calls it): no error."""
    src = """DEF t()
  DECL FRAME f
  DECL LOAD l
  DECL REAL r
  DECL CP c
  DECL CONT a
  DECL ORI_TYPE o
  DECL CIRC_TYPE ct
  DECL CIRC_MODE cm
  DECL IPO_MODE im
  DECL JERK_STRUC j
  DECL FDAT fd
  DECL PDAT pd
  DECL LDAT ld
  r = SVEL_JOINT(100.0)
  c = SVEL_CP(0.25, , ld)
  f = STOOL2(fd)
  f = STOOL(fd.TOOL_NO)
  f = SBASE(fd.BASE_NO)
  im = SIPO_MODE(fd.IPO_FRAME)
  l = SLOAD(fd.TOOL_NO)
  r = SACC_JOINT(pd)
  a = SAPO_PTP(pd)
  r = SGEAR_JERK(pd)
  c = SACC_CP(ld)
  o = SORI_TYP(ld)
  ct = SCIRC_TYP(ld)
  a = SAPO(ld)
  cm = SCIRC_M(ld)
  j = SJERK(ld)
END
"""
    ws = check(src)
    assert [f"{d.code} {d.line} {d.message}" for d in ws.diagnostics if d.is_error] == []
