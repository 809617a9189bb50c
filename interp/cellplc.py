"""A PLC between the robots of a cell (issue 89; docs/cells.md "A PLC between the robots"): its
own I/O image, wired to the robots' (``R1 $OUT[10] -> PLC $IN[1]``, ``PLC $OUT[1] -> R2 $IN[10]``),
and reactive rules that answer its inputs on its outputs::

    plc:
      rules:
        - when: "$IN[1] AND NOT $IN[2]"     # the PLC's inputs and outputs, a KRL condition
          after: 0.2                        # s after the condition rose
          set: {"$OUT[1]": true}            # the PLC's outputs

A rule is a robot's own cell rule (robot/cellrules.py: parsed by the project's expression parser
into the subset ``$IN[n]``, ``$OUT[n]``, ``$ANIN[n]``, ``$ANOUT[n]``, literals and operators,
type-checked and compiled by the front end's evaluator, never ``eval``; fired on the rising edge,
answered at least ``after`` s and one cycle later), seen from the PLC: its condition reads the
PLC's image, its ``set`` writes the PLC's outputs (``$OUT[n]``: TRUE/FALSE), which the wires carry
to the robots. A PLC has no ``$config.dat``: no SIGNAL names. The PLC scans once per IPO cycle,
after the cell's wires have carried the robots' outputs (the cell's one clock; a PLC's own scan
time is not modelled: the same decision as a robot's own cell rules).

Limits: :data:`krl.limits.MAX_CELL_RULES` rules. Errors: ``error`` (the cell's CellError) naming
file:line.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from robot.cellrules import ConditionError, Rule, compile_condition, parse_condition, rules_may_fire, signal_of
from robot.cellrules import step_rules
from robot.io import IOImage

#: the PLC's name in the cell file's wires (a robot may not have it)
PLC = "PLC"
_KEYS = ("rules",)
_RULE_KEYS = ("when", "after", "set")


@dataclass
class CellPlc:
    """The PLC of a cell: its rules and its I/O image (``io.log``: its changes)."""
    rules: list[Rule]
    io: IOImage = field(default_factory=IOImage)
    _seen: object = field(default=None, repr=False)

    def scan(self, t: float, dt: float) -> None:
        """The PLC's scan at `t` (s), after the wires: the answers due are written to its
        outputs, then its conditions are evaluated (robot/cellrules.py ``step_rules``)."""
        self.io.now = t
        self._seen = step_rules(self.rules, self.io, t, dt, self._seen)

    def busy(self) -> bool:
        """Whether the PLC may still change an output: an answer pending or a condition risen."""
        return rules_may_fire(self.rules, self.io)


def _set(mapping, at, error, k: int) -> dict[str, bool]:
    if not isinstance(mapping, dict) or not mapping:
        raise error(f"{at(mapping)}: PLC rule {k}: 'set' maps the PLC's outputs to TRUE/FALSE")
    out = {}
    for name, value in mapping.items():
        try:
            base, n = signal_of(str(name))
        except ConditionError:
            base, n = "", 0
        if base != "$OUT" or not isinstance(value, bool):
            raise error(f"{at(mapping, name)}: PLC rule {k}: the PLC's rules set its outputs, "
                        f"'$OUT[n]': true or false (not {name!s}: {value!s})")
        out[f"$OUT[{n}]"] = value
    return out


def _rule(item, at, error, k: int) -> Rule:
    if not isinstance(item, dict) or "when" not in item or "set" not in item:
        raise error(f"{at(item)}: PLC rule {k}: a mapping with 'when', 'set' and, optionally, 'after'")
    bad = [key for key in item if key not in _RULE_KEYS]
    if bad:
        raise error(f"{at(item, bad[0])}: PLC rule {k}: unknown key {bad[0]!s} (known: {', '.join(_RULE_KEYS)})")
    text = item["when"]
    text = ("TRUE" if text else "FALSE") if isinstance(text, bool) else text
    after = item.get("after", 0.0)
    if isinstance(after, bool) or not isinstance(after, (int, float)) or not math.isfinite(after) or after < 0:
        raise error(f"{at(item, 'after')}: PLC rule {k}: 'after' is a number of seconds, not negative")
    try:
        if not isinstance(text, str):
            raise ConditionError("'when' is KRL text")
        expr = parse_condition(text)
        condition = compile_condition(expr, lambda name: None)     # no SIGNAL names: no $config.dat
    except ConditionError as exc:
        col = f" (column {exc.column} of the condition)" if exc.column else ""
        raise error(f"{at(item, 'when')}: PLC rule {k}: {exc}{col}") from None
    return Rule(when=expr, text=text, set=_set(item["set"], at, error, k), after=float(after),
                where=at(item), source="plc", condition=condition)


def parse_plc(doc, at, limit: int, error) -> CellPlc | None:
    """The ``plc:`` of a cell file's document `doc` (None without one); `at(obj, key)`: file:line;
    at most `limit` rules; `error`: the exception class raised."""
    body = doc.get("plc")
    if body is None:
        return None
    if not isinstance(body, dict):
        raise error(f"{at(doc, 'plc')}: 'plc' is a mapping with 'rules'")
    bad = [key for key in body if key not in _KEYS]
    if bad:
        raise error(f"{at(body, bad[0])}: unknown key {bad[0]!s} of the PLC (known: {', '.join(_KEYS)})")
    items = body.get("rules") or []
    if not isinstance(items, list):
        raise error(f"{at(body, 'rules')}: the PLC's 'rules' is a list of rules (when, after, set)")
    if len(items) > limit:
        raise error(f"{at(body, 'rules')}: {len(items)} PLC rules, more than the limit of {limit}")
    return CellPlc([_rule(item, at, error, k + 1) for k, item in enumerate(items)])
