"""Built-in functions and procedures (reference §4.5-§4.8, §5.12, §5.19).

:data:`NATIVES` maps each built-in the simulator implements (upper-case name: the key the resolver
gives a NATIVE callee, krl/semantics/resolve.py; ``Runtime.native``) to ``fn(rt, args)``;
``args`` is a list of references (:class:`memory.Ref`; an expression argument is wrapped in
:class:`ValueRef`, an omitted one is None). :IN arguments are read with ``get()``, :OUT
arguments written with ``set()``. Signatures are the front end's data table
(krl/semantics/data/functions.yaml). BASIS routines (BAS, SVEL_JOINT, ...) are KRL in
interp/basis/bas.src (or the backup's), not natives.

SWRITE/SREAD use a printf/scanf-style format engine written here (no eval): ``%[flags]
[width][.precision]conv`` with flags ``-+ 0#``, conversions ``d i x X o f F e E g G c s``
and ``%%``. Width and precision are ASCII digits no larger than the length of the CHAR
buffer written or read. A bad specification (unknown conversion, width or precision past the
buffer, a non-ASCII digit) is a format error, as on the controller: the text up to it is
written, ``state.RET1`` = #FMT_ERR and ``state.HITS`` counts the values converted before it;
the program goes on (without a STATE_T variable it is a run-time error). StrToInt/StrToReal
accept KRL literal syntax only (reference §1.5). CAST_TO/CAST_FROM are in cast.py.
GETSYSSTATE answers "STOPBITS" (no stop reaction active; :func:`_getsysstate`); INVERSE
solves the inverse kinematics of the simulated robot (:func:`_inverse`).
The EthernetKRL and RSI functions (EKI_*, RSI_*) are in natives/eki.py.
COPEN(:SER_3, HANDLE) finds no device on any channel: HANDLE 0, the channel not connected
(:func:`_copen`). Unsupported: CREAD/CCLOSE/CIOCTL, GET_SIG_INF, CWRITE channels other than
$CMD — a clear "not supported" run-time error.
"""

from __future__ import annotations

import math
import re

from krl.semantics import types as T

from .cast import cast_from, cast_to
from .convert import INT_MAX, INT_MIN, frame_tuple, inv_pos, num, real_to_int, ref_text, to_bool, trunc_int
from .errors import KrlRuntimeError, value_invalid
from .memory import Ref
from .values import UNSET, Arr, EnumValue, Struct, is_char_array


class ValueRef(Ref):
    """An rvalue passed where a reference is expected (an :IN expression argument)."""

    __slots__ = ("v", "type", "name")

    def __init__(self, v, name: str = "argument") -> None:
        self.v = v
        self.type = None
        self.name = name

    def peek(self):
        return self.v

    def set(self, v) -> None:
        self.v = v


def _real(ref, what="argument") -> float:
    if ref is None:
        raise value_invalid(what)
    return float(num(ref.get(), what))


def _int(ref, what="argument") -> int:
    if ref is None:
        raise value_invalid(what)
    v = num(ref.get(), what)
    return v if v.__class__ is int else real_to_int(v)


def _chars(ref, what) -> Arr:
    if ref is None:
        raise value_invalid(what)
    v = ref.peek()
    if not is_char_array(v):
        raise KrlRuntimeError(f"{what} is not a CHAR array")
    return v


def _put_text(arr: Arr, text: str) -> int:
    n = len(arr.data)
    text = text[:n]
    for i, ch in enumerate(text):
        arr.data[i] = ch
    for i in range(len(text), n):
        arr.data[i] = "\0"
    return len(text)


def _mode_sens(ref) -> bool:
    if ref is None:
        return True
    v = ref.get()
    return not (isinstance(v, EnumValue) and v.name == "NOT_CASE_SENS")


# ------------------------------------------------------------------ math (§4.5)

def _abs(rt, a):
    return abs(_real(a[0]))


def _sqrt(rt, a):
    x = _real(a[0])
    if x < 0:
        raise KrlRuntimeError(f"SQRT of a negative number ({x})")
    return math.sqrt(x)


def _trig(fn):
    return lambda rt, a: fn(math.radians(_real(a[0])))


def _tan(rt, a):
    x = _real(a[0])
    if abs(math.cos(math.radians(x))) < 1e-12:
        raise KrlRuntimeError(f"TAN({x}) is undefined")
    return math.tan(math.radians(x))


def _acos(rt, a):
    x = _real(a[0])
    if not -1.0 <= x <= 1.0:
        raise KrlRuntimeError(f"ACOS argument {x} outside -1..1")
    return math.degrees(math.acos(x))


def _atan2(rt, a):
    y, x = _real(a[0]), _real(a[1])
    if x == 0 and y == 0:
        return 0.0
    return math.degrees(math.atan2(y, x))


def _frand(rt, a):
    lo, hi = _real(a[0]), _real(a[1])
    rt.clock_read()     # a random number: not idle (interp/runtime/idle.py)
    return rt.random.uniform(lo, hi)


def _inv_pos(rt, a):
    return inv_pos(a[0].get())


def _forward(rt, a):
    """FORWARD(axes, status): the TCP for ``axes`` with the current $TOOL/$BASE (E6POS)."""
    import numpy as np  # noqa: PLC0415

    from robot.frames import frame_to_matrix, inv_pos as _ip, matrix_to_frame  # noqa: PLC0415

    from .sysvars import pos_struct  # noqa: PLC0415

    ax = a[0].get()
    q = np.array([_real_leaf(ax, k) for k in ("A1", "A2", "A3", "A4", "A5", "A6")], dtype=float)
    ctl = rt.controller
    store = rt.sysvars.store
    tool = frame_to_matrix(*frame_tuple(store["$TOOL"]))
    base = frame_to_matrix(*frame_tuple(store["$BASE"]))
    x, y, z, aa, bb, cc = matrix_to_frame(ctl.model.tcp(q, tool, _ip(base)))
    s, t = ctl.model.kin.status_turn(q)
    if len(a) > 1 and a[1] is not None:
        a[1].set(0)
    return pos_struct({"X": x, "Y": y, "Z": z, "A": aa, "B": bb, "C": cc, "S": s, "T": t})


INVERSE_NOT_REACHABLE = 3
"""INVERSE's STATUS for a position the robot cannot reach (KSS reports "3": its value in
KUKA's field reports; KUKA does not document the codes). 0 is success."""
INVERSE_SOFT_LIMIT = 2
"""INVERSE's STATUS for a position reachable only outside the software limit switches
(a simulated code: KUKA's BASIS treats 2 and 3 alike, bas.src CheckERRStatus)."""


def _inverse(rt, a):
    """``E6AXIS INVERSE(E6POS TOOLPOS :IN, E6AXIS START_AXIS :IN, INT STATUS :OUT)``
    (reference §4.8; KSS operate.dat): the axes that put the TCP at TOOLPOS in the current
    $TOOL/$BASE (as FORWARD and the motions do), with TOOLPOS's S and T where it has them and
    otherwise the solution nearest START_AXIS. STATUS 0; a position out of reach: STATUS
    :data:`INVERSE_NOT_REACHABLE` (outside the software limits: :data:`INVERSE_SOFT_LIMIT`)
    and the result is START_AXIS (the program is expected to test STATUS)."""
    import numpy as np  # noqa: PLC0415

    from robot.errors import SoftLimitError, WorkspaceError  # noqa: PLC0415
    from robot.frames import frame_to_matrix  # noqa: PLC0415

    from .sysvars import axis_struct  # noqa: PLC0415

    pos = a[0].get()
    start = a[1].get() if len(a) > 1 and a[1] is not None else None
    ctl = rt.controller
    ref = (np.array([_real_leaf(start, k) for k in ("A1", "A2", "A3", "A4", "A5", "A6")], dtype=float)
           if start is not None else np.array(ctl.axis_act(), dtype=float)[:6])
    store = rt.sysvars.store
    tool = frame_to_matrix(*frame_tuple(store["$TOOL"]))
    base = frame_to_matrix(*frame_tuple(store["$BASE"]))
    target = frame_to_matrix(*frame_tuple(pos, "INVERSE position"))
    st = pos.f.get("S", UNSET) if isinstance(pos, Struct) else UNSET
    tu = pos.f.get("T", UNSET) if isinstance(pos, Struct) else UNSET
    code = 0
    try:
        q = ctl.model.ik(target, np.linalg.inv(tool), base, None if st is UNSET else int(num(st)),
                         None if tu is UNSET else int(num(tu)), ref)
    except SoftLimitError:
        q, code = ref, INVERSE_SOFT_LIMIT
    except WorkspaceError:
        q, code = ref, INVERSE_NOT_REACHABLE
    if len(a) > 2 and a[2] is not None:
        a[2].set(code)
    return axis_struct(q)


def _real_leaf(s, k):
    v = s.f.get(k, 0.0) if isinstance(s, Struct) else UNSET
    if v is UNSET:
        raise value_invalid(k)
    return float(num(v))


# ------------------------------------------------------------------ VARSTATE (§4.5)

def _varstate(rt, a):
    name = ref_text(a[0], "VARSTATE argument")
    try:
        ref = rt.ref_from_text(name)
    except KrlRuntimeError:
        return EnumValue("UNKNOWN")
    if ref is None:
        return EnumValue("UNKNOWN")
    try:
        v = ref.peek()
    except KrlRuntimeError:
        return EnumValue("DECLARED")
    from .values import is_initialised  # noqa: PLC0415

    return EnumValue("INITIALIZED" if is_initialised(v) else "DECLARED")


def _vartype(rt, a):
    name = ref_text(a[0], "VARTYPE argument")
    ref = rt.ref_from_text(name)
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


# ------------------------------------------------------------------ strings (§4.6)

def _strlen(rt, a):
    return len(ref_text(a[0], "STRLEN argument"))


def _strdecllen(rt, a):
    v = a[0].peek() if a[0] is not None else UNSET
    if isinstance(v, Arr):
        return len(v.data)
    if isinstance(v, str):
        return len(v)
    raise KrlRuntimeError("STRDECLLEN needs a CHAR array")


def _strclear(rt, a):
    _put_text(_chars(a[0], "STRCLEAR argument"), "")
    return True


def _stradd(rt, a):
    dest = _chars(a[0], "STRADD destination")
    return _put_text(dest, dest.text() + ref_text(a[1], "STRADD argument"))


def _strcopy(rt, a):
    dest = _chars(a[0], "STRCOPY destination")
    src = ref_text(a[1], "STRCOPY source")
    _put_text(dest, src)
    return len(src) <= len(dest.data)


def _strcomp(rt, a):
    s1, s2 = ref_text(a[0], "STRCOMP argument 1"), ref_text(a[1], "STRCOMP argument 2")
    if not _mode_sens(a[2] if len(a) > 2 else None):
        return s1.upper() == s2.upper()
    return s1 == s2


def _strfind(rt, a):
    start = _int(a[0])
    s, sub = ref_text(a[1], "STRFIND string"), ref_text(a[2], "STRFIND pattern")
    if not _mode_sens(a[3] if len(a) > 3 else None):
        s, sub = s.upper(), sub.upper()
    if start < 1:
        start = 1
    pos = s.find(sub, start - 1)
    return pos + 1 if pos >= 0 and sub else 0


def _strto(conv):
    def fn(rt, a):
        s = ref_text(a[0], "string")
        try:
            v = conv(s)
        except (ValueError, KrlRuntimeError):
            return False
        a[1].set(v)
        return True
    return fn


# The number syntax of StrToInt/StrToReal is KRL's literal syntax (reference §1.5,
# grammar/KRL.g4 INTLITERAL, HEXLITERAL, BINLITERAL, REALLITERAL) with the sign a data-list
# initial value may carry: ASCII digits only, no blanks, no '_', no 'nan'/'inf', no '0x'.
_INT_SYNTAX = re.compile(r"[+-]?[0-9]+")
_HEX_SYNTAX = re.compile(r"'[Hh]([0-9A-Fa-f]+)'")
_BIN_SYNTAX = re.compile(r"'[Bb]([01]+)'")
_REAL_SYNTAX = re.compile(r"[+-]?(?:[0-9]+\.[0-9]*(?:[Ee][+-]?[0-9]+)?|\.[0-9]+(?:[Ee][+-]?[0-9]+)?"
                          r"|[0-9]+(?:[Ee][+-]?[0-9]+)?)")


def _to_int(s: str) -> int:
    """A KRL INT literal (decimal with an optional sign, 'H..' or 'B..') in -2^31..2^31-1;
    raises ValueError otherwise."""
    if _INT_SYNTAX.fullmatch(s):
        if len(s.lstrip("+-").lstrip("0")) > 10:
            raise ValueError(s)
        v = int(s, 10)
    elif m := _HEX_SYNTAX.fullmatch(s):
        if len(m.group(1).lstrip("0")) > 8:
            raise ValueError(s)
        v = int(m.group(1), 16)
    elif m := _BIN_SYNTAX.fullmatch(s):
        if len(m.group(1).lstrip("0")) > 32:
            raise ValueError(s)
        v = int(m.group(1), 2)
    else:
        raise ValueError(s)
    if not INT_MIN <= v <= INT_MAX:
        raise ValueError(s)
    return v


def _to_real(s: str) -> float:
    """A KRL REAL or decimal INT literal with an optional sign; raises ValueError
    otherwise or when it is too large for any float (1E999)."""
    if not _REAL_SYNTAX.fullmatch(s):
        raise ValueError(s)
    v = float(s)
    if not math.isfinite(v):
        raise ValueError(s)
    return v


def _to_bool(s: str) -> bool:
    u = s.strip().upper()
    if u in ("TRUE", "1"):
        return True
    if u in ("FALSE", "0"):
        return False
    raise ValueError(s)


def _strtostring(rt, a):
    dest = _chars(a[1], "STRTOSTRING destination")
    _put_text(dest, ref_text(a[0], "string"))
    return True


def _strto_struct(tname):
    def fn(rt, a):
        text = ref_text(a[0], "string").strip()
        if not (text.startswith("{") and text.endswith("}")):
            return False
        body = text[1:-1]
        if ":" in body.split(",")[0]:
            body = body.split(":", 1)[1]
        vals = {}
        for part in body.split(","):
            w = part.split()
            if len(w) != 2:
                return False
            try:
                vals[w[0].upper()] = _to_real(w[1]) if w[0].upper() not in ("S", "T") else _to_int(w[1])
            except ValueError:
                return False
        from .sysvars import sys_type  # noqa: PLC0415

        s = Struct(sys_type(tname), vals)
        a[1].set(s)
        return True
    return fn


# ------------------------------------------------------------------ errors (§5.19, §8.3)

def _err_clear(rt, a):
    e = a[0].peek()
    rt.clear_err(e)


def _err_raise(rt, a):
    e = a[0].peek()
    n = e.f.get("NUMBER", 0)
    if n in (UNSET, 0):
        return None
    msg = rt.err_message(e)
    raise KrlRuntimeError(msg, n)


# ------------------------------------------------------------------ I/O (§5.12)

def _pulse(rt, a):
    sig, level, dur = a[0], a[1], a[2]
    lvl = to_bool(level.get(), "PULSE level")
    d = _real(dur, "PULSE duration")
    rt.pulse(sig, lvl, d)


def _krlmsg(a_msg, a_par) -> tuple[str, str, int, list[str]]:
    """(text, module, number, parameter texts) of a KrlMsg_T and its KrlMsgPar_T[] arguments."""
    msg = a_msg.peek() if a_msg is not None else None
    text, module, number = "", "", 0
    if isinstance(msg, Struct):
        for key in ("MSG_TXT", "MODUL"):
            v = msg.f.get(key)
            if isinstance(v, Arr):
                if key == "MSG_TXT":
                    text = v.text()
                else:
                    module = v.text()
        nr = msg.f.get("NR")
        number = nr if isinstance(nr, int) and not isinstance(nr, bool) else 0
    params = []
    pars = a_par.peek() if a_par is not None else None
    if isinstance(pars, Arr):
        for p in pars.data[:3]:
            if not isinstance(p, Struct):
                params.append("")
                continue
            kind = getattr(p.f.get("PAR_TYPE"), "name", "")
            t = p.f.get("PAR_TXT")
            if str(kind).upper() == "VALUE" and isinstance(t, Arr) and t.text() == "":
                v = next((p.f.get(k) for k in ("PAR_INT", "PAR_REAL", "PAR_BOOL") if p.f.get(k) is not UNSET), "")
                params.append("" if v is UNSET else str(v))
            else:
                params.append(t.text() if isinstance(t, Arr) else "")
    return text, module, number, params


def _set_krlmsg(rt, a):
    from .messages import format_text  # noqa: PLC0415

    kind = str(getattr(a[0].peek(), "name", a[0].peek()) if a and a[0] is not None else "NOTIFY").lstrip("#").upper()
    text, module, number, params = _krlmsg(a[1] if len(a) > 1 else None, a[2] if len(a) > 2 else None)
    rt.controller.message(f"KRL message: {text}")
    m = rt.messages.add(kind, format_text(text, params), module, number, time=rt.controller.time)
    rt.msg_handle = m.handle
    return m.handle


def _handle(a) -> int | None:
    """The message handle argument, None when it has no value (no message has it)."""
    try:
        return _int(a[0], "handle") if a else None
    except KrlRuntimeError:
        return None


def _exists_krlmsg(rt, a):
    h = _handle(a)
    return h is not None and rt.messages.exists(h)


def _clear_krlmsg(rt, a):
    h = _handle(a)
    return h is not None and rt.messages.clear(h)


def _set_krldlg(rt, a):
    from .messages import format_text  # noqa: PLC0415

    text, module, number, params = _krlmsg(a[0] if a else None, a[1] if len(a) > 1 else None)
    keys = []
    sk = a[2].peek() if len(a) > 2 and a[2] is not None else None
    if isinstance(sk, Arr):
        for k in sk.data:
            t = k.f.get("SK_TXT") if isinstance(k, Struct) else None
            keys.append(t.text() if isinstance(t, Arr) else "")
    while keys and not keys[-1].strip():
        keys.pop()
    if rt.messages.interactive:
        rt.controller.message(f"KRL dialog: {text}")
    else:
        rt.controller.message("KRL dialog (answered with the first softkey)")
    m = rt.messages.add("DIALOG", format_text(text, params), module, number, keys or ["OK"], rt.controller.time)
    rt.msg_handle = m.handle
    return m.handle


def _exists_krldlg(rt, a):
    h = _handle(a)
    open_, answer = rt.messages.dialog_answer(h) if h is not None else (False, None)
    if answer is not None and len(a) > 1 and a[1] is not None:
        a[1].set(answer)
    return open_


def _copen(rt, a):
    """``COPEN(:SER_3, HANDLE)``: open a channel of the controller. No device answers on any
    channel in the simulation: the channel is *not connected*, HANDLE is 0 (KUKA: a handle > 0
    for an open channel, 0 when it could not be opened), and the run notes it once per channel."""
    from .values import Channel  # noqa: PLC0415

    if len(a) != 2 or a[0] is None or not isinstance(a[0].peek(), Channel):
        raise KrlRuntimeError("COPEN needs a channel name and a handle variable: COPEN(:SER_3, HANDLE)")
    ch = a[0].peek()
    a[1].set(0)
    key = f"COPEN {ch.name}"
    if key not in rt.noted:
        rt.noted.add(key)
        rt.message(f"not simulated: channel :{ch.name} is not connected (no device on it): COPEN gives HANDLE 0")
    return None


def _cwrite(rt, a):
    ch = _int(a[0], "channel")
    cmd = rt.sysvars.store.get("$CMD")
    fmt = ref_text(a[3], "CWRITE format") if len(a) > 3 else ""
    if ch != cmd:
        raise KrlRuntimeError("CWRITE: only the $CMD channel is supported by this simulator")
    rt.message(f"CWRITE $CMD: {fmt}")
    st = a[1].peek() if a[1] is not None else None
    if isinstance(st, Struct) and "RET1" in st.f:
        st.f["RET1"] = EnumValue("CMD_OK")


# ------------------------------------------------------------------ system state (§4.8)

GETSYSSTATE_COMMANDS = ("STOPBITS",)
"""The GETSYSSTATE commands the simulator answers (the only one the corpus uses)."""


def _getsysstate(rt, a):
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
        if key not in rt.noted:
            rt.noted.add(key)
            rt.message(f"not simulated: GETSYSSTATE(\"{cmd[:64]}\") answers FALSE")
        return False
    if len(a) > 1 and a[1] is not None:
        a[1].set(0)
    if len(a) > 2 and a[2] is not None:
        a[2].set(0.0)
    return True


def _unsupported(name):
    def fn(rt, a):
        raise KrlRuntimeError(f"{name} is not supported by this simulator")
    return fn


# ------------------------------------------------------------------ SWRITE / SREAD (§4.7)

_FLAGS = "-+ 0#"
_DIGITS = "0123456789"     # ASCII only: str.isdigit() also takes '²', '٣', ...


class FormatError(Exception):
    """A format that SWRITE/SREAD cannot use: the state's RET1 becomes #FMT_ERR."""


def _ascii_digits(text: str, j: int) -> int:
    """The end of the run of ASCII digits starting at ``text[j]``."""
    n = len(text)
    while j < n and text[j] in _DIGITS:
        j += 1
    return j


def _bounded(digits: str, limit: int, what: str, fmt: str) -> int:
    """``digits`` as a width or precision no larger than ``limit`` (the buffer's length);
    compared as text first, so that a 20-digit number is never turned into an int."""
    significant = digits.lstrip("0") or "0"
    if len(significant) > len(str(limit)) or int(significant) > limit:
        raise FormatError(f"format error: {what} {digits[:12]}{'...' if len(digits) > 12 else ''} "
                          f"larger than the buffer ({limit} characters) in {fmt[:40]!r}")
    return int(significant)


def parse_format(fmt: str, limit: int) -> tuple[list, str | None]:
    """Split a format into literal strings and (flags, width, precision, conv) tuples.

    Returns (parts, error): ``parts`` the format up to the first bad specification,
    ``error`` its message (None when the whole format is good). Width and precision are
    ASCII digits and bounded by ``limit``, the length of the CHAR buffer written (SWRITE)
    or read (SREAD): a larger one is a format error, as is an unknown conversion."""
    out: list = []
    i, n = 0, len(fmt)
    lit = []
    try:
        while i < n:
            ch = fmt[i]
            if ch != "%":
                lit.append(ch)
                i += 1
                continue
            if i + 1 < n and fmt[i + 1] == "%":
                lit.append("%")
                i += 2
                continue
            if lit:
                out.append("".join(lit))
                lit = []
            j = i + 1
            flags = ""
            while j < n and fmt[j] in _FLAGS:
                flags += fmt[j]
                j += 1
            k = _ascii_digits(fmt, j)
            width = _bounded(fmt[j:k], limit, "width", fmt) if k > j else None
            j = k
            prec = None
            if j < n and fmt[j] == ".":
                k = _ascii_digits(fmt, j + 1)
                prec = _bounded(fmt[j + 1:k], limit, "precision", fmt) if k > j + 1 else 0
                j = k
            while j < n and fmt[j] in "lhL":
                j += 1
            if j >= n:
                raise FormatError(f"format error: incomplete specification at the end of {fmt[:40]!r}")
            conv = fmt[j]
            if conv not in "dixXofFeEgGcs":
                raise FormatError(f"format error: %{conv} in {fmt[:40]!r}")
            out.append((flags, width, prec, conv))
            i = j + 1
    except FormatError as exc:
        return out, str(exc)
    if lit:
        out.append("".join(lit))
    return out, None


def _pad(body: str, sign: str, flags: str, width: int | None, numeric: bool) -> str:
    s = sign + body
    if width is None or len(s) >= width:
        return s
    if "-" in flags:
        return s + " " * (width - len(s))
    if "0" in flags and numeric:
        return sign + "0" * (width - len(s)) + body
    return " " * (width - len(s)) + s


def format_one(spec, v) -> str:
    flags, width, prec, conv = spec
    if conv == "s":
        if isinstance(v, Arr):
            s = v.text()
        elif isinstance(v, str):
            s = v
        elif isinstance(v, bool):
            s = "TRUE" if v else "FALSE"
        elif isinstance(v, EnumValue):
            s = v.name
        else:
            s = str(v)
        if prec is not None:
            s = s[:prec]
        return _pad(s, "", flags, width, False)
    if conv == "c":
        if isinstance(v, str):
            s = v[:1]
        else:
            s = chr(trunc_int(v, "%c argument") & 0xFF)
        return _pad(s, "", flags, width, False)
    if isinstance(v, bool):
        v = 1 if v else 0
    x = num(v)
    if conv in "dixXo":
        x = x if x.__class__ is int else real_to_int(x)
        mag = abs(x)
        if conv in "di":
            body = str(mag)
        elif conv == "o":
            body = format(mag, "o")
        else:
            body = format(x & 0xFFFFFFFF if x < 0 else x, "x")
            if conv == "X":
                body = body.upper()
        if prec is not None and len(body) < prec:
            body = "0" * (prec - len(body)) + body
        sign = "-" if x < 0 and conv in "di" else ("+" if "+" in flags else (" " if " " in flags else ""))
        return _pad(body, sign, flags if prec is None else flags.replace("0", ""), width, True)
    x = float(x)
    p = 6 if prec is None else prec
    code = {"f": "f", "F": "f", "e": "e", "E": "E", "g": "g", "G": "G"}[conv]
    body = format(abs(x), f"{'#' if '#' in flags else ''}.{p}{code}")
    neg = x < 0 or (x == 0 and math.copysign(1, x) < 0 and body.strip("0.") != "")
    sign = "-" if neg else ("+" if "+" in flags else (" " if " " in flags else ""))
    return _pad(body, sign, flags, width, True)


def swrite_text(fmt: str, values: list, room: int, limit: int | None = None) -> tuple[str, int, str | None]:
    """(formatted text, number of converted values, format error or None): the text of
    ``fmt`` with ``values``, at most ``room`` characters (the rest of the destination;
    the values past it are still converted and counted); it stops at a bad specification
    (:func:`parse_format`; widths and precisions bounded by ``limit``, the destination's
    length, default ``room``)."""
    parts, error = parse_format(fmt, room if limit is None else limit)
    out = []
    size = 0
    k = 0
    for p in parts:
        if k >= len(values) and not isinstance(p, str):
            break
        if isinstance(p, str):
            piece = p
        else:
            if size >= room:        # converted but not shown: no width, no precision to build
                p = (p[0], None, None, p[3])
            piece = format_one(p, values[k])
            k += 1
        if size < room:
            out.append(piece[:room - size])
            size += len(out[-1])
    return "".join(out), k, error


def _state(ref, ok: bool, hits: int, length: int) -> None:
    if ref is None:
        return
    st = ref.peek()
    if isinstance(st, Struct):
        st.f["RET1"] = EnumValue("CMD_OK" if ok else "FMT_ERR")
        if "HITS" in st.f:
            st.f["HITS"] = hits
        if "LENGTH" in st.f:
            st.f["LENGTH"] = length
        if "MSG_NO" in st.f:
            st.f["MSG_NO"] = 0


def _format_error(state_ref, error: str) -> None:
    """A bad format with no STATE_T variable to report it in is a run-time error."""
    if state_ref is None or not isinstance(state_ref.peek(), Struct):
        raise KrlRuntimeError(error)


def _swrite(rt, a):
    dest = _chars(a[0], "SWRITE destination")
    off_ref = a[2]
    off = _int(off_ref, "SWRITE offset") if off_ref is not None else 0
    fmt = ref_text(a[3], "SWRITE format")
    vals = [r.get() if r is not None else UNSET for r in a[4:]]
    if any(v is UNSET for v in vals):
        raise value_invalid("SWRITE argument")
    n = len(dest.data)
    cur = dest.text()
    off = min(max(off, 0), n)
    text, hits, error = swrite_text(fmt, vals, n - off, n)
    if error is not None:
        _format_error(a[1], error)
    base = (cur + "\0" * n)[:off].replace("\0", " ")
    new = (base + text)[:n]
    for i, ch in enumerate(new):
        dest.data[i] = ch
    for i in range(len(new), n):
        dest.data[i] = "\0"
    if off_ref is not None:
        off_ref.set(len(new))
    _state(a[1], error is None, hits, len(new) - off)


def _scan_int(text: str, base: int) -> int:
    """A scanned integer; more digits than any INT has is INT overflow (never a Python
    int of thousands of digits)."""
    digits = text.lstrip("+-").lstrip("0")
    if len(digits) > 40:
        raise KrlRuntimeError(f"INT overflow ({text[:12]}... outside -2147483648..2147483647)")
    return int(text, base)


def sread_values(src: str, fmt: str, start: int = 0, limit: int | None = None) -> tuple[list, int, str | None]:
    """scanf: (list of (spec, python value), position after the last match, format error
    or None). Widths are bounded by ``limit`` (the source buffer's length; default
    ``len(src)``); numbers are ASCII digits only."""
    parts, error = parse_format(fmt, len(src) if limit is None else limit)
    pos = start
    out = []
    n = len(src)
    for p in parts:
        if isinstance(p, str):
            for ch in p:
                if ch.isspace():
                    while pos < n and src[pos].isspace():
                        pos += 1
                elif pos < n and src[pos] == ch:
                    pos += 1
                else:
                    return out, pos, error
            continue
        flags, width, prec, conv = p
        if conv != "c":
            while pos < n and src[pos].isspace():
                pos += 1
        lim = n if width is None else min(n, pos + width)
        if conv == "c":
            if pos >= n:
                break
            out.append((p, src[pos]))
            pos += 1
            continue
        if conv == "s":
            j = pos
            while j < lim and not src[j].isspace():
                j += 1
            if j == pos:
                break
            out.append((p, src[pos:j]))
            pos = j
            continue
        j = pos
        if conv in "di":
            if j < lim and src[j] in "+-":
                j += 1
            k = j
            while j < lim and src[j] in _DIGITS:
                j += 1
            if j == k:
                break
            out.append((p, _scan_int(src[pos:j], 10)))
        elif conv in "xX":
            while j < lim and src[j] in "0123456789abcdefABCDEF":
                j += 1
            if j == pos:
                break
            out.append((p, _scan_int(src[pos:j], 16)))
        elif conv == "o":
            while j < lim and src[j] in "01234567":
                j += 1
            if j == pos:
                break
            out.append((p, _scan_int(src[pos:j], 8)))
        else:
            if j < lim and src[j] in "+-":
                j += 1
            k = j
            while j < lim and (src[j] in _DIGITS or src[j] == "."):
                j += 1
            if j < lim and src[j] in "eE":
                m = j + 1
                if m < lim and src[m] in "+-":
                    m += 1
                if m < lim and src[m] in _DIGITS:
                    j = m
                    while j < lim and src[j] in _DIGITS:
                        j += 1
            if j == k:
                break
            try:
                out.append((p, float(src[pos:j])))
            except ValueError:
                break
        pos = j
    return out, pos, error


def _sread(rt, a):
    src = ref_text(a[0], "SREAD source")
    off_ref = a[2]
    off = _int(off_ref, "SREAD offset") if off_ref is not None else 0
    fmt = ref_text(a[3], "SREAD format")
    buf = a[0].peek()
    got, pos, error = sread_values(src, fmt, max(0, off), len(buf.data) if isinstance(buf, Arr) else len(src))
    if error is not None:
        _format_error(a[1], error)
    targets = a[4:]
    hits = 0
    for (spec, v), ref in zip(got, targets):
        if ref is None:
            continue
        if isinstance(ref.peek(), Arr):
            _put_text(ref.peek(), str(v))
        else:
            ref.set(v)
        hits += 1
    if off_ref is not None:
        off_ref.set(pos)
    _state(a[1], error is None and hits == len([t for t in targets if t is not None]), hits, pos - off)


NATIVES: dict = {
    "ABS": _abs, "SQRT": _sqrt, "SIN": _trig(math.sin), "COS": _trig(math.cos), "TAN": _tan,
    "ACOS": _acos, "ATAN2": _atan2, "FRAND": _frand, "INV_POS": _inv_pos,
    "FORWARD": _forward, "INVERSE": _inverse,
    "VARSTATE": _varstate, "VARTYPE": _vartype,
    "STRLEN": _strlen, "STRDECLLEN": _strdecllen, "STRCLEAR": _strclear, "STRADD": _stradd,
    "STRCOPY": _strcopy, "STRCOMP": _strcomp, "STRFIND": _strfind,
    "STRTOINT": _strto(_to_int), "STRTOREAL": _strto(_to_real), "STRTOBOOL": _strto(_to_bool),
    "STRTOSTRING": _strtostring,
    "STRTOFRAME": _strto_struct("FRAME"), "STRTOPOS": _strto_struct("POS"),
    "STRTOE3POS": _strto_struct("E3POS"), "STRTOE6POS": _strto_struct("E6POS"),
    "STRTOAXIS": _strto_struct("AXIS"), "STRTOE3AXIS": _strto_struct("E3AXIS"),
    "STRTOE6AXIS": _strto_struct("E6AXIS"),
    "ERR_CLEAR": _err_clear, "ERR_RAISE": _err_raise, "PULSE": _pulse,
    "SWRITE": _swrite, "SREAD": _sread, "CWRITE": _cwrite,
    "SET_KRLMSG": _set_krlmsg, "EXISTS_KRLMSG": _exists_krlmsg, "CLEAR_KRLMSG": _clear_krlmsg,
    "SET_KRLDLG": _set_krldlg, "EXISTS_KRLDLG": _exists_krldlg,
    "CAST_TO": cast_to, "CAST_FROM": cast_from,
    "CREAD": _unsupported("CREAD"), "COPEN": _copen,
    "CCLOSE": _unsupported("CCLOSE"), "CIOCTL": _unsupported("CIOCTL"),
    "GET_SIG_INF": _unsupported("GET_SIG_INF"), "GETSYSSTATE": _getsysstate,
}

from .natives.eki import NATIVES as _NET_NATIVES  # noqa: E402  (EKI_*, RSI_*: docs/network.md)

NATIVES.update(_NET_NATIVES)

__all__ = ["NATIVES", "ValueRef", "swrite_text", "sread_values", "parse_format"]
