"""The KRL type model and assignment compatibility (reference 3, 4.1).

Types are immutable values compared by name:

* :class:`Simple` -- INT, REAL, BOOL, CHAR (3.1);
* :class:`Array` -- element type and 1-3 dimensions (0 = open, for array parameters) (3.3);
* :class:`Struc` -- a named structure; its components live in ``Struc.fields`` once resolved
  (3.5, 3.7); equality is by name;
* :class:`Enum` -- a named enumeration with its values (3.6);
* :class:`StrType` -- the type of a string literal of a given length (3.4, 1.5);
* :class:`EnumLitType` -- an enum literal whose enum is not known yet (context decides);
* :data:`UNKNOWN` -- the type of an erroneous or unresolvable expression: compatible with
  everything, so one mistake gives one diagnostic;
* :data:`VOID` -- the result of a procedure.

:func:`assignable` implements 3.9: lossless conversions, INT <- REAL (rounding, reported as
lossy), INT <-> CHAR, the geometric families FRAME/POS/E3POS/E6POS and AXIS/E3AXIS/E6AXIS,
CHAR arrays from strings and CHAR arrays; user structures only from the same type.
"""

from __future__ import annotations

from dataclasses import dataclass, field


class KrlType:
    """Base class of all types."""

    __slots__ = ()
    name = "?"

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True, slots=True)
class Simple(KrlType):
    """INT, REAL, BOOL or CHAR (3.1)."""
    name: str

    def __str__(self) -> str:
        return self.name


INT = Simple("INT")
REAL = Simple("REAL")
BOOL = Simple("BOOL")
CHAR = Simple("CHAR")
SIMPLE = {"INT": INT, "REAL": REAL, "BOOL": BOOL, "CHAR": CHAR}


@dataclass(frozen=True, slots=True)
class Array(KrlType):
    """An array of 1-3 dimensions; a size of 0 is an open dimension of an array parameter (2.3, 3.3)."""
    elem: KrlType
    dims: tuple[int, ...]

    @property
    def name(self) -> str:  # type: ignore[override]
        return f"{self.elem}[{','.join(str(d) if d else '' for d in self.dims)}]"

    def __str__(self) -> str:
        return self.name


@dataclass(eq=False, slots=True)
class Struc(KrlType):
    """A structure type; ``fields`` maps UPPER component name -> (spelling, type).
    ``soft`` marks a definition from the built-in data tables (may be incomplete: a
    mismatch is a warning, not an error)."""
    name: str
    fields: dict[str, tuple[str, KrlType]] = field(default_factory=dict)
    soft: bool = False

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Struc) and other.name.upper() == self.name.upper()

    def __hash__(self) -> int:
        return hash(("STRUC", self.name.upper()))

    def __str__(self) -> str:
        return self.name

    def field_type(self, name: str) -> KrlType | None:
        got = self.fields.get(name.upper())
        return got[1] if got else None


@dataclass(eq=False, slots=True)
class Enum(KrlType):
    """An enumeration; ``values`` holds the UPPER value names; ``soft`` as for Struc."""
    name: str
    values: frozenset[str] = frozenset()
    soft: bool = False

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Enum) and other.name.upper() == self.name.upper()

    def __hash__(self) -> int:
        return hash(("ENUM", self.name.upper()))

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True, slots=True)
class StrType(KrlType):
    """Type of a string literal of `length` characters (length 1 is also a CHAR)."""
    length: int

    @property
    def name(self) -> str:  # type: ignore[override]
        return f"string[{self.length}]"

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True, slots=True)
class EnumLitType(KrlType):
    """Type of ``#VALUE`` before the context gives it an enum type."""
    value: str

    @property
    def name(self) -> str:  # type: ignore[override]
        return f"#{self.value}"

    def __str__(self) -> str:
        return self.name


@dataclass(frozen=True, slots=True)
class _Special(KrlType):
    name: str

    def __str__(self) -> str:
        return self.name


UNKNOWN = _Special("<unknown>")
VOID = _Special("<no value>")

CARTESIAN = frozenset({"FRAME", "POS", "E3POS", "E6POS"})
AXES = frozenset({"AXIS", "E3AXIS", "E6AXIS"})
GEOMETRIC = CARTESIAN | AXES


def is_numeric(t: KrlType) -> bool:
    """INT, REAL (or UNKNOWN, which is compatible with everything)."""
    return t in (INT, REAL) or t is UNKNOWN


def is_char_array(t: KrlType) -> bool:
    """A one-dimensional CHAR array: a string variable (3.4)."""
    return isinstance(t, Array) and t.elem == CHAR and len(t.dims) == 1


def is_stringish(t: KrlType) -> bool:
    """A CHAR array (1-D) or a string literal."""
    return is_char_array(t) or isinstance(t, StrType)


def geometric_family(t: KrlType) -> str | None:
    """'cartesian' for FRAME/POS/E3POS/E6POS, 'axis' for AXIS/E3AXIS/E6AXIS, else None (3.9)."""
    if isinstance(t, Struc):
        n = t.name.upper()
        if n in CARTESIAN:
            return "cartesian"
        if n in AXES:
            return "axis"
    return None


@dataclass(frozen=True, slots=True)
class Compat:
    """Result of an assignability test: ok, lossy (allowed, with a warning) and a reason."""
    ok: bool
    lossy: bool = False
    reason: str = ""


OK = Compat(True)


def assignable(target: KrlType, source: KrlType) -> Compat:
    """Can a value of type `source` be assigned to a variable of type `target` (3.9)?

    Aggregates are not handled here (the checker compares them component by component
    with :func:`Struc.field_type`); enum literals are checked against the target enum.
    """
    if target is UNKNOWN or source is UNKNOWN:
        return OK
    if target == source:
        return OK
    if isinstance(target, Simple):
        if target == REAL and source == INT:
            return OK
        if target == INT and source == REAL:
            return Compat(True, True, "REAL to INT rounds")
        if target == INT and source == CHAR or target == CHAR and source == INT:
            return OK
        if target == CHAR and isinstance(source, StrType) and source.length == 1:
            return OK
        if target == CHAR and is_char_array(source):
            return Compat(False, reason="a CHAR array is not a CHAR")
        return Compat(False, reason=f"{source} is not assignable to {target}")
    if isinstance(target, Enum):
        if isinstance(source, EnumLitType):
            if not target.values or source.value.upper() in target.values:
                return OK
            return Compat(False, reason=f"#{source.value} is not a value of {target.name}")
        return Compat(False, reason=f"{source} is not assignable to {target}")
    if isinstance(target, Struc):
        fam = geometric_family(target)
        if fam is not None and fam == geometric_family(source):
            return OK
        return Compat(False, reason=f"{source} is not assignable to {target}")
    if isinstance(target, Array):
        if is_char_array(target):
            if isinstance(source, StrType):
                n = target.dims[0]
                if n and source.length > n:
                    return Compat(True, True, f"string of {source.length} characters for CHAR[{n}]")
                return OK
            if is_char_array(source) or source == CHAR:
                return OK
        if isinstance(source, Array) and target.elem == source.elem and len(target.dims) == len(source.dims):
            return OK
        return Compat(False, reason=f"{source} is not assignable to {target}")
    return Compat(False, reason=f"{source} is not assignable to {target}")


def param_compatible(formal: KrlType, actual: KrlType, mode: str) -> Compat:
    """Argument passing (2.3): :IN converts like an assignment; :OUT needs the same type
    (geometric relatives, open-array formals and CHAR-array strings accepted)."""
    if formal is UNKNOWN or actual is UNKNOWN:
        return OK
    if isinstance(formal, Array) and 0 in formal.dims:
        # open array parameter: same element type and rank (strings for CHAR[])
        if formal.elem == CHAR and len(formal.dims) == 1 and (is_stringish(actual) or actual == CHAR):
            return OK if mode == "IN" or not isinstance(actual, StrType) else Compat(
                False, reason="a string literal cannot be passed to :OUT")
        if isinstance(actual, Array) and actual.elem == formal.elem and len(actual.dims) == len(formal.dims):
            return OK
        if isinstance(actual, Array) and assignable(formal.elem, actual.elem).ok:
            return OK
        return Compat(False, reason=f"{actual} does not match {formal}")
    if mode == "IN":
        return assignable(formal, actual)
    got = assignable(formal, actual)
    if got.ok and not got.lossy:
        return OK
    if got.ok and formal in (INT, REAL) and actual in (INT, REAL):
        return Compat(True, True, f"{actual} passed to :OUT {formal}")
    return Compat(False, reason=got.reason or f"{actual} does not match {formal}")


def parse_component_list(text: str) -> list[tuple[str, str, tuple[int, ...]]]:
    """'REAL X, Y, INT S, CHAR T[24]' -> [('REAL','X',()), ('REAL','Y',()), ('INT','S',()),
    ('CHAR','T',(24,))]: the STRUC component syntax of reference 3.5 (used by the data tables)."""
    out = []
    cur = None
    for part in text.split(","):
        words = part.strip().split()
        if not words:
            continue
        if len(words) == 2:
            cur, nm = words
        else:
            nm = words[0]
        dims: tuple[int, ...] = ()
        if "[" in nm:
            nm, rest = nm.split("[", 1)
            dims = tuple(int(x) if x.strip() else 0 for x in rest.rstrip("]").split(","))
        out.append((cur or "INT", nm, dims))
    return out
