"""The runtime as the network hub sees it (net/hub.py "sink"): flags and outputs a partner's
message sets, and global variables read and written by name in the controller's text form
(KukaVarProxy, net/varproxy.py; docs/network.md "KukaVarProxy").

Text forms (what the OpenShowVar protocol carries): INT ``42``, REAL ``12.5`` (fixed point, at
most 6 decimals), BOOL ``TRUE``/``FALSE``, ENUM ``#T1``, CHAR array ``"text"``, a structure
``{E6POS: X 1.5, Y 0, ...}``. A write takes the same forms (a structure may name only some
components). Names are global: ``$`` system variables, the variables of ``$config.dat`` and
of public data lists, with ``[i]`` and ``.COMPONENT`` after them. A value text is read by
:func:`parse_value` (literals only: nothing is evaluated) and assigned with the program's own
conversions.
"""

from __future__ import annotations

import re

from krl.limits import MAX_VARPROXY_NAME_CHARS, MAX_VARPROXY_VALUE_CHARS

from .errors import KrlRuntimeError
from .memory import field_ref, index_ref
from .values import UNSET, Arr, EnumValue, Struct, is_char_array, value_text  # noqa: F401 - the text form
from .writerules import admit, check, protected


class ValueTextError(ValueError):
    """A value text that is not a KRL literal (or past the size limits)."""


_TOKEN = re.compile(r'\s*(?:(?P<str>"[^"]*")|(?P<num>[+-]?(?:\d+\.?\d*(?:[Ee][+-]?\d+)?|\.\d+(?:[Ee][+-]?\d+)?))'
                    r"|(?P<enum>#[A-Za-z_$][\w$]*)|(?P<name>[A-Za-z_$][\w$]*)|(?P<p>[{}:,]))")


def parse_value(text: str):
    """A literal value text -> Python value (int, float, bool, EnumValue, str, or a dict for
    a structure). Raises :class:`ValueTextError`."""
    if len(text) > MAX_VARPROXY_VALUE_CHARS:
        raise ValueTextError(f"value text longer than {MAX_VARPROXY_VALUE_CHARS} characters")
    toks = []
    pos = 0
    t = text.strip()
    while pos < len(t):
        m = _TOKEN.match(t, pos)
        if not m or m.end() == pos:
            raise ValueTextError(f"not a KRL literal at {t[pos:pos + 20]!r}")
        toks.append((m.lastgroup, m.group(m.lastgroup)))
        pos = m.end()
        while pos < len(t) and t[pos].isspace():
            pos += 1
    if not toks:
        raise ValueTextError("empty value")
    val, i = _value(toks, 0, 0)
    if i != len(toks):
        raise ValueTextError("text after the value")
    return val


def _value(toks, i, depth):
    if depth > 8:
        raise ValueTextError("structure nested too deeply")
    if i >= len(toks):
        raise ValueTextError("value missing")
    kind, tok = toks[i]
    if kind == "str":
        return tok[1:-1], i + 1
    if kind == "num":
        if re.fullmatch(r"[+-]?\d+", tok):
            if len(tok.lstrip("+-")) > 10:
                raise ValueTextError("INT out of range")
            return int(tok), i + 1
        return float(tok), i + 1
    if kind == "enum":
        return EnumValue(tok[1:].upper()), i + 1
    if kind == "name" and tok.upper() in ("TRUE", "FALSE"):
        return tok.upper() == "TRUE", i + 1
    if tok == "{":
        i += 1
        if i + 1 < len(toks) and toks[i][0] == "name" and toks[i + 1][1] == ":":
            i += 2                      # the type name is the variable's own
        out = {}
        while i < len(toks) and toks[i][1] != "}":
            if toks[i][0] != "name":
                raise ValueTextError("a component name expected")
            comp = toks[i][1].upper()
            v, i = _value(toks, i + 1, depth + 1)
            out[comp] = v
            if i < len(toks) and toks[i][1] == ",":
                i += 1
        if i >= len(toks):
            raise ValueTextError("'}' missing")
        return out, i + 1
    raise ValueTextError(f"not a KRL literal: {tok[:20]!r}")


_PATH = re.compile(r"\s*(\$?[A-Za-z_][\w$]*)")


class RuntimeSink:
    """The sink of the network hub for a run. Every write of a partner into the run is
    announced first (:meth:`changed_outside`, interp/runtime/core.py ``Runtime.changed_outside``):
    a parked spin catches up over the state it saw, and every watch key moves."""

    __slots__ = ("announce", "sysvars", "program", "names", "io")

    def __init__(self, announce, sysvars, program, names, io) -> None:
        """For the run whose `announce()` is its ``Runtime.changed_outside``, with `sysvars`
        (sysvars.SysVars: ``$FLAG``, the ``$`` names), `program` (program.Program: the global
        names), `names` (names.Names: their references) and `io` (robot.io.IOImage: the
        controller's, for ``$OUT``)."""
        self.announce = announce
        self.sysvars = sysvars
        self.program = program
        self.names = names
        self.io = io

    def changed_outside(self) -> None:
        """A partner is about to write into the run (a flag, a variable, an input, a message in
        an EKI channel's memory, an RSI answer): net/partner.py, docs/network.md."""
        self.announce()

    def admit(self, name: str, value, writer: str, scalar: bool | None = True):
        """The controller's write rules (writerules.py) for a partner's write of `value` into
        `name` (``$IN[3]``, ``$ANIN[2]``, ...) by `writer` (``opcua``, ``modbus``): None when it
        is admitted, else the refusal (a KrlRuntimeError with its KSS number and ``rule``). Pure:
        a partner's server thread may ask (net/plc.py)."""
        return admit(name, value, writer, scalar)

    def set_flag(self, n: int, v: bool) -> None:
        check(f"$FLAG[{n}]", bool(v), "eki", True)
        flags = self.sysvars.store.get("$FLAG")
        if isinstance(flags, Arr) and 1 <= n <= len(flags.data):
            if flags.data[n - 1] != bool(v):
                self.announce()
            flags.data[n - 1] = bool(v)

    def set_out(self, n: int, v: bool) -> None:
        check(f"$OUT[{n}]", bool(v), "eki", True)
        self.io.set_out(n, bool(v), "network")

    def ref(self, text: str):
        """The reference a global name with indices and components denotes. Raises KeyError."""
        if len(text) > MAX_VARPROXY_NAME_CHARS:
            raise KeyError("name too long")
        m = _PATH.match(text)
        if not m:
            raise KeyError(text)
        name = m.group(1)
        ref = None
        if name.startswith("$"):
            ref = self.sysvars.lookup(name.upper())
        if ref is None:
            prog = self.program
            scope = prog.ws.global_scope
            sym = scope.lookup(name) if scope is not None else None
            if sym is None or sym.kind not in ("var", "const", "signal"):
                raise KeyError(name)
            try:
                ref = self.names.storage_ref(prog.ws.resolver.storage(name, sym, None, -1), None)
            except (KrlRuntimeError, IndexError):
                raise KeyError(name) from None
        rest = text[m.end():].strip()
        while rest:
            if rest.startswith("["):
                j = rest.find("]")
                parts = [x.strip() for x in rest[1:j].split(",")] if j > 0 else None
                if parts is None or not all(re.fullmatch(r"-?[0-9]{1,10}", x) for x in parts):
                    raise KeyError(text)
                ref = index_ref(ref, [int(x) for x in parts], name)
                rest = rest[j + 1:].strip()
            elif rest.startswith("."):
                mm = re.match(r"\.\s*([A-Za-z_][\w$]*)", rest)
                if not mm:
                    raise KeyError(text)
                ref = field_ref(ref, mm.group(1).upper(), name)
                rest = rest[mm.end():].strip()
            else:
                raise KeyError(text)
        return ref

    def read_var(self, name: str) -> str:
        """The text of a global variable (KeyError: no such name; KrlRuntimeError: no value)."""
        return value_text(self.ref(name).get())

    def write_var(self, name: str, text: str, writer: str = "varproxy") -> str:
        """Assign the value `text` to a global variable through the controller's write rules
        (writerules.py: protection, type and shape, range); returns its new text. An output it
        sets (``$OUT[n]``, a SIGNAL of outputs, ``$ANOUT[n]``) is logged as `writer`'s (the
        partner's name: robot/io.py ``IOImage.writer``), not the program's. Raises KeyError,
        ValueTextError, KrlRuntimeError (KSS 1388 a write-protected variable, 1446 a value refused,
        a conversion)."""
        ref = self.ref(name)
        if getattr(ref, "readonly", False):
            raise protected(name)
        v = parse_value(text)
        cur = ref.peek()
        check(name, v, "varproxy", not isinstance(cur, (Struct, Arr)))
        if isinstance(v, dict):
            v = Struct(None, v)
        self.announce()
        if is_char_array(cur) and isinstance(v, str):
            data = cur.data
            for i in range(len(data)):
                data[i] = v[i] if i < len(v) else "\0"
        else:
            io = self.io
            io.writer = writer
            try:
                ref.set(v)
            finally:
                io.writer = None
        return value_text(ref.get())
