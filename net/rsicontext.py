"""RSI contexts of both generations and their ETHERNET configuration, read onto one model
(docs/network.md "RobotSensorInterface").

A context is a signal flow: objects (type, id, parameters) whose inputs are linked to other
objects' outputs. Two file forms carry it:

* **RSI 3** (KSS 8.2/8.3, RSI Visual): ``NAME.rsi.xml``, root ``RSIObjects``, each object an
  ``RSIObject ObjType=".." ObjID=".."`` with ``Parameters/Parameter Name ParamValue`` and
  ``Inputs/Input InIdx OutObjID OutIdx``; indices count from 1. ``NAME.rsi`` (RSI Visual's own
  model) and ``NAME.rsi.diagram`` (its layout) are the editor's and are not read.
* **RSI 4/5** (KSS 8.5 and later, WorkVisual): ``NAME.rsix``, root ``RsiContext``, the objects
  in ``RsiObjects/RsiObject ObjType=".." ObjId=".."`` with ``Input InIdx OutObjId OutIdx``;
  indices count from 0 (WorkVisual's links name port ``Out1`` where the object says
  ``OutIdx="0"``: ROS-Industrial's ``RSI_Ethernet.rsix``). The editor's sections (``Editor``,
  ``BlueprintCollections``) are not read. Object types are written in mixed case
  (``AxisCorr``); the model keeps them upper case (``AXISCORR``), as RSI 3 writes them.

Both map onto :class:`Context` with 1-based indices, so index n of an ETHERNET object is the
configuration's ``INDX="n"`` in either generation (kroshu's SDK ships the same context in both:
RSI 3 ``OutIdx="2"`` and RSI 4 ``OutIdx="1"`` both take ``AK.A1`` of ``INDX="2"``).

The ETHERNET object's ``ConfigFile`` is KUKA's ``ROOT`` document (the template
``RSI_EthernetConfig.xml`` as KUKA ships it): ``CONFIG`` (``IP_NUMBER``, ``PORT``,
``SENTYPE``, ``ONLYSEND``; RSI 2's also ``PROTOCOL`` UDP or TCP), ``SEND/ELEMENTS`` and ``RECEIVE/ELEMENTS`` of ``ELEMENT TAG TYPE
INDX [HOLDON]``. The template's own comments are the format's documentation: TYPE is one of
``BOOL``, ``STRING``, ``LONG``, ``DOUBLE``; ``INDX="INTERNAL"`` switches on the controller's
internal values (the ``DEF_`` elements, in SEND and in RECEIVE: ``DEF_EStr``,
``DEF_Tech.T2``), ``INDX="n"`` is channel n of the object (at most 64); ``HOLDON="1"`` keeps an
output at its last value; ``ONLYSEND TRUE``: the sensor does not answer.

A cell file may name the ETHERNET configuration alone (AlexeiOvcharov's ``Painter_RSI.xml`` is
published without its context): the context is then *implied* from its RECEIVE tags, each
object fed from the channels whose tags name it: ``AK``/``AKorr`` ``.A1``..``.A6`` an AXISCORR,
``RKorr`` ``.X``..``.C`` a POSCORR, ``Stop`` a STOP (the names KUKA's examples and ROS-Industrial's,
FZI's, kroshu's contexts link that way), Timeout 100.

Errors are :class:`RsiConfigError` naming the file and the element.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from krl.limits import MAX_NET_CONFIG_BYTES, MAX_RSI_CONTEXT_NODES, MAX_RSI_OBJECTS

from .cellkey import LOOPBACK
from .xmlsafe import XmlRefused, local, parse

TYPES = ("BOOL", "STRING", "LONG", "DOUBLE")      # the template's "RSI Data: TYPE=" comment
MAX_CHANNELS = 64                                 # "Maximum of RSI Channels: 64"
RSI3, RSI45, IMPLIED = "RSI 3", "RSI 4/5", "implied"
AXES = ("A1", "A2", "A3", "A4", "A5", "A6")
CART = ("X", "Y", "Z", "A", "B", "C")


class RsiConfigError(ValueError):
    """A context or ETHERNET configuration outside the format; the message names the file and
    the element."""


@dataclass
class RsiObject:
    """One object of the signal flow. `inputs`: input index -> (object id, output index), both
    counted from 1."""

    type: str
    id: str
    params: dict[str, str] = field(default_factory=dict)
    inputs: dict[int, tuple[str, int]] = field(default_factory=dict)

    def param_name(self, name: str) -> str | None:
        """The parameter's name as the context writes it (names compare without case)."""
        if name in self.params:
            return name
        low = name.lower()
        for k in self.params:
            if k.lower() == low:
                return k
        return None

    def param(self, name: str, default: float) -> float:
        k = self.param_name(name)
        if k is None:
            return default
        try:
            return float(self.params[k])
        except ValueError:
            return default


@dataclass
class Element:
    """An ELEMENT of SEND or RECEIVE: TAG (``EL`` or ``EL.ATTR``), TYPE, INDX (None for
    INTERNAL), HOLDON."""

    tag: str
    type: str
    indx: int | None
    holdon: bool = False

    @property
    def internal(self) -> bool:
        return self.indx is None


@dataclass
class EthernetConfig:
    path: Path | None
    ip: str
    port: int
    sentype: str
    onlysend: bool
    send: list[Element]
    receive: list[Element]
    protocol: str = "UDP"        # RSI 2's CONFIG/PROTOCOL (KR C2 configurations): UDP or TCP


@dataclass
class Context:
    """An RSI context read from its files (either generation)."""

    name: str
    generation: str
    path: Path | None
    objects: dict[str, RsiObject]
    ethernet_id: str
    ethernet: EthernetConfig

    def of_type(self, t: str) -> list[RsiObject]:
        return [o for o in self.objects.values() if o.type == t]

    def obj(self, ident: str) -> RsiObject | None:
        """The object of id `ident` (ids compare without case, as KRL names do)."""
        o = self.objects.get(ident)
        if o is not None:
            return o
        low = ident.lower()
        for k, v in self.objects.items():
            if k.lower() == low:
                return v
        return None

    @property
    def eth(self) -> RsiObject:
        return self.objects[self.ethernet_id]

    # the fields net/rsi.py reads
    @property
    def ip(self) -> str:
        return self.ethernet.ip

    @property
    def port(self) -> int:
        return self.ethernet.port


def _read(path: Path, what: str) -> bytes:
    try:
        with open(path, "rb") as fh:
            return fh.read(MAX_NET_CONFIG_BYTES + 1)
    except OSError as exc:
        raise RsiConfigError(f"{what}: {path}: {exc.strerror or 'cannot read'}") from None


def _parse(path: Path, what: str, nodes: int):
    try:
        return parse(_read(path, what), MAX_NET_CONFIG_BYTES, f"{what} {path.name}", nodes)
    except XmlRefused as exc:
        raise RsiConfigError(str(exc)) from None


def load_context(path: Path, name: str, ethernet: Path | None = None, folders=()) -> Context:
    """The context in the file `path` (``.rsi.xml``, ``.rsix``, or an ETHERNET configuration
    alone) and its ETHERNET configuration: `ethernet` when given, else the object's
    ``ConfigFile`` found by :func:`find_config` (beside the context, in `folders`, in a folder
    beside the context's). Raises :class:`RsiConfigError`."""
    path = Path(path)
    if path.name.lower().endswith(".rsi") and path.with_name(path.name + ".xml").is_file():
        path = path.with_name(path.name + ".xml")          # NAME.rsi names the context NAME.rsi.xml
    if path.name.lower().endswith(".rsi") or path.name.lower().endswith(".rsi.diagram"):
        raise RsiConfigError(f"RSI context {path.name}: RSI Visual's editor file; the controller reads "
                             f"{path.name.split('.')[0]}.rsi.xml (RSI 3) or .rsix (RSI 4/5)")
    root = _parse(path, "RSI context", MAX_RSI_CONTEXT_NODES)
    kind = local(root.tag)
    if kind.upper() == "ROOT":
        cfg = read_ethernet(path, root)
        return implied_context(name, cfg)
    if kind == "RSIObjects":
        generation, objs = RSI3, [e for e in root if local(e.tag) == "RSIObject"]
    elif kind == "RsiContext":
        holders = [c for c in root if local(c.tag) == "RsiObjects"]
        if len(holders) != 1:
            raise RsiConfigError(f"RSI context {path.name}: RsiContext without one RsiObjects section")
        generation, objs = RSI45, [e for e in holders[0] if local(e.tag) == "RsiObject"]
    else:
        raise RsiConfigError(f"RSI context {path.name}: root element <{kind[:40]}> is neither RSIObjects "
                             "(RSI 3 .rsi.xml), RsiContext (RSI 4/5 .rsix) nor an ETHERNET configuration <ROOT>")
    if len(objs) > MAX_RSI_OBJECTS:
        raise RsiConfigError(f"RSI context {path.name}: {len(objs)} objects, more than {MAX_RSI_OBJECTS}")
    objects: dict[str, RsiObject] = {}
    base = 1 if generation == RSI45 else 0      # RSI 4/5 counts from 0
    for el in objs:
        o = _object(el, path, base, generation)
        if o.id.lower() in (k.lower() for k in objects):
            raise RsiConfigError(f"RSI context {path.name}: object id {o.id!r} twice")
        objects[o.id] = o
    eth = [o for o in objects.values() if o.type == "ETHERNET"]
    if len(eth) != 1:
        raise RsiConfigError(f"RSI context {path.name} ({generation}): {len(eth)} ETHERNET objects (one is simulated)")
    eo = eth[0]
    if ethernet is None:
        k = eo.param_name("ConfigFile")
        cfg_name = eo.params.get(k, "") if k else ""
        if not cfg_name or "/" in cfg_name or "\\" in cfg_name or ".." in cfg_name:
            raise RsiConfigError(f"RSI context {path.name}: ETHERNET {eo.id} ConfigFile {cfg_name[:60]!r} is not a file name")
        ethernet = find_config(cfg_name, path, folders)
        if ethernet is None:
            raise RsiConfigError(f"RSI context {path.name}: ETHERNET {eo.id} ConfigFile {cfg_name} not found beside "
                                 "the context, beside the program, in the backup's SensorInterface folder or in a "
                                 "folder beside the context's (the cell file's rsi: ethernet: names it)")
    cfg = read_ethernet(ethernet)
    for o in objects.values():
        for i, (src, oi) in o.inputs.items():
            if src.lower() not in (k.lower() for k in objects):
                raise RsiConfigError(f"RSI context {path.name}: object {o.id} input {i} is linked to "
                                     f"{src[:40]!r}, which is no object of the context")
    return Context(name, generation, path, objects, eo.id, cfg)


def _object(el, path: Path, base: int, generation: str) -> RsiObject:
    id_attr, out_attr = ("ObjID", "OutObjID") if generation == RSI3 else ("ObjId", "OutObjId")
    ident = str(el.get(id_attr) or el.get("ObjID") or el.get("ObjId") or "")
    typ = str(el.get("ObjType", "")).upper()
    if not ident or not typ:
        raise RsiConfigError(f"RSI context {path.name}: an object without ObjType and {id_attr}")
    o = RsiObject(typ, ident)
    for sec in el:
        tag = local(sec.tag)
        for p in sec:
            pt = local(p.tag)
            if tag == "Parameters" and pt == "Parameter" and p.get("Name"):
                o.params[str(p.get("Name"))] = str(p.get("ParamValue", ""))
            elif tag == "Inputs" and pt == "Input":
                try:
                    i = int(p.get("InIdx", "")) + base
                    oi = int(p.get("OutIdx", "")) + base
                except ValueError:
                    raise RsiConfigError(f"RSI context {path.name}: object {ident}: an Input without "
                                         "numbers in InIdx and OutIdx") from None
                src = p.get(out_attr) or p.get("OutObjID") or p.get("OutObjId") or ""
                o.inputs[i] = (str(src), oi)
    return o


MAX_SIBLING_FOLDERS = 64


def find_config(name: str, context: Path, folders=()) -> Path | None:
    """Where the ETHERNET object's ``ConfigFile`` `name` is: beside the context, in `folders`
    (the program's, the backup's SensorInterface), then in a folder beside the context's
    (published repositories keep it in a sibling: FZI's ``krl/Common``, iiQKA's
    ``RobotSensorInterface/Ethernet configuration``; at most 64 folders looked at). Names
    compare without case, as on the controller's file system."""
    tried = [context.parent, *folders]
    up = context.parent.parent
    if up.is_dir():
        tried += sorted(p for p in up.iterdir() if p.is_dir() and p != context.parent)[:MAX_SIBLING_FOLDERS]
    for f in tried:
        p = _beside(f, name)
        if p.is_file():
            return p
    return None


def _beside(folder: Path, name: str) -> Path:
    p = folder / name
    if p.exists():
        return p
    for q in folder.iterdir() if folder.is_dir() else ():
        if q.name.lower() == name.lower():
            return q
    return p


def _child(el, name: str):
    for c in el:
        if local(c.tag).upper() == name:
            return c
    return None


def _text(el, name: str) -> str | None:
    if el is None:
        return None
    c = _child(el, name)
    return c.text.strip() if c is not None and c.text and c.text.strip() else None


def read_ethernet(path: Path, root=None) -> EthernetConfig:
    """KUKA's ETHERNET configuration (``ROOT``: ``CONFIG``, ``SEND``, ``RECEIVE``) in `path`.
    Raises :class:`RsiConfigError` naming the file and the element outside the format."""
    path = Path(path)
    name = path.name
    if root is None:
        root = _parse(path, "RSI ETHERNET configuration", MAX_RSI_CONTEXT_NODES)
    if local(root.tag).upper() != "ROOT":
        raise RsiConfigError(f"RSI {name}: root element <{local(root.tag)[:40]}>, not <ROOT> of an ETHERNET configuration")
    conf = _child(root, "CONFIG")
    if conf is None:
        raise RsiConfigError(f"RSI {name}: no CONFIG element")
    port_text = _text(conf, "PORT")
    try:
        port = int(port_text or "")
    except ValueError:
        raise RsiConfigError(f"RSI {name}: CONFIG/PORT {str(port_text)[:20]!r} is not a number") from None
    if not 0 < port <= 65535:
        raise RsiConfigError(f"RSI {name}: CONFIG/PORT {port} outside 1..65535")
    only = (_text(conf, "ONLYSEND") or "FALSE").upper()
    if only not in ("TRUE", "FALSE"):
        raise RsiConfigError(f"RSI {name}: CONFIG/ONLYSEND {only[:20]!r} is neither TRUE nor FALSE")
    protocol = (_text(conf, "PROTOCOL") or "UDP").upper()
    if protocol not in ("UDP", "TCP"):
        raise RsiConfigError(f"RSI {name}: CONFIG/PROTOCOL {protocol[:20]!r} is neither UDP nor TCP")
    send = _elements(root, "SEND", name)
    receive = _elements(root, "RECEIVE", name)
    return EthernetConfig(path, _text(conf, "IP_NUMBER") or LOOPBACK, port, _text(conf, "SENTYPE") or "ImFree",
                          only == "TRUE", send, receive, protocol)


def _elements(root, section: str, name: str) -> list[Element]:
    s = _child(root, section)
    if s is None:
        return []
    holder = _child(s, "ELEMENTS")
    out = []
    for e in (holder if holder is not None else ()):
        if local(e.tag).upper() != "ELEMENT":
            continue
        tag = str(e.get("TAG", "")).strip()
        where = f"RSI {name}: {section} element {tag[:40]!r}"
        if not tag:
            raise RsiConfigError(f"RSI {name}: {section} element without TAG")
        typ = str(e.get("TYPE", "DOUBLE")).strip().upper()
        if typ not in TYPES:
            raise RsiConfigError(f"{where}: TYPE {typ[:20]!r} is not one of {', '.join(TYPES)}")
        indx_text = str(e.get("INDX", "")).strip()
        if indx_text.upper() == "INTERNAL":
            indx = None
        else:
            try:
                indx = int(indx_text)
            except ValueError:
                raise RsiConfigError(f"{where}: INDX {indx_text[:20]!r} is neither INTERNAL nor a channel number") from None
            if not 1 <= indx <= MAX_CHANNELS:
                raise RsiConfigError(f"{where}: INDX {indx} outside 1..{MAX_CHANNELS}")
        hold = str(e.get("HOLDON", "0")).strip()
        if hold not in ("0", "1"):
            raise RsiConfigError(f"{where}: HOLDON {hold[:20]!r} is neither 0 nor 1")
        out.append(Element(tag, typ, indx, hold == "1"))
    return out


_IMPLIED = (("AXISCORR", "AXISCORR1", ("AK", "AKORR"), AXES),
            ("POSCORR", "POSCORR1", ("RK", "RKORR"), CART))


def implied_context(name: str, cfg: EthernetConfig) -> Context:
    """The context an ETHERNET configuration alone implies (module docstring)."""
    eth = RsiObject("ETHERNET", "ETHERNET1", {"ConfigFile": cfg.path.name if cfg.path else "", "Timeout": "100"})
    objects = {eth.id: eth}
    for typ, ident, prefixes, comps in _IMPLIED:
        obj = RsiObject(typ, ident)
        for el in cfg.receive:
            head, _, comp = el.tag.partition(".")
            if el.indx is not None and head.upper() in prefixes and comp.upper() in comps:
                obj.inputs[comps.index(comp.upper()) + 1] = (eth.id, el.indx)
        if obj.inputs:
            objects[ident] = obj
    for el in cfg.receive:
        if el.indx is not None and el.tag.upper() == "STOP":
            objects["STOP1"] = RsiObject("STOP", "STOP1", inputs={1: (eth.id, el.indx)})
    return Context(name, IMPLIED, cfg.path, objects, eth.id, cfg)


def is_ethernet_config(path: Path) -> bool:
    """True when `path` is an ETHERNET configuration (root ``ROOT``), not a context."""
    try:
        return local(_parse(Path(path), "RSI configuration", MAX_RSI_CONTEXT_NODES).tag).upper() == "ROOT"
    except RsiConfigError:
        return False


def find_context(name: str, program: Path | None, backup: Path | None) -> Path | None:
    """Where the controller keeps the context `name` of ``RSI_CREATE``: ``NAME.rsi.xml`` (RSI 3)
    or ``NAME.rsix`` (RSI 4/5), for a name with or without ``.rsi``, in the backup's
    ``Config/User/Common/SensorInterface`` (KSS 8.5+ also ``RobotSensorInterface/Context``),
    then beside the program. None when there is none."""
    stem = name[:-4] if name.lower().endswith(".rsi") else name
    if name.lower().endswith((".xml", ".rsix")):
        want = [name.upper()]
    else:
        want = [(stem + ".rsi.xml").upper(), (stem + ".rsix").upper(), (stem + ".xml").upper()]
    folders = []
    if backup is not None:
        for top in (backup, backup / "KRC"):
            folders += [top / "Config" / "User" / "Common" / "SensorInterface",
                        top / "Config" / "RobotSensorInterface" / "Context"]
    if program is not None:
        folders.append(program.parent)
    for f in folders:
        if f.is_dir():
            found = {p.name.upper(): p for p in sorted(f.iterdir()) if p.is_file()}
            for w in want:
                if w in found:
                    return found[w]
    return None
