"""KRL values (reference §3).

Representation (shared by both interpreters):

* INT -> ``int`` (32-bit range enforced by :mod:`convert`), REAL -> ``float``,
  BOOL -> ``bool``, CHAR -> a one-character ``str`` (code 0..255; arithmetic uses the code);
* a string literal -> ``str``;
* ENUM -> :class:`EnumValue` (compared by value name; the enum type comes from the context;
  the front end's, krl/semantics/values.py, as :data:`UNSET`);
* STRUC -> :class:`Struct`: ``type`` (a :class:`krl.semantics.types.Struc`, or None for an
  untyped aggregate) and ``f``, a dict UPPER component name -> value. An aggregate
  evaluates to a Struct holding only the components it names (a *partial* value,
  reference §3.9): assignment copies exactly the components present;
* arrays -> :class:`Arr` (1-based, row-major flat ``data``);
* :data:`UNSET` marks a leaf that was declared but never assigned: reading it is error
  1422 "value invalid" (reference §10.2).

Types are the front end's :mod:`krl.semantics.types` classes (Simple, Array, Struc, Enum).
"""

from __future__ import annotations

from functools import partial

from krl.limits import MAX_NESTING
from krl.semantics import types as T
from krl.semantics.values import UNSET, EnumValue  # the front end's scalar values

from .errors import KrlRuntimeError


class Channel:
    """``:SER_3``: a channel of the controller as an argument (COPEN), by its upper-case name."""

    __slots__ = ("name",)

    def __init__(self, name: str) -> None:
        self.name = name.upper()

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Channel) and other.name == self.name

    def __hash__(self) -> int:
        return hash((":", self.name))

    def __repr__(self) -> str:
        return f":{self.name}"


class Struct:
    """A structure value; ``f`` maps UPPER component names to values (see module doc)."""

    __slots__ = ("type", "f")

    def __init__(self, type_, f: dict | None = None) -> None:
        self.type = type_
        self.f = f if f is not None else {}

    def __repr__(self) -> str:
        name = self.type.name if self.type is not None else ""
        return "{" + (name + ": " if name else "") + ", ".join(f"{k} {v!r}" for k, v in self.f.items()) + "}"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Struct) and self.f == other.f


class Arr:
    """An array: ``type`` (T.Array), ``dims`` (sizes), ``data`` (flat, row-major)."""

    __slots__ = ("type", "dims", "data")

    def __init__(self, type_, dims: tuple, data: list) -> None:
        self.type = type_
        self.dims = dims
        self.data = data

    @property
    def elem(self):
        return self.type.elem

    def flat(self, idx: list[int]) -> int:
        """Flat position of 1-based indices ``idx``; raises IndexError when out of range."""
        if len(idx) != len(self.dims):
            raise IndexError(f"{len(idx)} indices for {len(self.dims)} dimensions")
        pos = 0
        for i, n in zip(idx, self.dims):
            if not 1 <= i <= n:
                raise IndexError(f"index {i} outside 1..{n}")
            pos = pos * n + (i - 1)
        return pos

    def text(self) -> str:
        """A CHAR array as a Python string: up to the first NUL or unset element."""
        out = []
        for c in self.data:
            if c is UNSET or c == "\0":
                break
            out.append(c)
        return "".join(out)

    def __repr__(self) -> str:
        if self.type.elem == T.CHAR:
            return repr(self.text())
        return f"Arr{self.dims}{self.data!r}"


def is_char_array(v) -> bool:
    return isinstance(v, Arr) and v.type.elem == T.CHAR and len(v.dims) == 1


def data_size(t) -> int:
    """The number of data elements (krl/limits.py MAX_DATA_ELEMENTS) a fresh value of type
    ``t`` holds, computed from the type without building the value: a scalar or an unknown
    type 1, a structure 1 plus its components, an array its element count times its
    element. Raises :class:`errors.KrlRuntimeError` for a STRUC that contains itself or
    types nested deeper than krl/limits.py MAX_NESTING (the caller adds the place)."""
    memo: dict = {}     # id(Struc) -> (elements, levels of STRUC nesting below and with it)
    busy: set = set()

    def size(t) -> tuple[int, int]:
        if isinstance(t, T.Array):
            n = 1
            for d in t.dims:
                n *= d
            got, levels = size(t.elem)
            return n * got, levels
        if not isinstance(t, T.Struc):
            return 1, 0
        got = memo.get(id(t))
        if got is not None:
            return got
        if id(t) in busy:
            raise KrlRuntimeError(f"STRUC {t.name} contains itself")
        if len(busy) >= MAX_NESTING:
            raise KrlRuntimeError(f"nesting too deep: more than {MAX_NESTING} levels of STRUC in {t.name}")
        busy.add(id(t))
        n, levels = 1, 0
        for _, ft in t.fields.values():
            k, lv = size(ft)
            n += k
            levels = max(levels, lv)
        busy.discard(id(t))
        got = memo[id(t)] = (n, levels + 1)
        return got

    n, levels = size(t)
    if levels > MAX_NESTING:
        raise KrlRuntimeError(f"nesting too deep: more than {MAX_NESTING} levels of STRUC in {t}")
    return n


def value_size(v) -> int:
    """The data elements of an existing value (as :func:`data_size` counts them; an open
    array parameter's copy is sized by its value, not its type)."""
    if isinstance(v, Arr):
        if not v.data:
            return 0
        first = v.data[0]
        return len(v.data) * (value_size(first) if isinstance(first, (Struct, Arr)) else 1)
    if isinstance(v, Struct):
        return data_size(v.type) if v.type is not None else 1 + len(v.f)
    return 1


#: id(structure type) -> (the type, its field count, a function of no arguments that makes a
#: fresh value of it): made once per type (:func:`struc_maker`); a structure type is never
#: made by the run (only the front end's), so the table stays as small as the program's types
_STRUC_MAKERS: dict[int, tuple] = {}


def struc_maker(t, _building: frozenset = frozenset()):
    """A function of no arguments returning a fresh value of structure type ``t`` (UNSET
    leaves, the components in the type's order): a structure whose components are all scalars
    is one C-level copy of a dict; a STRUC or array component is made by its own maker
    (:func:`maker`; a STRUC that contains itself, which values.data_size refuses, by
    :func:`make_value`)."""
    c = _STRUC_MAKERS.get(id(t))
    fields = t.fields
    if c is not None and c[0] is t and c[1] == len(fields):
        return c[2]
    tmpl = dict.fromkeys(fields, UNSET)
    inner = _building | {id(t)}
    nested = tuple((k, partial(make_value, ft) if _contains(ft, inner) else maker(ft, inner))
                   for k, (_, ft) in fields.items() if isinstance(ft, (T.Struc, T.Array)))
    copy = tmpl.copy
    if not nested:
        def make():
            return Struct(t, copy())
    else:
        def make():
            f = copy()
            for k, mk in nested:
                f[k] = mk()
            return Struct(t, f)
    _STRUC_MAKERS[id(t)] = (t, len(fields), make)
    return make


def _contains(t, ids: frozenset) -> bool:
    """True when type ``t`` is, or holds as an array element, a STRUC of ``ids``."""
    while isinstance(t, T.Array):
        t = t.elem
    return isinstance(t, T.Struc) and id(t) in ids


def maker(t, _building: frozenset = frozenset()):
    """A function of no arguments returning a fresh :func:`make_value` of ``t`` (for a routine's
    locals: made once per routine, called at each call). An array's maker is not kept
    anywhere else (array types are also made while the program runs)."""
    if isinstance(t, T.Struc):
        return struc_maker(t, _building)
    if isinstance(t, T.Array):
        n = 1
        for d in t.dims:
            n *= d
        dims = t.dims
        e = t.elem
        if isinstance(e, (T.Struc, T.Array)):
            mk = partial(make_value, e) if _contains(e, _building) else maker(e, _building)

            def make():
                return Arr(t, dims, [mk() for _ in range(n)])
        else:
            def make():     # (no template: a value is made only after its data memory is taken)
                return Arr(t, dims, [UNSET] * n)
        return make
    return _unset


def _unset():
    return UNSET


def make_value(t):
    """A fresh, uninitialised value of type ``t`` (UNSET leaves)."""
    if isinstance(t, T.Struc):
        c = _STRUC_MAKERS.get(id(t))
        if c is not None and c[0] is t and c[1] == len(t.fields):
            return c[2]()
        return struc_maker(t)()
    if isinstance(t, T.Array):
        n = 1
        for d in t.dims:
            n *= d
        e = t.elem
        if isinstance(e, T.Struc):
            make = struc_maker(e)
            return Arr(t, t.dims, [make() for _ in range(n)])
        if isinstance(e, T.Array):
            return Arr(t, t.dims, [make_value(e) for _ in range(n)])
        return Arr(t, t.dims, [UNSET] * n)
    return UNSET


def zero_value(t):
    """A value of type ``t`` whose INT leaves are 0, REAL 0.0, BOOL FALSE, CHAR NUL; ENUM
    leaves stay UNSET (no value is neutral). For system variables the simulator does not
    model and nothing gives a value (sysvars.SysVars)."""
    return _zeroed(make_value(t), t)


def _zeroed(v, t):
    """``v`` (a fresh :func:`make_value` of ``t``) with its UNSET leaves set to zero."""
    if isinstance(v, Struct):
        for k, (_, ft) in t.fields.items():
            v.f[k] = _zeroed(v.f[k], ft)
    elif isinstance(v, Arr):
        v.data[:] = [_zeroed(x, t.elem) for x in v.data]
    elif t == T.INT:
        v = 0
    elif t == T.REAL:
        v = 0.0
    elif t == T.BOOL:
        v = False
    elif t == T.CHAR:
        v = "\0"
    return v


#: classes of the immutable leaf values: a structure holding only these is copied by a plain
#: copy of its components (:func:`copy_value`) and imaged by one (interp/runtime/idle.py freeze)
LEAVES = frozenset((int, float, bool, str, type(None), EnumValue, type(UNSET)))


def copy_value(v):
    """A deep copy (for :IN parameters and whole-value reads)."""
    if v.__class__ is Struct and LEAVES.issuperset(map(type, v.f.values())):
        return Struct(v.type, v.f.copy())    # only immutable leaves: one C-level copy
    if isinstance(v, Struct):        # (a scalar component is its own copy: no call for it)
        return Struct(v.type, {k: copy_value(x) if isinstance(x, (Struct, Arr)) else x for k, x in v.f.items()})
    if isinstance(v, Arr):
        if v.data and isinstance(v.data[0], (Struct, Arr)):
            return Arr(v.type, v.dims, [copy_value(x) for x in v.data])
        return Arr(v.type, v.dims, list(v.data))
    return v


def is_initialised(v) -> bool:
    """True if ``v`` is set (a Struct/Arr counts as set when one leaf is set)."""
    if v is UNSET:
        return False
    if isinstance(v, Struct):
        return any(is_initialised(x) for x in v.f.values())
    if isinstance(v, Arr):
        return any(is_initialised(x) for x in v.data)
    return True


def type_name_of(v) -> str:
    """KRL type name of a value, for messages and VARTYPE."""
    if isinstance(v, bool):
        return "BOOL"
    if isinstance(v, int):
        return "INT"
    if isinstance(v, float):
        return "REAL"
    if isinstance(v, str):
        return "CHAR" if len(v) == 1 else "string"
    if isinstance(v, EnumValue):
        return v.type.name if v.type is not None else "ENUM"
    if isinstance(v, Struct):
        return v.type.name if v.type is not None else "aggregate"
    if isinstance(v, Arr):
        return str(v.type)
    return "?"


def format_real(v: float) -> str:
    """A REAL in the controller's text: fixed point, at most 6 decimals."""
    s = f"{float(v):.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def value_text(v) -> str:
    """The controller's text of value `v`, as KRL writes its literals (reference §2): INT ``42``,
    REAL ``12.5``, BOOL ``TRUE``/``FALSE``, ENUM ``#T1``, CHAR ``"x"``, a CHAR array ``"text"``, a
    structure ``{E6POS: X 1.5, ...}``, an array's first 64 elements; "" for an unset value. The
    one text of a value for KukaVarProxy (interp/runtime/netvars.py) and the run-time errors'
    messages (no Python literal such as ``False`` in a KRL message)."""
    if v is UNSET or v is None:
        return ""
    if isinstance(v, bool):
        return "TRUE" if v else "FALSE"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return format_real(v)
    if isinstance(v, EnumValue):
        return "#" + v.name
    if isinstance(v, str):
        return '"' + v + '"'
    if is_char_array(v):
        return '"' + v.text() + '"'
    if isinstance(v, Struct):
        parts = [f"{k} {value_text(x)}" for k, x in v.f.items() if x is not UNSET]
        name = getattr(v.type, "name", None)
        return "{" + (f"{name}: " if name else "") + ", ".join(parts) + "}"
    if isinstance(v, Arr):
        return "{" + ", ".join(value_text(x) for x in v.data[:64]) + "}"
    return str(v)
