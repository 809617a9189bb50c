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

``phase`` is one of start, blend_start, blend_end, end. ``reached`` (mm) fires in the
first IPO cycle in which that motion is being executed and the TCP is within the given
distance of the motion's programmed end point (default ``$IN_POS_CAR`` = 0.1 mm when
``reached: true``). Values: BOOL for ``$IN``, REAL for ``$ANIN``. Each stimulus fires once.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from .io import parse_signal

PHASES = ("start", "blend_start", "blend_end", "end")


class StimulusError(ValueError):
    """Malformed stimuli file."""


@dataclass
class Stimulus:
    """One input change. Exactly one of ``at`` or a motion condition is set.

    Attributes:
        set: signal name -> value.
        at: time in s, or None.
        motion: motion id (n-th enqueued motion), or None. line: source line, or None.
        phase: motion phase, or None. reached_mm: distance for "TCP reaches the point".
        delay: extra delay in s after the condition holds.
    """

    set: dict[str, Any]
    at: float | None = None
    motion: int | None = None
    line: int | None = None
    phase: str | None = None
    reached_mm: float | None = None
    delay: float = 0.0
    fired: bool = False
    due: float | None = field(default=None, repr=False)

    def matches_motion(self, motion_id: int, line: int | None) -> bool:
        if self.motion is not None:
            return self.motion == motion_id
        return self.line is not None and line is not None and self.line == line


def parse_stimuli(doc: Any, default_reach_mm: float = 0.1) -> list[Stimulus]:
    """Build stimuli from a parsed YAML document. Raises StimulusError."""
    if doc is None:
        return []
    if isinstance(doc, dict):
        doc = doc.get("stimuli", [])
    if not isinstance(doc, list):
        raise StimulusError("stimuli: expected a list")
    out: list[Stimulus] = []
    for i, item in enumerate(doc):
        if not isinstance(item, dict) or "set" not in item or not isinstance(item["set"], dict):
            raise StimulusError(f"stimulus {i + 1}: needs a 'set' mapping")
        sets = {}
        for name, v in item["set"].items():
            base, _ = parse_signal(str(name))
            if base not in ("$IN", "$ANIN"):
                raise StimulusError(f"stimulus {i + 1}: only $IN/$ANIN can be stimulated, not {name}")
            sets[str(name).upper().replace(" ", "")] = v
        st = Stimulus(set=sets, delay=float(item.get("delay", 0.0)))
        if "at" in item:
            st.at = float(item["at"])
        elif "when" in item and isinstance(item["when"], dict):
            w = item["when"]
            st.motion = int(w["motion"]) if "motion" in w else None
            st.line = int(w["line"]) if "line" in w else None
            if st.motion is None and st.line is None:
                raise StimulusError(f"stimulus {i + 1}: 'when' needs motion or line")
            if "phase" in w:
                if w["phase"] not in PHASES:
                    raise StimulusError(f"stimulus {i + 1}: phase must be one of {PHASES}")
                st.phase = str(w["phase"])
            if "reached" in w:
                r = w["reached"]
                st.reached_mm = default_reach_mm if r is True else float(r)
            if st.phase is None and st.reached_mm is None:
                st.phase = "end"
        else:
            raise StimulusError(f"stimulus {i + 1}: needs 'at' or 'when'")
        out.append(st)
    return out


def load_stimuli(path: str | Path, default_reach_mm: float = 0.1) -> list[Stimulus]:
    """Read a stimuli YAML file (see the module docstring)."""
    text = Path(path).read_text(encoding="utf-8")
    return parse_stimuli(yaml.safe_load(text), default_reach_mm)
