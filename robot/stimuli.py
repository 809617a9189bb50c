"""Stimuli: simulated input changes read from a YAML file (issue 5, "Execution").

Format (a list, or a mapping with a ``stimuli`` list)::

    stimuli:
      - at: 1.5                       # simulated time, s
        set: {"$IN[3]": true}
      - when: {motion: 2, phase: end} # motion = the n-th motion enqueued (1-based) ...
        set: {"$IN[5]": true}
        delay: 0.1                    # optional, s after the condition
      - when: {line: 12, reached: 2.0}  # ... or the motion statement on source line 12;
        set: {"$ANIN[1]": 0.5}          # reached: TCP within 2 mm of its programmed point

A signal is ``$IN[n]`` or ``$ANIN[n]``, or the name of a ``SIGNAL`` declared on them in
``$config.dat`` or the program's data list (``SIGNAL PART_OK $IN[3]``; a group ``SIGNAL CODE
$IN[1] TO $IN[4]`` takes an INT, bit 0 on the first input). The run resolves the names before
it starts (:func:`resolve_signals`).

A *cell file* is a stimuli file with reactive rules and presets beside (issue 22)::

    robot: kr180_r3200_pa                # a robot of robot/data, by name (optional)
    sim_time: {Mill_FrameAut3: 180}      # s a program of the cell needs to reach its end (optional)
    presets: {autoext: true, pgno: 2}    # robot/cellpresets.py
    rules:                               # robot/cellrules.py: rising edge, `after` s later
      - when: "$OUT[3] AND NOT PART_OK"
        after: 0.2
        set: {PART_OK: true}

``start`` says where the robot stands when the run begins: a point of the program (``XHOME``)
or an axis literal (``"{A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}"``, or the same as a mapping
``{A1: 0, A2: -90, ...}``); ``krl run --start`` overrides it (interp/run.py ``start_axes``).
``robot`` names the robot the cell holds, when the backup has no machine data of its own: one
of the project's robot library (robot/machine.py ``library_robots``; a name, never a path, as
the file is untrusted). ``krl run --robot`` overrides it; it overrides the backup's machine data.
``network`` names the partners the run connects (EKI channels, RSI, the PLC's Modbus TCP and
OPC UA servers, KukaVarProxy; net/settings.py, docs/network.md).
``sim_time`` maps a program's name to the simulated time (s, at most
:data:`~krl.limits.MAX_CELL_SIM_TIME_S`) it needs to reach its end, for a long job: the
real-programs report runs it that long when that is longer than its own limit.

The file is validated against this schema: a top-level mapping holds only ``stimuli``,
``rules``, ``presets``, ``robot``, ``sim_time``, ``start``; a stimulus only ``at``, ``when``, ``set``, ``delay``; ``when`` only
``motion``, ``line``, ``phase``, ``reached``; a rule only ``when`` (KRL text), ``after``, ``set``;
``presets`` only ``pgno``, ``autoext``. Anything else is a :class:`StimulusError` that names the
key and the place (``file:line``). Limits: at most :data:`MAX_STIMULI` stimuli,
:data:`MAX_CELL_RULES` rules, :data:`MAX_STIMULI_BYTES` bytes.

``phase`` is one of start, blend_start, blend_end, end. ``reached`` (mm) fires in the
first IPO cycle in which that motion is being executed and the TCP is within the given
distance of the motion's programmed end point (default ``$IN_POS_CAR`` = 0.1 mm when
``reached: true``). Values: BOOL for ``$IN``, REAL for ``$ANIN``. Each stimulus fires once.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from krl.ast import nodes as N
from krl.ast.build import build_expression
from krl.limits import (
    MAX_CELL_RULES, MAX_CELL_SIM_TIME_S, MAX_RULE_TOKENS, MAX_START_CHARS, MAX_STIMULI, MAX_STIMULI_BYTES,
)
from krl.syntax.parse import default_bundle, parse_expression

from .cellrules import ConditionError, Rule, compile_condition, parse_condition, signal_of
from .machine import library_robots
from .catalogue import find
from net.settings import SettingsError, parse_network

PHASES = ("start", "blend_start", "blend_end", "end")
TOP_KEYS = ("stimuli", "rules", "presets", "robot", "sim_time", "start", "network", "geometry", "tool", "floor")
PRESET_KEYS = ("pgno", "autoext")
RULE_KEYS = ("when", "after", "set")
STIMULUS_KEYS = ("at", "when", "set", "delay")
WHEN_KEYS = ("motion", "line", "phase", "reached")
_NAME = re.compile(r"[A-Za-z_$][A-Za-z0-9_$]{0,23}\Z")   # a KRL name (reference §2: 24 characters)


class StimulusError(ValueError):
    """Malformed stimuli file; the message names the file:line and the key when known."""


@dataclass
class Stimulus:
    """One input change. Exactly one of ``at`` or a motion condition is set.

    Attributes:
        set: signal name -> value (``$IN[n]``/``$ANIN[n]``, or a SIGNAL name until
            :func:`resolve_signals` replaces it).
        at: time in s, or None.
        motion: motion id (n-th enqueued motion), or None. line: source line, or None.
        phase: motion phase, or None. reached_mm: distance for "TCP reaches the point";
        ``reached: true`` takes the robot's in-position distance ``$IN_POS_CAR``
        (``reached_default``; the controller of the run sets it from its machine data).
        delay: extra delay in s after the condition holds.
        where: ``file:line`` of the stimulus in its file ("" when built from data).
        source: the ``source`` of its I/O events (``stimulus``; ``auto`` for an answer of
            ``--inputs auto``, interp/runtime/autocell.py); on_fire: called with the time
            when it takes effect.
    """

    set: dict[str, Any]
    at: float | None = None
    motion: int | None = None
    line: int | None = None
    phase: str | None = None
    reached_mm: float | None = None
    reached_default: bool = False
    delay: float = 0.0
    fired: bool = False
    due: float | None = field(default=None, repr=False)
    where: str = field(default="", repr=False)
    source: str = field(default="stimulus", repr=False)   # the I/O events' source (auto: --inputs auto)
    on_fire: Callable[[float], None] | None = field(default=None, repr=False, compare=False)

    def matches_motion(self, motion_id: int, line: int | None) -> bool:
        if self.motion is not None:
            return self.motion == motion_id
        return self.line is not None and line is not None and self.line == line


# ------------------------------------------------------------------ YAML with line numbers
class _Map(dict):
    """A YAML mapping that remembers its line and the line of each key (1-based)."""

    line: int = 0
    key_lines: dict


class _Loader(yaml.SafeLoader):
    pass


def _construct_map(loader: _Loader, node: yaml.MappingNode):
    data = _Map()
    data.line = node.start_mark.line + 1
    data.key_lines = {}
    yield data
    data.update(loader.construct_mapping(node))
    for key_node, _ in node.value:
        try:
            data.key_lines[loader.construct_object(key_node)] = key_node.start_mark.line + 1
        except TypeError:   # an unhashable key: construct_mapping has complained already
            pass


_Loader.add_constructor("tag:yaml.org,2002:map", _construct_map)


class _Where:
    def __init__(self, source: str) -> None:
        self.source = source

    def __call__(self, obj: Any = None, key: Any = None) -> str:
        line = 0
        if isinstance(obj, _Map):
            line = obj.key_lines.get(key, obj.line) if key is not None else obj.line
        if self.source and line:
            return f"{self.source}:{line}"
        return self.source or "stimuli"


def _number(value: Any, what: str, where: str, *, integer: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise StimulusError(f"{where}: {what} must be a number, not {value!r}")
    if integer and not isinstance(value, int):
        raise StimulusError(f"{where}: {what} must be a whole number, not {value!r}")
    if not math.isfinite(value):
        raise StimulusError(f"{where}: {what} must be finite, not {value!r}")
    return value


def _unknown(obj: dict, allowed: tuple[str, ...], what: str, where: _Where) -> None:
    for key in obj:
        if key not in allowed:
            raise StimulusError(f"{where(obj, key)}: unknown {what} {key!r} "
                                f"(allowed: {', '.join(allowed)})")


def _signal_name(name: Any, where: str) -> str:
    """``$IN[n]``/``$ANIN[n]`` in canonical form, or a SIGNAL name (upper case)."""
    if not isinstance(name, str):
        raise StimulusError(f"{where}: signal name must be text, not {name!r}")
    s = name.strip().upper().replace(" ", "")
    if "[" in s:
        try:
            base, n = signal_of(name)
        except ConditionError as exc:
            raise StimulusError(f"{where}: not a signal: {name!r} ({exc})") from None
        if base not in ("$IN", "$ANIN"):
            raise StimulusError(f"{where}: only $IN/$ANIN can be stimulated, not {name}")
        return f"{base}[{n}]"
    if not _NAME.match(s):
        raise StimulusError(f"{where}: not a signal name: {name!r}")
    return s


def _parse_set(mapping: dict, where: _Where) -> dict[str, Any]:
    """The ``set:`` mapping of a stimulus or rule: signal -> value (BOOL/INT for ``$IN`` and
    SIGNAL names, REAL for ``$ANIN``)."""
    sets: dict[str, Any] = {}
    for name, v in mapping.items():
        at = where(mapping, name)
        key = _signal_name(name, at)
        if isinstance(v, bool) or key.startswith("$ANIN"):
            if key.startswith("$ANIN"):
                v = _number(v, f"value of {key}", at)
        else:
            v = int(_number(v, f"value of {key}", at, integer=True))
        sets[key] = v
    return sets


@dataclass
class Cell:
    """A stimuli file: its timed/motion stimuli and its reactive rules (robot/cellrules.py)."""

    stimuli: list[Stimulus] = field(default_factory=list)
    rules: list[Rule] = field(default_factory=list)
    pgno: int | None = None        # presets: the program number the PLC answers (robot/cellpresets.py)
    autoext: bool = False          # presets: Automatic External (operating mode EXT)
    robot: Path | None = None      # the robot of the project's library the cell names
    sim_time: dict[str, float] = field(default_factory=dict)   # PROGRAM (upper case) -> s it needs
    start: str | None = None       # where the robot stands at the start (interp/run.py start_axes)
    network: Any = None            # net.settings.NetworkSettings: the partners (`network:`, docs/network.md)
    geometry: Any = None           # robot/collision.py CellGeometry: `geometry:`, `tool:`, `floor:` (issue 64)


def _parse_rules(doc: Any, where: _Where, key_where: str) -> list[Rule]:
    if doc is None:
        return []
    if not isinstance(doc, list):
        raise StimulusError(f"{key_where}: 'rules' must be a list of rules (when, after, set)")
    if len(doc) > MAX_CELL_RULES:
        raise StimulusError(f"{key_where}: {len(doc)} rules, more than the limit of {MAX_CELL_RULES}")
    out = []
    for i, item in enumerate(doc):
        if not isinstance(item, dict):
            raise StimulusError(f"{key_where}: rule {i + 1} must be a mapping (when, after, set)")
        here = where(item)
        _unknown(item, RULE_KEYS, f"field of rule {i + 1}:", where)
        if "when" not in item:
            raise StimulusError(f"{here}: rule {i + 1} needs 'when' (a KRL condition)")
        if not isinstance(item.get("set"), dict) or not item["set"]:
            raise StimulusError(f"{here}: rule {i + 1} needs a 'set' mapping of signals")
        text = item["when"]
        wat = where(item, "when")
        if isinstance(text, bool):
            text = "TRUE" if text else "FALSE"
        if not isinstance(text, str):
            raise StimulusError(f"{wat}: 'when' must be KRL text, not {text!r}")
        try:
            expr = parse_condition(text)
        except ConditionError as exc:
            col = f" (column {exc.column} of the condition)" if exc.column else ""
            raise StimulusError(f"{wat}: {exc}{col}") from None
        after = float(_number(item.get("after", 0.0), "after", where(item, "after")))
        if after < 0:
            raise StimulusError(f"{where(item, 'after')}: after must not be negative")
        out.append(Rule(when=expr, text=text, set=_parse_set(item["set"], where), after=after, where=here))
    return out


def parse_cell(doc: Any, default_reach_mm: float = 0.1, source: str = "") -> Cell:
    """Build a :class:`Cell` from a parsed YAML document: a list of stimuli, or a mapping with
    ``stimuli`` and/or ``rules``.

    `source` is the file name used in messages. Raises :class:`StimulusError` for a key
    outside the schema, a missing ``set``/``at``-or-``when``, a value of the wrong type, a rule
    condition outside the subset of robot/cellrules.py, or more than :data:`MAX_STIMULI`
    stimuli or :data:`MAX_CELL_RULES` rules.
    """
    where = _Where(source)
    if doc is None:
        return Cell()
    rules: list[Rule] = []
    if isinstance(doc, dict):
        _unknown(doc, TOP_KEYS, "top-level key", where)
        if not any(k in doc for k in TOP_KEYS):
            raise StimulusError(f"{where(doc)}: the mapping needs one of " + ", ".join(f"'{k}'" for k in TOP_KEYS))
        cell = Cell([], _parse_rules(doc.get("rules"), where, where(doc, "rules")))
        _parse_presets(doc.get("presets"), cell, where, where(doc, "presets"))
        if "robot" in doc:
            cell.robot = _library_robot(doc["robot"], where(doc, "robot"), Path(source).parent if source else None)
        if "sim_time" in doc:
            cell.sim_time = _sim_times(doc["sim_time"], where, where(doc, "sim_time"))
        if "start" in doc:
            cell.start = _start(doc["start"], where(doc, "start"))
        if doc.get("stimuli") is not None:
            cell.stimuli = _parse_stimuli(doc["stimuli"], default_reach_mm, where)
        if any(doc.get(k) is not None for k in ("geometry", "tool", "floor")):
            # deferred: tools/startup_bench.py, krl run +4 ms at the top (2026-11-26)
            from .collision import GeometryError, parse_geometry  # noqa: PLC0415

            try:
                cell.geometry = parse_geometry(doc.get("geometry"), doc.get("tool"), doc.get("floor"),
                                               Path(source).parent if source else None)
            except GeometryError as exc:
                key = next(k for k in ("geometry", "tool", "floor") if doc.get(k) is not None)
                raise StimulusError(f"{where(doc, key)}: {exc}") from None
        if doc.get("network") is not None:

            try:
                cell.network = parse_network(doc["network"], Path(source).parent if source else Path("."))
            except SettingsError as exc:
                raise StimulusError(f"{where(doc, 'network')}: {exc}") from None
        return cell
    return Cell(_parse_stimuli(doc, default_reach_mm, where))


def _sim_times(doc: Any, where: _Where, at: str) -> dict[str, float]:
    if not isinstance(doc, dict):
        raise StimulusError(f"{at}: 'sim_time' must map program names to seconds")
    out = {}
    for name, value in doc.items():
        if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z_$][A-Za-z0-9_$]{0,23}", name):
            raise StimulusError(f"{at}: sim_time: {str(name)[:40]!r} is not a program name")
        s = float(_number(value, f"sim_time of {name}", where(doc, name)))
        if not 0 < s <= MAX_CELL_SIM_TIME_S:
            raise StimulusError(f"{where(doc, name)}: sim_time of {name} must be 0 < s <= {MAX_CELL_SIM_TIME_S:g}")
        out[name.upper()] = s
    return out


class StartError(ValueError):
    """A start position (``krl run --start``, a cell file's ``start:``) that cannot place the
    robot; the message names it and why."""


#: the components of an AXIS/E6AXIS and of a POS/E6POS start, in order
START_AXES = ("A1", "A2", "A3", "A4", "A5", "A6")
START_CART = ("X", "Y", "Z", "A", "B", "C")


def parse_start(text: str):
    """The AST of a start position: an AXIS/E6AXIS or POS/E6POS aggregate literal
    (``{A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}``, ``{X 500, Y 0, Z 800, A 0, B 90, C 0, S 2,
    T 35}``) or the name of a point (``XHOME``), parsed by the project's expression parser
    (one line, at most :data:`~krl.limits.MAX_RULE_TOKENS` tokens). Raises
    :class:`StartError` for anything else."""
    if not isinstance(text, str) or not text.strip():
        raise StartError("a start position is an E6AXIS literal or the name of a point, e.g. XHOME")
    if len(text) > MAX_START_CHARS:
        raise StartError(f"a start position is at most {MAX_START_CHARS} characters")
    bundle = default_bundle()
    parsed = parse_expression(text.strip(), MAX_RULE_TOKENS, bundle)
    expr = build_expression(parsed.tree, "<start>", bundle.symbolic) if parsed.error is None else None
    if isinstance(expr, N.Name):
        return expr
    if isinstance(expr, N.Aggregate):
        for it in expr.items:
            v = it.value
            if isinstance(v, N.Unary) and v.op in ("-", "+"):
                v = v.operand
            if not isinstance(v, (N.IntLit, N.RealLit)):
                raise StartError(f"start {text!r}: {it.name} must be a number")
        return expr
    raise StartError(f"start {text!r}: not an E6AXIS literal ({{A1 0, A2 -90, ...}}) or a point name")


def _start(value: Any, at: str) -> str:
    """The ``start:`` of a cell file: an E6AXIS literal or a point name, checked by the
    project's expression parser (:func:`parse_start`)."""
    if isinstance(value, dict):
        parts = []
        for k, v in value.items():
            if not isinstance(k, str) or isinstance(v, bool) or not isinstance(v, (int, float)):
                raise StimulusError(f"{at}: start: {str(k)[:24]!r} must map to a number")
            parts.append(f"{k} {v}")
        value = "{" + ", ".join(parts) + "}"
    if not isinstance(value, str) or len(value) > MAX_START_CHARS:
        raise StimulusError(f"{at}: start must be a point name (XHOME) or an E6AXIS literal "
                            f"(\"{{A1 0, A2 -90, A3 90, A4 0, A5 0, A6 0}}\")")
    try:
        parse_start(value)
    except StartError as exc:
        raise StimulusError(f"{at}: {exc}") from None
    return value


def _library_robot(name: Any, at: str, folder: Path | None = None) -> Path:
    """The robot a cell file names: one of the project's library (robot/data), a KUKA model of the
    catalogue (robot/catalogue.py: its name, resolved by robot/mada.py ``load_robot``), or a robot
    description (``.urdf``, ``.xacro``: robot/description.py) of the cell file's own folder tree —
    never a path elsewhere (a cell file is untrusted)."""
    robots = library_robots()
    if isinstance(name, str) and name in robots:
        return robots[name]

    if isinstance(name, str) and find(name) is not None:
        return Path(name)
    if isinstance(name, str) and folder is not None and name.lower().endswith((".urdf", ".xacro")):
        try:
            p = (folder / name).resolve(strict=True)
            if p.is_relative_to(folder.resolve()) and p.is_file():
                return p
        except OSError:
            pass
        raise StimulusError(f"{at}: robot {name[:60]!r}: a description of the cell file's own folder was expected")
    raise StimulusError(f"{at}: robot must name a robot of the project's library ({', '.join(robots)}), a KUKA "
                        f"model (`krl robot list`) or a .urdf/.xacro beside the cell file, not {str(name)[:60]!r}")


def _parse_presets(doc: Any, cell: Cell, where: _Where, key_where: str) -> None:
    if doc is None:
        return
    if not isinstance(doc, dict):
        raise StimulusError(f"{key_where}: 'presets' must be a mapping ({', '.join(PRESET_KEYS)})")
    _unknown(doc, PRESET_KEYS, "preset", where)
    if "pgno" in doc and doc["pgno"] is not None:
        n = int(_number(doc["pgno"], "pgno", where(doc, "pgno"), integer=True))
        if not 0 < n < 1 << 16:
            raise StimulusError(f"{where(doc, 'pgno')}: pgno must be 1..65535")
        cell.pgno = n
    if "autoext" in doc:
        if not isinstance(doc["autoext"], bool):
            raise StimulusError(f"{where(doc, 'autoext')}: autoext must be true or false")
        cell.autoext = doc["autoext"]


def parse_stimuli(doc: Any, default_reach_mm: float = 0.1, source: str = "") -> list[Stimulus]:
    """The stimuli of a parsed YAML document (:func:`parse_cell` without the rules)."""
    return parse_cell(doc, default_reach_mm, source).stimuli


def _parse_stimuli(doc: Any, default_reach_mm: float, where: _Where) -> list[Stimulus]:
    if not isinstance(doc, list):
        raise StimulusError(f"{where()}: 'stimuli' must be a list of stimuli")
    if len(doc) > MAX_STIMULI:
        raise StimulusError(f"{where()}: {len(doc)} stimuli, more than the limit of {MAX_STIMULI}")
    out: list[Stimulus] = []
    for i, item in enumerate(doc):
        if not isinstance(item, dict):
            raise StimulusError(f"{where()}: stimulus {i + 1} must be a mapping with 'set'")
        here = where(item)
        _unknown(item, STIMULUS_KEYS, f"field of stimulus {i + 1}:", where)
        if not isinstance(item.get("set"), dict) or not item["set"]:
            raise StimulusError(f"{here}: stimulus {i + 1} needs a 'set' mapping of signals")
        sets = _parse_set(item["set"], where)
        st = Stimulus(set=sets, delay=float(_number(item.get("delay", 0.0), "delay", where(item, "delay"))),
                      where=here)
        if st.delay < 0:
            raise StimulusError(f"{where(item, 'delay')}: delay must not be negative")
        if "at" in item and "when" in item:
            raise StimulusError(f"{here}: stimulus {i + 1} has both 'at' and 'when'; give one")
        if "at" in item:
            st.at = float(_number(item["at"], "at", where(item, "at")))
        elif "when" in item:
            w = item["when"]
            if not isinstance(w, dict):
                raise StimulusError(f"{where(item, 'when')}: 'when' must be a mapping "
                                    f"({', '.join(WHEN_KEYS)})")
            _unknown(w, WHEN_KEYS, "field of 'when':", where)
            st.motion = int(_number(w["motion"], "motion", where(w, "motion"), integer=True)) \
                if "motion" in w else None
            st.line = int(_number(w["line"], "line", where(w, "line"), integer=True)) if "line" in w else None
            if st.motion is None and st.line is None:
                raise StimulusError(f"{where(w)}: 'when' needs motion or line")
            if "phase" in w:
                if w["phase"] not in PHASES:
                    raise StimulusError(f"{where(w, 'phase')}: phase must be one of {', '.join(PHASES)}")
                st.phase = str(w["phase"])
            if "reached" in w:
                r = w["reached"]
                st.reached_default = r is True
                st.reached_mm = default_reach_mm if r is True else float(_number(r, "reached", where(w, "reached")))
            if st.phase is None and st.reached_mm is None:
                st.phase = "end"
        else:
            raise StimulusError(f"{here}: stimulus {i + 1} needs 'at' or 'when'")
        out.append(st)
    return out


def load_stimuli(path: str | Path, default_reach_mm: float = 0.1) -> list[Stimulus]:
    """The stimuli of a stimuli YAML file (:func:`load_cell` without the rules)."""
    return load_cell(path, default_reach_mm).stimuli


def load_cell(path: str | Path, default_reach_mm: float = 0.1) -> Cell:
    """Read and validate a stimuli YAML file, stimuli and rules (see the module docstring):
    the one loader of a cell file (a run reads it once: interp/run.py ``make_runtime`` hands
    the Cell to the robot choice and the controller).

    Raises :class:`StimulusError` (with ``file:line``) for an unreadable, oversized or
    malformed file."""
    return parse_cell(read_cell_yaml(path), default_reach_mm, source=str(path))


def read_cell_yaml(path: str | Path) -> Any:
    """The YAML document of the cell file `path`, read within :data:`MAX_STIMULI_BYTES` as UTF-8
    with a safe loader; each mapping carries ``line`` and
    ``key_lines`` (1-based) for messages. The one reader of cell files (:func:`load_cell`,
    interp/robotcell.py's cells of several robots). Raises :class:`StimulusError` (with
    ``file:line``) for an unreadable, oversized or malformed file."""
    p = Path(path)
    try:
        if p.stat().st_size > MAX_STIMULI_BYTES:
            raise StimulusError(f"{p}: larger than the limit of {MAX_STIMULI_BYTES} bytes")
        if not p.is_file():
            raise StimulusError(f"{p}: not a regular file")
        text = p.read_bytes().decode("utf-8")
    except OSError as exc:
        raise StimulusError(f"{p}: cannot read: {exc.strerror or exc}") from None
    except UnicodeDecodeError as exc:
        raise StimulusError(f"{p}: not UTF-8 text (byte {exc.start})") from None
    try:
        doc = yaml.load(text, Loader=_Loader)  # noqa: S506 - a SafeLoader subclass
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = f":{mark.line + 1}" if mark is not None else ""
        raise StimulusError(f"{p}{line}: not valid YAML: {exc.problem or exc.context}") from None
    except yaml.YAMLError as exc:
        raise StimulusError(f"{p}: not valid YAML: {exc}") from None
    except TypeError as exc:   # an unhashable mapping key
        raise StimulusError(f"{p}: not a valid stimuli file: {exc}") from None
    return doc


def resolve_signals(stimuli: list[Stimulus],
                    lookup: Callable[[str], tuple[str, int, int | None] | None],
                    rules: list[Rule] = ()) -> None:
    """Replace SIGNAL names in the stimuli and rules by the inputs they stand for, in place,
    and build each rule's condition (robot/cellrules.py ``compile_condition``).

    `lookup(NAME)` gives ``(base, first, last)`` for a SIGNAL declared on ``base``
    (``"$IN"``, ``"$ANIN"``, ...) from input ``first`` to ``last`` (None for one input), or
    None for an unknown name. A group takes an INT (bit 0 on ``first``), one ``$IN`` a BOOL.
    Raises :class:`StimulusError` (with the stimulus's or rule's ``file:line``) for an unknown
    name, a signal on an output, a value that does not fit, or a condition that names an
    unknown signal or mixes types.
    """
    for st in stimuli:
        st.set = _resolve_set(st.set, st.where or "stimuli", lookup)
    for r in rules:
        where = r.where or "rules"
        r.set = _resolve_set(r.set, where, lookup)
        try:
            r.condition = compile_condition(r.when, lookup)
        except ConditionError as exc:
            col = f" (column {exc.column} of the condition)" if exc.column else ""
            raise StimulusError(f"{where}: when {r.text!r}: {exc}{col}") from None


def _resolve_set(sets: dict[str, Any], where: str,
                 lookup: Callable[[str], tuple[str, int, int | None] | None]) -> dict[str, Any]:
    resolved: dict[str, Any] = {}
    for name, value in sets.items():
        if name.startswith("$"):
            resolved[name] = value
            continue
        found = lookup(name)
        if found is None:
            raise StimulusError(f"{where}: unknown signal {name} (neither $IN[n]/$ANIN[n] nor a "
                                f"SIGNAL declared in $config.dat or the program's data list)")
        base, first, last = found
        if base not in ("$IN", "$ANIN"):
            raise StimulusError(f"{where}: {name} is a SIGNAL on {base}; only $IN/$ANIN can be stimulated")
        if base == "$ANIN" or last is None:
            if base == "$IN" and not isinstance(value, bool):
                raise StimulusError(f"{where}: {name} is one input ($IN[{first}]): give true or false")
            resolved[f"{base}[{first}]"] = value
            continue
        width = last - first + 1
        if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value < (1 << width):
            raise StimulusError(f"{where}: {name} is the group $IN[{first}] TO $IN[{last}]: "
                                f"give a whole number 0..{(1 << width) - 1}")
        for bit, n in enumerate(range(first, last + 1)):
            resolved[f"$IN[{n}]"] = bool((value >> bit) & 1)
    return resolved
