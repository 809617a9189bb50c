"""Symbol tables: a hierarchy of scopes, as in reference 2.7.

    system  (predefined types, system variables, built-in routines; from the data tables)
      -> basis   (the BASIS declarations a $config.dat normally holds; shadowed by a real one)
        -> global  ($config.dat, system data lists $*.dat, GLOBAL names of PUBLIC data lists,
                    main routines of all modules and GLOBAL routines)
          -> module  (the module's .dat data list and the local routines of its .src)
            -> routine (parameters and local declarations)

Each :class:`Scope` has three namespaces (values, types, routines); lookups walk up the
parents. Names are case-insensitive (1.1): keys are upper-case. ``type_symbols`` records, for
each STRUC/ENUM a program declares in the scope, where the checker's Declarer entered it (a
Symbol of kind 'type': ``decl``, ``path``, ``module``, ``scope``); built-in types have none.

A :class:`Symbol` is what the checker attaches to a Name/Call (``node.ann.symbol``):
``kind`` is one of 'var', 'const', 'param', 'signal', 'sysvar', 'routine', 'type', 'label';
``type`` is its KrlType; ``scope`` the scope kind where it was declared; ``decl`` the
declaring AST node (None for built-ins); ``access`` 'RW' or 'RO'; ``mode`` the parameter mode;
``signature`` a :class:`RoutineSig` for routines; ``module`` the module name for module/global
data (the interpreters key persistent data-list storage on it); ``alias`` for an IMPORT
name, the imported data-list variable's symbol.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache

from krl.semantics import types as T
from krl.semantics.builtins import load_builtins


@dataclass(slots=True)
class ParamSig:
    """A routine parameter in a signature: name, type and mode ('IN', 'OUT' or None)."""
    name: str
    type: T.KrlType
    mode: str | None          # 'IN', 'OUT' or None (not written)


@dataclass(slots=True)
class RoutineSig:
    """A routine signature: returns None for a procedure."""
    name: str
    returns: T.KrlType | None
    params: list[ParamSig] = field(default_factory=list)
    varargs: bool = False

    @property
    def is_function(self) -> bool:
        return self.returns is not None


@dataclass(slots=True, eq=False)
class Symbol:
    """A declared name (see the module docstring for the fields)."""
    name: str
    kind: str
    type: T.KrlType
    scope: str = ""
    decl: object = None
    access: str = "RW"
    mode: str | None = None
    signature: RoutineSig | None = None
    module: str = ""
    stop_read: bool = False
    stop_write: bool = False
    path: str = ""
    alias: "Symbol | None" = None    # IMPORT: the data-list variable this name stands for

    def __repr__(self) -> str:
        return f"Symbol({self.name!r}, {self.kind}, {self.type}, scope={self.scope})"


class Scope:
    """One level of the hierarchy; kind is 'system', 'basis', 'global', 'module' or 'routine'."""

    __slots__ = ("kind", "name", "parent", "values", "types", "routines", "type_symbols")

    def __init__(self, kind: str, name: str = "", parent: "Scope | None" = None):
        self.kind = kind
        self.name = name
        self.parent = parent
        self.values: dict[str, Symbol] = {}
        self.types: dict[str, T.KrlType] = {}
        self.routines: dict[str, Symbol] = {}
        self.type_symbols: dict[str, Symbol] = {}   # UPPER name -> where a declared type was entered

    def define(self, table: str, sym: Symbol) -> Symbol | None:
        """Add `sym` to namespace `table` ('values' or 'routines'); return the previous
        symbol of that name in this scope (a duplicate) without replacing it, else None."""
        d = getattr(self, table)
        key = sym.name.upper()
        old = d.get(key)
        if old is not None:
            return old
        d[key] = sym
        return None

    def define_type(self, name: str, typ: T.KrlType) -> T.KrlType | None:
        """Add a type name; return the existing type of that name in this scope (a duplicate), else None."""
        key = name.upper()
        old = self.types.get(key)
        if old is not None:
            return old
        self.types[key] = typ
        return None

    def lookup(self, name: str) -> Symbol | None:
        """A variable, constant, parameter, signal or system variable, searched up the parents (2.7)."""
        key = name.upper()
        s: Scope | None = self
        while s is not None:
            got = s.values.get(key)
            if got is not None:
                return got
            s = s.parent
        return None

    def lookup_routine(self, name: str) -> Symbol | None:
        """A routine (user, EXT-declared or built-in), searched up the parents."""
        key = name.upper()
        s: Scope | None = self
        while s is not None:
            got = s.routines.get(key)
            if got is not None:
                return got
            s = s.parent
        return None

    def lookup_type(self, name: str) -> T.KrlType | None:
        """A type by name, searched up the parents."""
        key = name.upper()
        s: Scope | None = self
        while s is not None:
            got = s.types.get(key)
            if got is not None:
                return got
            s = s.parent
        return None


def make_array(elem: T.KrlType, dims) -> T.KrlType:
    """`elem` itself for no dimensions, else Array(elem, dims) (3.3)."""
    dims = tuple(dims or ())
    return T.Array(elem, dims) if dims else elem


def fill_struc(scope: Scope, struc: T.Struc, components) -> list[str]:
    """Resolve (type name, comp name, dims) triples into struc.fields; returns unknown type names."""
    unknown = []
    for tname, cname, dims in components:
        ct = scope.lookup_type(tname)
        if ct is None:
            unknown.append(tname)
            ct = T.UNKNOWN
        struc.fields.setdefault(cname.upper(), (cname, make_array(ct, dims)))
    return unknown


def _sig_from_info(scope: Scope, info) -> RoutineSig:
    def ty(name: str, dims) -> T.KrlType:
        return make_array(scope.lookup_type(name) or T.UNKNOWN, dims)
    return RoutineSig(info.name,
                      ty(info.returns, ()) if info.returns else None,
                      [ParamSig(p.name, ty(p.type_name, p.dims), p.mode) for p in info.params],
                      info.varargs)


@lru_cache(maxsize=1)
def system_scopes() -> tuple[Scope, Scope]:
    """(system, basis) scopes built from the data tables, once per process. Treat as read-only."""
    b = load_builtins()
    system = Scope("system", "$SYSTEM")
    for n in b.simple:
        system.define_type(n, T.SIMPLE[n])
    for name, values in b.enums.items():
        system.define_type(name, T.Enum(name, frozenset(str(v).upper() for v in values), soft=name.upper() not in b.exact))
    strucs = {name: T.Struc(name, soft=name.upper() not in b.exact) for name in b.structs}
    for name, s in strucs.items():
        system.define_type(name, s)
    for name, text in b.structs.items():
        fill_struc(system, strucs[name], T.parse_component_list(text))
    # types of KUKA's system data lists (kss.yaml): only names the reference tables lack
    for name, values in b.kss_enums.items():
        if system.lookup_type(name) is None:
            system.define_type(name, T.Enum(name, frozenset(v.upper() for v in values), soft=True))
    kss = {name: T.Struc(name, soft=True) for name in b.kss_structs if system.lookup_type(name) is None}
    for name, s in kss.items():
        system.define_type(name, s)
    for name, s in kss.items():
        fill_struc(system, s, T.parse_component_list(b.kss_structs[name]))
    for info in list(b.sysvars.values()) + list(b.kss_variables.values()):
        typ = make_array(system.lookup_type(info.type_name) or T.UNKNOWN, info.dims)
        system.define("values", Symbol(info.name, "sysvar", typ, "system", None, info.access,
                                       stop_read=info.stop_read, stop_write=info.stop_write))
    basis = Scope("basis", "$BASIS", system)
    for name, values in b.basis_enums.items():
        basis.define_type(name, T.Enum(name, frozenset(str(v).upper() for v in values), soft=name.upper() not in b.exact))
    bstrucs = {name: T.Struc(name, soft=name.upper() not in b.exact) for name in b.basis_structs}
    for name, s in bstrucs.items():
        basis.define_type(name, s)
    for name, text in b.basis_structs.items():
        fill_struc(basis, bstrucs[name], T.parse_component_list(text))
    for name, (tname, dims) in b.basis_variables.items():
        typ = make_array(basis.lookup_type(tname) or T.UNKNOWN, dims)
        basis.define("values", Symbol(name, "var", typ, "basis", module="$CONFIG"))
    for info in b.routines.values():
        target = basis if info.name in b.basis_routines else system    # functions.yaml basis: bas.src's
        sig = _sig_from_info(basis, info)
        rtype = sig.returns if sig.returns is not None else T.VOID
        target.define("routines", Symbol(info.name, "routine", rtype, target.kind, None, "RO",
                                         signature=sig))
    return system, basis
