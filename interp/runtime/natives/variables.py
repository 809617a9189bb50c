"""A variable named by text (reference 4.5): VARSTATE and VARTYPE.

The text is resolved the way the program's own names are, in the calling routine's scope
(``ctx.names.ref_from_text``; no KRL expression is parsed here). VARSTATE answers #UNKNOWN (no such
variable), #DECLARED (declared, no value) or #INITIALIZED; VARTYPE the variable's type as
VAR_TYPE (#TYP_INT ... #TYP_E6AXIS, #TYP_ENUM, #TYP_STRUC, #TYP_UNKNOWN).
"""

from __future__ import annotations

from krl.semantics import types as T

from ..convert import ref_text
from ..errors import KrlRuntimeError
from ..values import EnumValue, is_initialised
from .registry import Family

VARIABLES = Family("variables")


@VARIABLES.native("VAR_STATE VARSTATE(CHAR VAR_STR[] :IN)", pure=True)
def _varstate(ctx, a):
    name = ref_text(a[0], "VARSTATE argument")
    try:
        ref = ctx.names.ref_from_text(name)
    except KrlRuntimeError:
        return EnumValue("UNKNOWN")
    if ref is None:
        return EnumValue("UNKNOWN")
    try:
        v = ref.peek()
    except KrlRuntimeError:
        return EnumValue("DECLARED")
    return EnumValue("INITIALIZED" if is_initialised(v) else "DECLARED")


@VARIABLES.native("VAR_TYPE VARTYPE(CHAR VAR_STR[] :IN)", pure=True)
def _vartype(ctx, a):
    name = ref_text(a[0], "VARTYPE argument")
    ref = ctx.names.ref_from_text(name)
    if ref is None:
        return EnumValue("TYP_UNKNOWN")
    t = ref.type
    if t in (T.INT, T.REAL, T.BOOL, T.CHAR):
        return EnumValue("TYP_" + t.name)
    if isinstance(t, T.Enum):
        return EnumValue("TYP_ENUM")
    if isinstance(t, T.Struc):
        n = t.name.upper()
        return EnumValue("TYP_" + n if n in ("FRAME", "POS", "E3POS", "E6POS", "AXIS", "E3AXIS", "E6AXIS") else "TYP_STRUC")
    return EnumValue("TYP_UNKNOWN")
