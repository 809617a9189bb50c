"""What changed since the night before: the flags of the index page.

Rules (one :class:`Flag` each):

* an item whose status changed (a conformance case, a corpus file's parse status, a real
  program's end): ``regression`` when a case leaves ``pass`` or a file leaves ``ok``,
  ``improvement`` the other way, ``change`` otherwise; an item that appears or disappears
  is a ``change``;
* a ``count`` figure that changed: ``regression`` or ``improvement`` where the figure has a
  good direction (:data:`BETTER`), ``change`` otherwise;
* a ``ratio`` figure (a speed ratio measured in one run) outside its noise band. The band is
  measured from the history, not guessed: the median of the earlier nights' values ± 3
  robust standard deviations (1.4826 × the median absolute deviation), and at least ±
  the largest night-to-night step seen so far, so that a band is as wide as the noise
  already observed. With fewer than :data:`MIN_BAND_NIGHTS` earlier nights there is no band
  and no flag yet (the figure is still charted).

Every flag links to the report of the night it was raised in.
"""

from __future__ import annotations

import statistics
from dataclasses import dataclass
from urllib.parse import quote

from .figures import kind_of

#: earlier nights needed before a ratio's noise band is measured
MIN_BAND_NIGHTS = 3

#: figure -> +1 (higher is better) or -1 (lower is better); prefixes end in "."
BETTER: dict[str, int] = {
    "conformance.passed": 1, "conformance.tree_vm_agree": 1, "conformance.fuzz_agree": 1,
    "conformance.real_agree": 1, "corpus.files_ok": 1, "corpus.known_invalid": -1,
    "negative.rejected": 1, "real.completed": 1, "limits.breaches": -1, "limits.worst_ratio": -1,
    "fuzz.findings": -1, "bench.": 1, "lsp.": -1,
}

#: item kind -> (the good status, the report it links to, anchor prefix)
ITEM_REPORTS = {
    "case": ("pass", "conformance/report.html", ""),
    "corpus_file": ("ok", "recovery/report.html", None),
    "real_program": ("completed", "conformance/report.html", None),
}
#: figure prefix -> the report a figure flag links to
FIGURE_REPORTS = (("conformance.", "conformance/report.html"), ("real.", "conformance/report.html#real"),
                  ("corpus.", "recovery/report.html"), ("negative.", "recovery/report.html"),
                  ("check.", "check/check_report.md"), ("fuzz.", "fuzz/summary.json"),
                  ("limits.", "limits.jsonl"), ("bench.", "bench.json"), ("lsp.", "lsp-bench.json"))


@dataclass(frozen=True)
class Flag:
    """One change: ``severity`` regression | improvement | change, ``subject`` (a figure or
    ``kind:name``), ``text`` for people, ``link`` relative to reports/nightly/."""
    severity: str
    subject: str
    text: str
    link: str


def _direction(name: str) -> int:
    for key, sign in BETTER.items():
        if name == key or (key.endswith(".") and name.startswith(key)):
            return sign
    return 0


def _figure_link(date: str, name: str) -> str:
    for prefix, report in FIGURE_REPORTS:
        if name.startswith(prefix):
            return f"{quote(date)}/{report}"
    return quote(date) + "/"


def noise_band(values: list[float]) -> tuple[float, float] | None:
    """(low, high) of the noise band of the earlier values, or None with too few of them."""
    if len(values) < MIN_BAND_NIGHTS:
        return None
    med = statistics.median(values)
    mad = statistics.median(abs(v - med) for v in values)
    steps = [abs(b - a) for a, b in zip(values, values[1:])]
    half = max(3 * 1.4826 * mad, max(steps))
    return med - half, med + half


def _severity(sign: int, delta: float) -> str:
    if sign == 0 or delta == 0:
        return "change"
    return "improvement" if sign * delta > 0 else "regression"


def figure_flags(series: dict[str, list[tuple[str, float]]], date: str) -> list[Flag]:
    """Flags of the figures of night ``date`` against the nights before it."""
    out: list[Flag] = []
    for name, points in sorted(series.items()):
        earlier = [v for d, v in points if d < date]
        now = [v for d, v in points if d == date]
        if not now or not earlier:
            continue
        value, prev = now[0], earlier[-1]
        kind = kind_of(name)
        if kind == "count" and value != prev:
            out.append(Flag(_severity(_direction(name), value - prev), name,
                            f"{name}: {prev:g} -> {value:g}", _figure_link(date, name)))
        elif kind == "ratio":
            band = noise_band(earlier)
            if band and not band[0] <= value <= band[1]:
                out.append(Flag(_severity(_direction(name), value - statistics.median(earlier)), name,
                                f"{name}: {value:g} outside its noise band {band[0]:.3g}..{band[1]:.3g} "
                                f"(from {len(earlier)} earlier nights)", _figure_link(date, name)))
    return out


def item_flags(before: dict[tuple[str, str], str], after: dict[tuple[str, str], str], date: str) -> list[Flag]:
    """Flags of the items whose status differs between two nights."""
    out: list[Flag] = []
    kinds_before, kinds_after = {k for k, _ in before}, {k for k, _ in after}
    for kind in sorted(kinds_before ^ kinds_after):      # a whole report missing on one night
        out.append(Flag("change", f"{kind}:*", f"{kind}: no statuses recorded "
                        f"{'this night' if kind in kinds_before else 'the night before'}", quote(date) + "/"))
    for key in sorted(set(before) | set(after)):
        kind, name = key
        if kind not in kinds_before or kind not in kinds_after:
            continue
        old, new = before.get(key), after.get(key)
        if old == new:
            continue
        good, report, anchor = ITEM_REPORTS.get(kind, ("", "", None))
        link = f"{quote(date)}/{report}" + (f"#{quote(name)}" if anchor is not None and report else "")
        if old is None or new is None:
            text = f"{kind} {name}: {'new' if old is None else 'gone'}" + (f" ({new})" if new else "")
            severity = "change"
        else:
            text = f"{kind} {name}: {old} -> {new}"
            severity = ("regression" if old == good else "improvement" if new == good else "change")
        out.append(Flag(severity, f"{kind}:{name}", text, link))
    return out
