"""KUKA's BASIS routines that programs call (reference 4.8; KSS bas.src), KUKA Trace's among them: the
checker knows their signatures even when a backup's BASIS lacks them. KRL implements them:
the project's BASIS (interp/basis/bas.src, added to a program outside a backup) or the
backup's own bas.src; a call binds to that routine like any other. A backup whose bas.src
lacks one gets the stand-in for KUKA's software (interp/runtime/kss.py).
"""

from __future__ import annotations

from .registry import Family

BASIS = Family("BASIS")

BASIS.krl("REAL SVEL_JOINT(REAL VEL :IN)", "bas.src")
BASIS.krl("CP SVEL_CP(REAL VEL :IN, CHAR TOOL[] :IN, LDAT LDAT_ :OUT)", "bas.src")
BASIS.krl("REAL SACC_JOINT(PDAT PDAT_ :OUT)", "bas.src")
BASIS.krl("CP SACC_CP(LDAT LDAT_ :OUT)", "bas.src")
BASIS.krl("CONT SAPO(PDAT PDAT_ :OUT)", "bas.src")
BASIS.krl("CONT SAPO_PTP(PDAT PDAT_ :OUT)", "bas.src")
BASIS.krl("FRAME STOOL(FDAT FDAT_ :OUT)", "bas.src")
BASIS.krl("FRAME STOOL2(FDAT FDAT_ :OUT)", "bas.src")
BASIS.krl("FRAME SBASE(INT BASE_NO :IN)", "bas.src")
BASIS.krl("LOAD SLOAD(INT TOOL_NO :IN)", "bas.src")
BASIS.krl("IPO_MODE SIPO_MODE(IPO_MODE MODE :IN)", "bas.src")
BASIS.krl("ORI_TYPE SORI_TYP(ORI_TYPE TYP :IN)", "bas.src")
BASIS.krl("CIRC_TYPE SCIRC_TYP(CIRC_TYPE TYP :IN)", "bas.src")
BASIS.krl("CIRC_MODE SCIRC_M(CIRC_MODE MODE :OUT)", "bas.src")
BASIS.krl("REAL SGEAR_JERK(PDAT PDAT_ :OUT)", "bas.src")
BASIS.krl("JERK_STRUC SJERK(LDAT LDAT_ :OUT)", "bas.src")
BASIS.krl("BAS(BAS_COMMAND COMMAND :IN, REAL VALUE :IN)", "bas.src")

# KUKA Trace (KSS 8 bas.src): start and stop a recording; they write $TRACE (interp/runtime/sysvars.py),
# which marks the recording in the run's trace (issue 60)
BASIS.krl("TraceStart(CHAR CONFIG[] :IN, CHAR NAME[] :IN)", "bas.src")
BASIS.krl("TraceStop()", "bas.src")
