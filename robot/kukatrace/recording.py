"""Read a KUKA Trace recording: the ``KRCIpo`` CSV of 12 ms samples and the ``PROG.TXT`` motion log
(issue 60; the formats as the KR C4 and OfficeLite of ../shared/real-traces write them, KSS 8.5).

**KRCIpo CSV.** ``;``-separated, one header row, one row per IPO cycle. The header is Latin-1
(``A_Act[°]``: byte 0xB0). Columns are found by name, units taken from the recordings, not from
the header (checked on every recording of ../shared/real-traces, tests/robot/test_kukatrace.py):

* ``Zeit[sec]``: time since the trace started, s;
* ``X_Act``, ``Y_Act``, ``Z_Act``: the TCP in ``$BASE`` with the active ``$TOOL``, mm;
* ``A_Act``, ``B_Act``, ``C_Act`` and ``AxisPos_Act1..6``: **radians** although the header says
  degrees (HOME's A2 reads -1.91986 = -110°; the forward kinematics of the axes as radians gives
  the recorded TCP to 0.00 mm, robot/data/kr3_r540.dat): read as radians, given in degrees;
* ``CartVel_Act``: the TCP speed in **mm/s** although the header says m/s (about 2190 for A1 at
  225 °/s with the TCP 557 mm from the axis); its first row is not a speed (up to 59 000): NaN;
* any other column (torques ``GearTorq_*``, ``DriveMotorTorq_*``) is kept as read, by name.

"Act" values are measured: they lag the commanded motion by 36-48 ms.

**PROG.TXT.** A header block (``#BEGINHEADER`` .. ``#ENDHEADER``: ``TIME``, ``DATE``, ``ROBOT
TYPE``, ``TRACEHELPER NAME``) and per motion a ``SIGNAL: START`` block and a ``SIGNAL: END``
block (``#BEGINMOTIONINFO`` .. ``#ENDMOTIONINFO``) of ``KEY: value`` lines; values in braces
(``{ x 1.0, y 2.0, cm { x .. } }``) are structures. ``TIME`` is the trace time of the signal (s),
``ENDTIME`` the planned end, which ignores the program override. ``LINE`` counts the lines of the
file as it was on the controller. ``TYPE`` ``CIR`` is a CIRC.

Errors: :class:`RecordingError` (a ValueError) naming ``file:line`` and what is wrong; a file
larger than ``krl.limits.MAX_RECORDING_BYTES`` or a CSV row of more than
``MAX_RECORDING_COLUMNS`` columns is refused before it is parsed.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from krl.limits import MAX_RECORDING_BYTES, MAX_RECORDING_COLUMNS

from ..axismap import ROBOT_KEYS

from ..exactstop import override_interval

#: the name suffixes of the two files of a recording (case-insensitive)
IPO_SUFFIX = "_KRCIpo.csv"
PROG_SUFFIX = "_PROG.TXT"
#: the IPO cycle of a KR C4 (s): the samples' step
IPO_CYCLE_S = 0.012
#: the columns given in degrees (read as radians)
#: the axis columns: AxisPos_Act1..6 (A1..A6, robot/axismap.py)
AXIS_COLUMNS = tuple(f"AxisPos_Act{k[1:]}" for k in ROBOT_KEYS)
ANGLE_COLUMNS = ("A_Act", "B_Act", "C_Act") + AXIS_COLUMNS
#: PROG.TXT's motion types and the KRL names the project uses for them
TYPE_NAMES = {"CIR": "CIRC"}


class RecordingError(ValueError):
    """A KUKA Trace file that cannot be read: the message names file:line and why."""


@dataclass
class MotionRecord:
    """One motion of a PROG.TXT (its START block, completed by its END block).

    Times in s of trace time; ``endtime``: the planned end (PROG.TXT's ENDTIME: the program
    override is not in it); ``end``: the END signal (None when the trace stopped before it).
    ``kind``: PTP, LIN, CIRC (KRL's names); ``point``/``aux``: the target and the auxiliary point
    as recorded ({x, y, z mm, a, b, c deg, s, t} in ``$BASE``; None if absent); ``velocities``,
    ``accelerations``: PTP ``a1..a6`` in %, CP ``cp`` mm/s (mm/s²) and ``ori1``/``ori2`` °/s
    (°/s²); ``base``, ``tool``: (X, Y, Z, A, B, C) mm/deg; ``load``/``load_a3``: ``{m, cm, j}``;
    ``file_line``: where the START block is in the PROG.TXT.
    """

    start: float
    endtime: float | None
    kind: str
    line: int | None
    module: str = ""
    routine: str = ""
    end: float | None = None
    point_name: str = ""
    point: dict[str, float] | None = None
    aux_name: str = ""
    aux: dict[str, float] | None = None
    blending: str = "NONE"
    velocities: dict[str, float] = field(default_factory=dict)
    accelerations: dict[str, float] = field(default_factory=dict)
    base: tuple[float, ...] | None = None
    tool: tuple[float, ...] | None = None
    ipo_mode: str = ""
    load: dict[str, Any] | None = None
    load_a3: dict[str, Any] | None = None
    file_line: int = 0

    @property
    def exact_stop(self) -> bool:
        """True for a motion without approximation (``BLENDING: NONE``)."""
        return self.blending.upper() in ("", "NONE")


@dataclass
class Recording:
    """One KUKA Trace recording.

    ``name``: the trace name (the file name between the controller's prefix and the helper's
    suffix, e.g. ``A1_PTP_10_po85``); ``ipo_path``/``prog_path``: the files read (either may be
    None); ``header``: PROG.TXT's header (``ROBOT TYPE`` ...); ``t`` (N,) s; ``axes`` (N, 6) deg;
    ``tcp`` (N, 6) X, Y, Z mm and A, B, C deg; ``speed`` (N,) mm/s (first row NaN); ``columns``:
    every other CSV column by name; ``motions``: :class:`MotionRecord` in order of their START.
    """

    name: str
    ipo_path: Path | None
    prog_path: Path | None
    header: dict[str, str]
    t: np.ndarray
    axes: np.ndarray
    tcp: np.ndarray
    speed: np.ndarray
    columns: dict[str, np.ndarray]
    motions: list[MotionRecord]

    @property
    def robot_type(self) -> str:
        """PROG.TXT's ``ROBOT TYPE`` (e.g. ``#KR3R540 C4SR``), '' when unknown."""
        return self.header.get("ROBOT TYPE", "")

    def override_interval(self) -> tuple[float, float] | None:
        """The program overrides the END signals allow (robot/exactstop.py
        :func:`~robot.exactstop.override_interval`), as fractions; None when none fits."""
        return override_interval(self.motions, IPO_CYCLE_S)


# ------------------------------------------------------------------------------ files
def recording_files(path: str | Path) -> tuple[str, Path | None, Path | None]:
    """(name, CSV path, PROG.TXT path) of the recording `path` names: either of its two files,
    or their common stem (``.../WINDOWS-V37DJA1 - 8101392_A1_PTP_10_po85``). Raises
    RecordingError when neither file exists."""
    p = Path(path)
    low = p.name.lower()
    stem = None
    for suffix in (IPO_SUFFIX, PROG_SUFFIX):
        if low.endswith(suffix.lower()):
            stem = p.with_name(p.name[:-len(suffix)])
    if stem is None:
        stem = p
    ipo = stem.with_name(stem.name + IPO_SUFFIX)
    prog = stem.with_name(stem.name + PROG_SUFFIX)
    ipo = ipo if ipo.is_file() else None
    prog = prog if prog.is_file() else None
    if ipo is None and prog is None:
        raise RecordingError(f"{path}: no KUKA Trace recording here (neither {stem.name}{IPO_SUFFIX} "
                             f"nor {stem.name}{PROG_SUFFIX})")
    name = stem.name.split("_", 1)[1] if "_" in stem.name else stem.name
    return name, ipo, prog


def is_recording(path: str | Path) -> bool:
    """True when `path` names a KUKA Trace recording (:func:`recording_files` finds a file)."""
    try:
        recording_files(path)
    except RecordingError:
        return False
    return True


def _read_text(path: Path) -> str:
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_RECORDING_BYTES + 1)
    except OSError as exc:
        raise RecordingError(f"{path}: cannot read ({exc.strerror})") from None
    if len(raw) > MAX_RECORDING_BYTES:
        raise RecordingError(f"{path}: larger than {MAX_RECORDING_BYTES} bytes (krl.limits.MAX_RECORDING_BYTES)")
    return raw.decode("latin-1")


def read_recording(path: str | Path) -> Recording:
    """The recording `path` names (:func:`recording_files`): its samples and its motions.
    Raises RecordingError."""
    name, ipo, prog = recording_files(path)
    header: dict[str, str] = {}
    motions: list[MotionRecord] = []
    if prog is not None:
        header, motions = read_prog(prog)
    if ipo is not None:
        t, axes, tcp, speed, cols = read_ipo(ipo)
    else:
        t, axes, tcp, speed, cols = np.zeros(0), np.zeros((0, 6)), np.zeros((0, 6)), np.zeros(0), {}
    return Recording(name, ipo, prog, header, t, axes, tcp, speed, cols, motions)


# ------------------------------------------------------------------------------ KRCIpo
_UNIT = re.compile(r"\[[^\]]*\]\s*$")


def read_ipo(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """(t s, axes deg (N, 6), tcp (N, 6) mm/deg, speed mm/s, other columns) of a KRCIpo CSV (the
    module's docstring says what each column holds). Raises RecordingError."""
    text = _read_text(path)
    lines = text.splitlines()
    first = next((i for i, ln in enumerate(lines) if ln.strip()), None)
    if first is None:
        raise RecordingError(f"{path}:1: empty file (a KRCIpo CSV starts with its header row)")
    head = lines[first].split(";")
    if len(head) > MAX_RECORDING_COLUMNS:
        raise RecordingError(f"{path}:{first + 1}: {len(head)} columns, more than "
                             f"{MAX_RECORDING_COLUMNS} (krl.limits.MAX_RECORDING_COLUMNS)")
    names = [_UNIT.sub("", h).strip() for h in head]
    need = ["X_Act", "Y_Act", "Z_Act", *ANGLE_COLUMNS]
    missing = [n for n in need if n not in names]
    if missing:
        raise RecordingError(f"{path}:{first + 1}: not a KRCIpo header (no column {', '.join(missing)})")
    rows: list[list[float]] = []
    for i in range(first + 1, len(lines)):
        ln = lines[i]
        if not ln.strip():
            continue
        cells = ln.split(";")
        if len(cells) != len(names):
            raise RecordingError(f"{path}:{i + 1}: {len(cells)} values, the header has {len(names)} columns")
        try:
            rows.append([float(c) for c in cells])
        except ValueError:
            bad = next(c for c in cells if not _is_number(c))
            raise RecordingError(f"{path}:{i + 1}: {bad.strip()[:40]!r} is not a number") from None
    data = np.array(rows, dtype=float).reshape(len(rows), len(names))
    col = {n: data[:, k] for k, n in enumerate(names)}
    t = data[:, 0].copy()
    if len(t) and (not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0)):
        raise RecordingError(f"{path}: the time column ({head[0].strip()}) is not finite and ascending")
    axes = np.degrees(np.column_stack([col[c] for c in AXIS_COLUMNS]))
    tcp = np.column_stack([col["X_Act"], col["Y_Act"], col["Z_Act"],
                           np.degrees(col["A_Act"]), np.degrees(col["B_Act"]), np.degrees(col["C_Act"])])
    speed = col["CartVel_Act"].copy() if "CartVel_Act" in col else np.full(len(t), np.nan)
    if len(speed):
        speed[0] = np.nan          # the first row holds no speed
    used = {names[0], "X_Act", "Y_Act", "Z_Act", "CartVel_Act", *ANGLE_COLUMNS}
    others = {n: col[n] for n in names if n not in used}
    return t, axes, tcp, speed, others


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


# ------------------------------------------------------------------------------ PROG.TXT
def read_prog(path: Path) -> tuple[dict[str, str], list[MotionRecord]]:
    """(header, motions) of a PROG.TXT. Raises RecordingError."""
    text = _read_text(path)
    header: dict[str, str] = {}
    motions: list[MotionRecord] = []
    block: dict[str, str] | None = None
    where = 0
    in_header = False
    for i, raw in enumerate(text.splitlines(), 1):
        ln = raw.strip()
        if not ln:
            continue
        if ln == "#BEGINHEADER":
            in_header = True
        elif ln == "#ENDHEADER":
            in_header = False
        elif ln == "#BEGINMOTIONINFO":
            if block is not None:
                raise RecordingError(f"{path}:{i}: #BEGINMOTIONINFO inside the block of line {where}")
            block, where = {}, i
        elif ln == "#ENDMOTIONINFO":
            if block is None:
                raise RecordingError(f"{path}:{i}: #ENDMOTIONINFO without #BEGINMOTIONINFO")
            _motion_block(path, where, block, motions)
            block = None
        else:
            key, sep, value = ln.partition(":")
            if not sep:
                raise RecordingError(f"{path}:{i}: not a KEY: value line: {ln[:60]!r}")
            key = key.strip().upper()
            if block is not None:
                block[key] = value.strip()
                block.setdefault("__line__:" + key, str(i))
            elif in_header:
                header[key] = value.strip()
            else:
                raise RecordingError(f"{path}:{i}: a line outside the header and the motion blocks")
    if block is not None:
        raise RecordingError(f"{path}:{where}: #BEGINMOTIONINFO without #ENDMOTIONINFO")
    return header, motions


def _number(path: Path, block: dict[str, str], key: str, where: int) -> float | None:
    text = block.get(key)
    if text is None or text == "":
        return None
    try:
        v = float(text)
    except ValueError:
        line = block.get("__line__:" + key, where)
        raise RecordingError(f"{path}:{line}: {key}: {text[:40]!r} is not a number") from None
    if not math.isfinite(v):
        raise RecordingError(f"{path}:{block.get('__line__:' + key, where)}: {key}: {text[:40]!r} is not finite")
    return v


def _motion_block(path: Path, where: int, block: dict[str, str], motions: list[MotionRecord]) -> None:
    signal = block.get("SIGNAL", "").upper()
    t = _number(path, block, "TIME", where)
    if t is None:
        raise RecordingError(f"{path}:{where}: motion block without TIME")
    line_v = _number(path, block, "LINE", where)
    line = int(line_v) if line_v is not None else None
    module = block.get("MODULE", "")
    if signal == "END":
        for m in motions:
            if m.end is None and m.line == line and m.module == module:
                m.end = t
                return
        raise RecordingError(f"{path}:{where}: SIGNAL: END of line {line} without its START")
    if signal != "START":
        raise RecordingError(f"{path}:{where}: SIGNAL {signal or '(none)'}: START or END was expected")

    def struct(key: str) -> dict[str, Any] | None:
        text = block.get(key)
        if not text:
            return None
        try:
            return parse_struct(text)
        except ValueError as exc:
            raise RecordingError(f"{path}:{block.get('__line__:' + key, where)}: {key}: {exc}") from None

    def frame(key: str) -> tuple[float, ...] | None:
        s = struct(key)
        if s is None:
            return None
        return tuple(float(s.get(k, 0.0)) for k in ("x", "y", "z", "a", "b", "c"))

    kind = block.get("TYPE", "").upper()
    motions.append(MotionRecord(
        start=t, endtime=_number(path, block, "ENDTIME", where), kind=TYPE_NAMES.get(kind, kind), line=line,
        module=module, routine=block.get("FUNCTION/PROCEDURE", ""), point_name=block.get("POINT NAME", ""),
        point=struct("POINT COORDINATES"), aux_name=block.get("AUXILIARY POINT NAME", ""),
        aux=struct("AUXILIARY POINT COORDINATES"), blending=block.get("BLENDING", "NONE"),
        velocities=_flat(struct("VELOCITIES")), accelerations=_flat(struct("ACCELERATIONS")),
        base=frame("BASE"), tool=frame("TOOL"), ipo_mode=block.get("IPO MODE", ""),
        load=struct("LOAD"), load_a3=struct("LOAD A3"), file_line=where))


def _flat(s: dict[str, Any] | None) -> dict[str, float]:
    return {k: float(v) for k, v in (s or {}).items() if isinstance(v, float)}


_TOKEN = re.compile(r"\s*(\{|\}|,|[^\s{},]+)")


def parse_struct(text: str) -> dict[str, Any]:
    """A PROG.TXT structure ``{ x 1.5, s 2, cm { x 0.1 } }`` as a dict (numbers as floats, a
    nested structure as a dict, any other word as a string). Raises ValueError."""
    tokens = [m.group(1) for m in _TOKEN.finditer(text)]
    pos = 0

    def value() -> Any:
        nonlocal pos
        if pos >= len(tokens):
            raise ValueError("the structure ends early")
        tok = tokens[pos]
        if tok == "{":
            return obj()
        pos += 1
        try:
            return float(tok)
        except ValueError:
            return tok

    def obj() -> dict[str, Any]:
        nonlocal pos
        if pos >= len(tokens) or tokens[pos] != "{":
            raise ValueError("'{' was expected")
        pos += 1
        out: dict[str, Any] = {}
        while pos < len(tokens) and tokens[pos] != "}":
            key = tokens[pos]
            if key in "{},":
                raise ValueError(f"a component name was expected, not {key!r}")
            pos += 1
            out[key.lower()] = value()
            if pos < len(tokens) and tokens[pos] == ",":
                pos += 1
        if pos >= len(tokens):
            raise ValueError("'}' was expected")
        pos += 1
        return out

    result = obj()
    if pos != len(tokens):
        raise ValueError(f"text after the structure: {' '.join(tokens[pos:])[:40]!r}")
    return result


__all__ = ["IPO_CYCLE_S", "MotionRecord", "Recording", "RecordingError", "is_recording", "parse_struct",
           "read_ipo", "read_prog", "read_recording", "recording_files"]
