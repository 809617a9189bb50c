"""System functions and package routines that the simulator does not implement: they stand in
for KUKA's software (interp/runtime/kss.py: counted, one note per run, listed in the run
summary). A procedure does nothing and a function returns the zero value of its result type
(of the type its use gives it, for an ANY result), in a backup or not: the checker's one
decision (docs/robot.md "KUKA's system software at run time"); where no such value exists, the
run stops with "routine NAME not found", as on a controller without the software. Each
declaration says what a call gives.
"""

from __future__ import annotations

from .registry import Family

# with a documented signature (reference 4.8)
KSS = Family("KUKA system functions")

_ZERO_OF_USE = ("the zero value of the type its use gives it (KUKA's software stand-in, noted once); with no "
                "such use the run stops: routine NAME not found")

KSS.stand_in("REAL DIGIN(...)", "0.0 (KUKA's software stand-in, noted once)")
KSS.stand_in("BOOL IS_KEY_PRESSED(INT KEY :IN)",
             "TRUE while the key is held on the KCP/smartPAD ($operate.dat EXTFCTP BOOL "
             "IS_KEY_PRESSED(INT KEY :IN)); nobody presses a key in a simulation", value=False)
KSS.stand_in("E6POS GET_SINGUL(...)", "an E6POS of zeros (KUKA's software stand-in, noted once)")
for _sig in ("ANY EB(...)", "ANY LK(...)", "ANY TOOL_ADJ(...)", "ANY SYNC(...)"):   # EK: natives/geometry.py
    KSS.stand_in(_sig, _ZERO_OF_USE)

# KUKA's system modules, known by name only (functions.yaml ``lenient: system``)
SYSTEM_MODULES = Family("KUKA system modules", lenient="system")

_NAME_ONLY = ("a procedure does nothing, a function returns the zero value of the type its use gives it "
              "(KUKA's software stand-in, noted once); with no such use the run stops: routine NAME not found")

SYSTEM_MODULES.krl("IR_STOPM", "ir_stopm.src")
SYSTEM_MODULES.krl("USE_CM_PRO_VALUES", "collmonlib.src")
for _name in ("SET_CD_PARAMS", "USE_CD_PARAMS", "SET_TQ_VALUES", "GET_COLLMON_SET",
              "EB_ABS", "EO", "TEST_BRAKE", "MSGQUIT", "MSGNOTIFY", "MSGSTATE", "MSGDIALOG", "MSGLOOP",
              "MBX_REC", "ISMESSAGESET", "EMI_RECSTATE"):
    SYSTEM_MODULES.stand_in(_name, _NAME_ONLY)

# KUKA.FRI (the LBR's Fast Robot Interface), known by name only (``lenient: fri``)
FRI = Family("FRI", lenient="fri")
for _name in ("FRIOPEN", "FRICLOSE", "FRISTART", "FRISTOP", "FRISETUP"):
    FRI.stand_in(_name, _NAME_ONLY)
