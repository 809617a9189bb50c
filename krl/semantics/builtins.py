"""Built-in types, system variables and routines, loaded from the data tables in
``krl/semantics/data`` (types.yaml, sysvars.yaml from the reference; functions.yaml generated
from the simulator's natives registry, interp/runtime/natives, where each routine is declared
with its signature; kss.yaml derived from KUKA system files by krl/survey/derive_tables.py,
each entry with its source). Data, not code:
this module only reads the tables into plain records, once per process.

Reference: 3.7 (predefined structures and enums), 4.5-4.8 (functions and procedures),
6.10 and 7 (system variables, access, advance-run stops).
"""

from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import msgpack
import yaml

from krl.store import Store, shared_store

DATA_DIR = Path(__file__).parent / "data"

try:  # the C loader is much faster where libyaml is present
    _Loader = yaml.CSafeLoader
except AttributeError:  # pragma: no cover
    _Loader = yaml.SafeLoader


@dataclass(slots=True)
class SysVarInfo:
    """A system variable: type name, array sizes, access ('RW' or 'RO'), advance-run stops,
    and ``cyclic``: an assignment to one of its elements is re-evaluated every IPO cycle
    (``$CYCFLAG``, reference §5.15). The write rules (sysvars.yaml's header,
    interp/runtime/writerules.py): ``range`` (lo, hi) of a scalar or of each element, ``safety``
    (a signal of the safety controller: write-protected for every writer), ``fieldbus`` (an
    input the I/O system drives), ``source`` (where the range or protection is documented)."""
    name: str
    type_name: str
    dims: tuple[int, ...] = ()
    access: str = "RW"
    stop_read: bool = False
    stop_write: bool = False
    cyclic: bool = False
    range: tuple[float, float] | None = None
    safety: bool = False
    fieldbus: bool = False
    source: str = ""


@dataclass(slots=True)
class ParamInfo:
    """A parameter of a built-in: type name, array sizes (0 = open), mode 'IN'/'OUT'."""
    name: str
    type_name: str
    dims: tuple[int, ...] = ()
    mode: str = "IN"


@dataclass(slots=True)
class SignatureInfo:
    """A built-in routine; returns is None for a procedure; varargs for '...' lists."""
    name: str
    returns: str | None
    params: list[ParamInfo] = field(default_factory=list)
    varargs: bool = False


@dataclass(slots=True)
class Builtins:
    simple: list[str]
    cartesian: list[str]
    axis: list[str]
    structs: dict[str, str]                 # name -> component list text (STRUC syntax)
    enums: dict[str, list[str]]
    basis_structs: dict[str, str]
    basis_enums: dict[str, list[str]]
    basis_variables: dict[str, tuple[str, tuple[int, ...]]]
    sysvars: dict[str, SysVarInfo]          # UPPER name -> info
    routines: dict[str, SignatureInfo]      # UPPER name -> signature
    exact: frozenset[str] = frozenset()     # UPPER names of complete type definitions
    # kss.yaml (derived, lower precedence than the hand-written tables above):
    kss_structs: dict[str, str] = field(default_factory=dict)
    # the checker knows these names; the interpreters simulate only `sysvars`
    kss_variables: dict[str, SysVarInfo] = field(default_factory=dict)
    kss_enums: dict[str, list[str]] = field(default_factory=dict)
    sources: dict[str, str] = field(default_factory=dict)      # UPPER name -> "path:line"
    packages: dict[str, tuple[str, str]] = field(default_factory=dict)  # UPPER name -> (package, source)
    # UPPER routine name -> (package, source): a package's routines, installed where an archive lists it
    package_routines: dict[str, tuple[str, str]] = field(default_factory=dict)
    programs: dict[str, str] = field(default_factory=dict)    # UPPER file name of a KUKA hook program -> source
    # functions.yaml (generated from the natives registry): the routines whose call stops the
    # advance run (reference 6.10; krl/semantics/advance.py)
    advance_stop: frozenset[str] = frozenset()
    # functions.yaml: the routines of KUKA's BASIS package (bas.src), declared in the $BASIS scope
    basis_routines: frozenset[str] = frozenset()


_NAME_DIMS = re.compile(r"^\s*(\$?[A-Za-z_][\w$]*)\s*(?:\[([\d,\s]*)\])?\s*$")
_SIG = re.compile(r"^\s*(?:([A-Za-z_]\w*)(?:\[(\d*)\])?\s+)?(\$?[A-Za-z_]\w*)\s*\((.*)\)\s*$")
_PARAM = re.compile(r"^\s*([A-Za-z_]\w*)\s+([A-Za-z_]\w*)\s*(?:\[([\d,\s]*)\])?\s*(?::\s*(IN|OUT))?\s*$")


def _dims(text: str | None) -> tuple[int, ...]:
    if text is None:
        return ()
    return tuple(int(x) if x.strip() else 0 for x in text.split(","))


def split_name(key: str) -> tuple[str, tuple[int, ...]]:
    """'$IN[8192]' -> ('$IN', (8192,)); 'TOOL_NAME[16,24]' -> ('TOOL_NAME', (16, 24))."""
    m = _NAME_DIMS.match(key)
    if not m:
        raise ValueError(f"bad name in data table: {key!r}")
    return m.group(1), _dims(m.group(2))


def parse_signature(text: str, is_function: bool) -> SignatureInfo:
    """'REAL ABS(REAL X :IN)' -> SignatureInfo; raises ValueError for a malformed entry."""
    m = _SIG.match(text)
    if not m:
        raise ValueError(f"bad signature: {text!r}")
    rtype, _rsize, name, params_text = m.groups()
    if is_function and not rtype:
        raise ValueError(f"function without return type: {text!r}")
    sig = SignatureInfo(name.upper(), rtype if is_function else None)
    for part in [p for p in params_text.split(",") if p.strip()]:
        if part.strip() == "...":
            sig.varargs = True
            continue
        pm = _PARAM.match(part)
        if not pm:
            raise ValueError(f"bad parameter {part!r} in {text!r}")
        ptype, pname, pdims, mode = pm.groups()
        sig.params.append(ParamInfo(pname, ptype, _dims(pdims), mode or "IN"))
    return sig


def _refuse(*_args):
    raise ValueError("an extension type in a stored table")


def _read(name: str, store=None) -> dict:
    """The YAML document of the data table `name`, from the one store (krl/store.py, kind
    ``table``, keyed by the SHA-256 of the file's bytes) when it holds it: msgpack of the plain
    document (dicts, lists, scalars), kept only when it reads back equal. A stored entry that
    does not unpack to a mapping is corrupt: the YAML is read again."""
    raw = (DATA_DIR / name).read_bytes()
    key = f"{hashlib.sha256(raw).hexdigest()}:{name}"
    store = shared_store() if store is None else store
    got = store.get("table", [key]).get(key)
    if got is not None:
        try:
            doc = msgpack.unpackb(got, raw=False, strict_map_key=False, ext_hook=_refuse)
            if type(doc) is dict:
                return doc
        except (ValueError, TypeError, msgpack.exceptions.UnpackException):
            pass
        store.corrupt += 1
    doc = yaml.load(raw.decode("utf-8"), Loader=_Loader) or {}
    try:
        data = msgpack.packb(doc, use_bin_type=True, strict_types=True)
        if msgpack.unpackb(data, raw=False, strict_map_key=False) == doc:
            store.put("table", {key: data})
    except (TypeError, ValueError, OverflowError):
        pass                            # not plain data: read from the YAML each time
    return doc


@lru_cache(maxsize=1)
def load_builtins() -> Builtins:
    """Read the data tables (cached per process; each document from the one store when it
    holds it, :func:`_read`). Raises ValueError for a malformed table."""
    return _builtins()


def _builtins() -> Builtins:
    """The tables from the store's documents, or from the YAML files when a stored document
    misleads the reader (a corrupt entry: made anew)."""
    try:
        return _load_builtins()
    except (ValueError, KeyError, TypeError, AttributeError):
        return _load_builtins(Store(enabled=False))


def _load_builtins(store=None) -> Builtins:
    types = _read("types.yaml", store)
    sysv = _read("sysvars.yaml", store)
    funcs = _read("functions.yaml", store)
    basis = types.get("basis", {})
    sysvars: dict[str, SysVarInfo] = {}
    for key, info in sysv.items():
        name, dims = split_name(key)
        stops = info.get("stop", []) or []
        rng = info.get("range")
        if rng is not None and (len(rng) != 2 or not all(isinstance(x, (int, float)) for x in rng) or rng[0] > rng[1]):
            raise ValueError(f"sysvars.yaml: {key}: range must be [lo, hi]")
        sysvars[name.upper()] = SysVarInfo(name, info["type"], dims, info.get("access", "RW"),
                                           "read" in stops, "write" in stops, bool(info.get("cyclic")),
                                           tuple(rng) if rng is not None else None, bool(info.get("safety")),
                                           bool(info.get("fieldbus")), str(info.get("source", "")))
    routines: dict[str, SignatureInfo] = {}
    for text in funcs.get("functions", []):
        sig = parse_signature(text, True)
        routines[sig.name] = sig
    for text in funcs.get("procedures", []):
        sig = parse_signature(text, False)
        routines[sig.name] = sig
    for names in (funcs.get("lenient") or {}).values():
        for name in names:
            routines.setdefault(str(name).upper(), SignatureInfo(str(name).upper(), "ANY", [], True))
    kss = _read("kss.yaml", store)
    sources: dict[str, str] = {}
    kss_structs: dict[str, str] = {}
    kss_enums: dict[str, list[str]] = {}
    for key, info in (kss.get("types") or {}).items():
        if "struc" in info:
            kss_structs[info["name"]] = info["struc"]
        else:
            kss_enums[info["name"]] = [str(v) for v in info["enum"]]
        sources[key] = info["source"]
    kss_variables: dict[str, SysVarInfo] = {}
    for key, info in (kss.get("variables") or {}).items():
        name, dims = split_name(info["name"])
        if name.upper() not in sysvars:
            tname, tdims = split_name(info["type"])
            kss_variables[name.upper()] = SysVarInfo(name, tname, dims + tdims,
                                                     "RO" if info.get("const") else "RW")
            sources.setdefault(key, info["source"])
    for key, info in (kss.get("routines") or {}).items():
        if key not in routines:
            routines[key] = parse_signature(info["signature"], bool(info["function"]))
            sources.setdefault(key, info["source"])
    packages = {k: (v["package"], v["source"]) for k, v in (kss.get("packages") or {}).items()}
    package_routines = {k: (v["package"], v["source"]) for k, v in (kss.get("package_routines") or {}).items()}
    programs = {k: v["source"] for k, v in (kss.get("programs") or {}).items()}
    options = types.get("options", {}) or {}
    bvars = {}
    for key, tname in list((basis.get("variables") or {}).items()) + list((options.get("variables") or {}).items()):
        name, dims = split_name(key)
        bvars[name] = (tname, dims)
    return Builtins(
        simple=list(types.get("simple", [])),
        cartesian=list(types.get("geometric", {}).get("cartesian", [])),
        axis=list(types.get("geometric", {}).get("axis", [])),
        structs=dict(types.get("structs", {})),
        enums={k: list(v) for k, v in (types.get("enums") or {}).items()},
        basis_structs={**dict(basis.get("structs", {})), **dict(options.get("structs", {}) or {})},
        basis_enums={k: list(v) for k, v in {**(basis.get("enums") or {}),
                                              **(options.get("enums") or {})}.items()},
        basis_variables=bvars,
        sysvars=sysvars,
        routines=routines,
        exact=frozenset(str(n).upper() for n in types.get("exact", [])),
        kss_structs=kss_structs,
        kss_variables=kss_variables,
        kss_enums=kss_enums,
        sources=sources,
        packages=packages,
        package_routines=package_routines,
        programs=programs,
        advance_stop=frozenset(str(n).upper() for n in funcs.get("advance_stop") or ()),
        basis_routines=frozenset(str(n).upper() for n in funcs.get("basis") or ()),
    )
