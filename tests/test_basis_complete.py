"""The BASIS for programs outside a backup is complete (issue 50): the routines KSS 8's motion
inline forms call in their WITH parts (SPTP/SLIN/SCIRC: the spline helpers of bas.src and
``USE_CM_PRO_VALUES`` of KUKA's system software) are GLOBAL routines of interp/basis/*.src,
read by the front end, and they run on both interpreters with the values a KR C4's BASIS gives.

That every routine of the checker's tables (krl/semantics/data/functions.yaml) has an
implementation, a BASIS routine or a declared stand-in is the natives registry's completeness
test (tests/interp/test_natives.py, issue 47): the table is generated from the registry, where
each routine is declared with how it runs."""

from __future__ import annotations

import pytest

from interp.run import make_runtime, run_spec, RunSinks
from interp.runtime.natives import REGISTRY
from robot.trace import TraceWriter

# the names of KUKA's system software (functions.yaml lenient: system) that KSS 8's inline
# forms write into their WITH parts (SPTP/SLIN/SCIRC: $COLLMON_TOL_PRO[1] = USE_CM_PRO_VALUES(0))
INLINE_FORM_SYSTEM = ("USE_CM_PRO_VALUES",)
# the spline WITH parts of KSS 8's inline forms (SPTP, SLIN, SCIRC) as a KR C4 writes them
# (the corpus's Bugaj32__KUKA-pick-and-place-palletizing, BmadeRobots__KukaVarProxy):
# SVEL_JOINT SVEL_CP STOOL2 SBASE SIPO_MODE SLOAD SACC_JOINT SACC_CP SAPO_PTP SAPO SORI_TYP
# SCIRC_TYP SCIRC_M SGEAR_JERK SJERK (and STOOL, the frame of a tool number, which STOOL2 calls)
INLINE_FORM_FUNCTIONS = ("SVEL_JOINT", "SVEL_CP", "STOOL", "STOOL2", "SBASE", "SIPO_MODE", "SLOAD", "SACC_JOINT",
                         "SACC_CP", "SAPO_PTP", "SAPO", "SORI_TYP", "SCIRC_TYP", "SCIRC_M", "SGEAR_JERK", "SJERK")


def test_the_inline_forms_functions_are_basis_routines():
    """Declared in the natives registry as KRL of the project's BASIS (that the file has each
    routine, of the declared kind, is tests/interp/test_natives.py's completeness check)."""
    got = {name: REGISTRY[name].krl for name in INLINE_FORM_FUNCTIONS + INLINE_FORM_SYSTEM}
    assert got == {**{name: "bas.src" for name in INLINE_FORM_FUNCTIONS}, "USE_CM_PRO_VALUES": "collmonlib.src"}


@pytest.mark.parametrize("interp", ["tree", "vm"])
def test_kss8_inline_forms_run_outside_a_backup(tmp_path, interp):
    """SPTP/SLIN/SCIRC as KSS 8's inline forms write them, with a KR C4 template's PDAT/LDAT
    (GEAR_JERK 50, JERK_FAC 50): the values the BASIS gives (DEF_GEAR_JERK 100 % of a KR C4's
    $config.dat at 50 %, DEF_JERK_STRUC's CP 500 m/s^3 at 50 %)."""
    (tmp_path / "sfold.src").write_text(SRC)
    (tmp_path / "sfold.dat").write_text(DAT)
    trace = TraceWriter(keep=True)
    rt, _ = make_runtime(run_spec(tmp_path / "sfold.src", mujoco=False, interp=interp, max_sim_time=60.0),
                         RunSinks(trace=trace))
    result = rt.run()
    assert result.reason == "completed", (result.reason, result.text)
    outs = {e["signal"]: e["value"] for e in trace.events if e["kind"] == "io"}
    assert outs == {"$OUT[1]": True, "$OUT[2]": True, "$OUT[3]": True}, outs


SRC = """DEF sfold()
  BAS(#INITMOV, 0)
  SPTP XP1 WITH $VEL_AXIS[1] = SVEL_JOINT(100.0), $TOOL = STOOL2(FP1), $BASE = SBASE(FP1.BASE_NO), $IPO_MODE = SIPO_MODE(FP1.IPO_FRAME), $LOAD = SLOAD(FP1.TOOL_NO), $ACC_AXIS[1] = SACC_JOINT(PPDAT1), $APO = SAPO_PTP(PPDAT1), $GEAR_JERK[1] = SGEAR_JERK(PPDAT1), $COLLMON_TOL_PRO[1] = USE_CM_PRO_VALUES(0)
  SLIN XP2 WITH $VEL = SVEL_CP(0.5, , LCPDAT1), $TOOL = STOOL2(FP2), $BASE = SBASE(FP2.BASE_NO), $IPO_MODE = SIPO_MODE(FP2.IPO_FRAME), $LOAD = SLOAD(FP2.TOOL_NO), $ACC = SACC_CP(LCPDAT1), $ORI_TYPE = SORI_TYP(LCPDAT1), $APO = SAPO(LCPDAT1), $JERK = SJERK(LCPDAT1), $COLLMON_TOL_PRO[1] = USE_CM_PRO_VALUES(0)
  SCIRC XP3, XP4 WITH $VEL = SVEL_CP(0.5, , LCPDAT1), $TOOL = STOOL(FP2.TOOL_NO), $BASE = SBASE(FP2.BASE_NO), $IPO_MODE = SIPO_MODE(FP2.IPO_FRAME), $LOAD = SLOAD(FP2.TOOL_NO), $ACC = SACC_CP(LCPDAT1), $ORI_TYPE = SORI_TYP(LCPDAT1), $CIRC_TYPE = SCIRC_TYP(LCPDAT1), $APO = SAPO(LCPDAT1), $CIRC_MODE = SCIRC_M(LCPDAT1), $JERK = SJERK(LCPDAT1), $COLLMON_TOL_PRO[1] = USE_CM_PRO_VALUES(0)
  ; WITH sets the system variables for its motion only; the helpers' values read directly
  R = SGEAR_JERK(PPDAT1)
  JS = SJERK(LCPDAT1)
  J = JS.CP
  M = USE_CM_PRO_VALUES(0)
  $OUT[1] = ABS(R - 50.0) < 0.0001
  $OUT[2] = ABS(J - 250.0) < 0.0001
  $OUT[3] = M == 0
END
"""
DAT = """DEFDAT sfold
DECL REAL R = 0.0
DECL REAL J = 0.0
DECL INT M = 7
DECL JERK_STRUC JS
DECL E6POS XP1={X 500.0,Y 0.0,Z 600.0,A 0.0,B 90.0,C 0.0,S 2,T 2,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}
DECL E6POS XP2={X 500.0,Y 100.0,Z 600.0,A 0.0,B 90.0,C 0.0,S 2,T 2,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}
DECL E6POS XP3={X 550.0,Y 150.0,Z 600.0,A 0.0,B 90.0,C 0.0,S 2,T 2,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}
DECL E6POS XP4={X 500.0,Y 200.0,Z 600.0,A 0.0,B 90.0,C 0.0,S 2,T 2,E1 0.0,E2 0.0,E3 0.0,E4 0.0,E5 0.0,E6 0.0}
DECL FDAT FP1={TOOL_NO 0,BASE_NO 0,IPO_FRAME #BASE,POINT2[] " "}
DECL FDAT FP2={TOOL_NO 0,BASE_NO 0,IPO_FRAME #BASE,POINT2[] " "}
DECL PDAT PPDAT1={VEL 100.000,ACC 100.000,APO_DIST 100.000,GEAR_JERK 50.0000,EXAX_IGN 0}
DECL LDAT LCPDAT1={VEL 2.00000,ACC 100.000,APO_DIST 100.000,APO_FAC 50.0000,AXIS_VEL 100.000,AXIS_ACC 100.000,ORI_TYP #VAR,CIRC_TYP #BASE,JERK_FAC 50.0000,GEAR_JERK 50.0000,EXAX_IGN 0}
ENDDAT
"""
