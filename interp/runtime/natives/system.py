"""The controller's state and errors (reference 4.8, 5.19, 8.3): ERR_CLEAR, ERR_RAISE,
GETSYSSTATE.

ERR_RAISE stops the program with the error an ERROR_T variable holds (nothing when its NUMBER
is 0); ERR_CLEAR clears it. GETSYSSTATE answers "STOPBITS" (:func:`_getsysstate`).
"""

from __future__ import annotations

from krl.semantics.facts import ARGS, TASKS
from ..convert import ref_text
from ..errors import KrlRuntimeError
from ..values import UNSET
from .registry import Family

SYSTEM = Family("system state")


@SYSTEM.native("ERR_CLEAR(ERROR_T PERR :OUT)", reads=(ARGS, TASKS), writes=(ARGS, TASKS))
def _err_clear(ctx, a):
    e = a[0].peek()
    ctx.errstate.clear_err(e)


@SYSTEM.native("ERR_RAISE(ERROR_T PERR :OUT)", reads=(ARGS, TASKS), writes=(ARGS, TASKS))
def _err_raise(ctx, a):
    e = a[0].peek()
    n = e.f.get("NUMBER", 0)
    if n in (UNSET, 0):
        return None
    msg = ctx.errstate.err_message(e)
    raise KrlRuntimeError(msg, n)


GETSYSSTATE_COMMANDS = ("STOPBITS",)
"""The GETSYSSTATE commands the simulator answers (the only one the corpus uses)."""


@SYSTEM.native("BOOL GETSYSSTATE(...)", pure=True)
def _getsysstate(ctx, a):
    """``BOOL GETSYSSTATE(CHAR CMD[64] :IN, INT IPAR :OUT, REAL RPAR :OUT)`` (KSS
    ``$OPERATE`` EXTFCTP, operate.dat; reference §4.8 names it, KUKA does not document it).
    ``"STOPBITS"`` (KUKA's torque monitoring, tm_bib.src, asks it before it changes its
    limits): TRUE, IPAR = the stop reactions active on the controller as bits, 0 = none, and
    RPAR = 0.0. The simulated controller never holds the robot in a stop reaction that a
    program goes on past (a stop ends the run), so IPAR is always 0: the simulated answer.
    Any other command: FALSE, IPAR and RPAR unchanged, one ``message`` event per command."""
    cmd = ref_text(a[0], "GETSYSSTATE command").strip().upper()
    if cmd not in GETSYSSTATE_COMMANDS:
        key = "GETSYSSTATE " + cmd[:64]
        ctx.note_once(key, f"not simulated: GETSYSSTATE(\"{cmd[:64]}\") answers FALSE")
        return False
    if len(a) > 1 and a[1] is not None:
        a[1].set(0)
    if len(a) > 2 and a[2] is not None:
        a[2].set(0.0)
    return True
