"""Touch-up of a taught point: the point's declaration in its data list gets the robot's actual
position, as the smartPAD's "Touch Up" writes it (KUKA System Software 8, "Modifying motion
parameters: touching up a point").

The data list is read through the front end (robot/datalist.py: the declaration's line and its
components); only the numbers of that one aggregate are replaced, component by component, so
the line keeps its spelling, spacing, comments and the components the point did not have.
The file is written durably (krl/durable.py ``write_bytes``: owner, group and mode kept, a
read-only file refused, an edit saved meanwhile kept) in its own encoding
(krl/source.py ``decode_bytes``/``encode_text``: a cp1252 file stays cp1252, CRLF stays CRLF).
"""

from __future__ import annotations

import re
from pathlib import Path

from krl.limits import MAX_WEB_FILE_BYTES
from krl.durable import write_bytes
from krl.source import decode_bytes, encode_text
from robot.datalist import DataListError, read_data_list

CARTESIAN = ("X", "Y", "Z", "A", "B", "C")
STATUS_TURN = ("S", "T")
AXES = ("A1", "A2", "A3", "A4", "A5", "A6")
_NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|'[Bb][01]+'|'[Hh][0-9A-Fa-f]+'"


class TouchUpError(ValueError):
    """The point cannot be touched up (the message says why, with file:line)."""


def _fmt(v: float) -> str:
    return f"{float(v):.6f}".rstrip("0").rstrip(".") if v != int(v) else f"{int(v)}"


def touch_up(dat: Path, name: str, pos: dict, axes: list[float]) -> dict:
    """Write ``pos`` (X..C mm/deg, S, T of ``$POS_ACT``) or, for an axis point (A1..A6 only),
    ``axes`` (deg) into the declaration of ``name`` in the data list ``dat``. Returns the new
    components. Raises :class:`TouchUpError` (no such point, not a point, the line does not
    hold the aggregate) and OSError (the file cannot be written)."""

    try:
        if dat.stat().st_size > MAX_WEB_FILE_BYTES:
            raise TouchUpError(f"{dat.name}: larger than {MAX_WEB_FILE_BYTES} bytes")
        values = read_data_list(dat)
    except DataListError as exc:
        raise TouchUpError(str(exc)) from None
    dv = values.get(name.upper())
    if dv is None:
        raise TouchUpError(f"{dat.name}: no point {name}")
    if not isinstance(dv.value, dict) or not dv.value:
        raise TouchUpError(f"{dat.name}:{dv.line}: {name} is not a point (no aggregate value)")
    have = set(dv.value)
    if have & set(CARTESIAN) and {"X", "Y", "Z"} <= have:
        new = {k: float(pos[k]) for k in CARTESIAN if k in have}
        new.update({k: int(pos[k]) for k in STATUS_TURN if k in have and k in pos})
    elif have & set(AXES):
        new = {k: float(axes[int(k[1]) - 1]) for k in AXES if k in have}
    else:
        raise TouchUpError(f"{dat.name}:{dv.line}: {name} is neither a Cartesian nor an axis point")
    data = dat.read_bytes()
    text, encoding = decode_bytes(data)
    lines = text.splitlines(keepends=True)
    i = dv.line - 1
    line = lines[i]
    m = re.search(rf"\b{re.escape(name)}\s*=\s*\{{", line, re.IGNORECASE)
    if m is None:
        raise TouchUpError(f"{dat.name}:{dv.line}: the aggregate of {name} is not on its declaration line")
    start = m.end()
    end = line.find("}", start)
    if end < 0:
        raise TouchUpError(f"{dat.name}:{dv.line}: the aggregate of {name} does not end on its line")
    body = line[start:end]
    for key, v in new.items():
        pattern = rf"(?<![\w$])({re.escape(key)}\s+)({_NUMBER})"
        text_v = str(v) if isinstance(v, int) else _fmt(v)
        body, n = re.subn(pattern, lambda mm, t=text_v: mm.group(1) + t, body, count=1, flags=re.IGNORECASE)
        if n != 1:
            raise TouchUpError(f"{dat.name}:{dv.line}: component {key} of {name} not found")
    lines[i] = line[:start] + body + line[end:]
    write_bytes(dat, encode_text("".join(lines), encoding), expect=data)
    return new


__all__ = ["TouchUpError", "touch_up"]
