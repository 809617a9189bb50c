"""Breakpoints of a debug run (interp/debug/engine.py): a line or function breakpoint with
its KRL condition and its hit condition (DAP ``SourceBreakpoint``/``FunctionBreakpoint``).

A condition is a KRL expression (krl/syntax's ``expression`` rule) evaluated in the frame of
the statement where the breakpoint stands; a hit condition counts the passes whose condition
held. Limits: at most krl.limits.MAX_DAP_BREAKPOINTS per request; a hit count of at most nine
digits.
"""

from __future__ import annotations


class Breakpoint:
    """One breakpoint: ``id`` (unique in the run), ``line`` (0 for a function breakpoint),
    ``condition`` (KRL text or None), ``hit_text`` (the hit condition as given, or None),
    ``hits`` (passes whose condition held, this run)."""

    def __init__(self, bid: int, line: int, condition: str | None, hit: str | None) -> None:
        self.id = bid
        self.line = line
        self.condition = condition.strip() if condition and condition.strip() else None
        self.hit_text = hit.strip() if hit and hit.strip() else None
        self.hit_test = hit_test(self.hit_text) if self.hit_text else None
        self.hits = 0


def hit_test(text: str):
    """DAP hitCondition: ``N`` or ``>=N`` (from the Nth hit on), ``=N``/``==N`` (the Nth
    hit only), ``>N``, ``%N`` (every Nth hit). None when the text is none of these."""
    t = text.replace(" ", "")
    for op, fn in ((">=", lambda h, n: h >= n), ("==", lambda h, n: h == n), ("=", lambda h, n: h == n),
                   (">", lambda h, n: h > n), ("%", lambda h, n: n > 0 and h % n == 0), ("", lambda h, n: h >= n)):
        if t.startswith(op) and t[len(op):].isdigit() and len(t) - len(op) <= 9:
            n = int(t[len(op):])
            return lambda h, n=n, fn=fn: fn(h, n)
    return None
