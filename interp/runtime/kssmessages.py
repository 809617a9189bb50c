"""The KUKA messages (CrossMeld numbers) the simulated controller raises, with their texts and the
place that raises each: the texts ``krl log summary`` gives for a logbook's message numbers
(krl/logbook/summary.py; the logbook itself stores only the key, ``M_1422``). Each number is the
constant of the module that raises it, so this table cannot drift from the run."""

from __future__ import annotations

from krl.semantics.values import INTERRUPT_NOT_DECLARED, NOT_AVAILABLE, VALUE_INVALID

from .writerules import VALUE_INADMISSIBLE, WRITE_PROTECTED

__all__ = ["KNOWN_MESSAGES"]

#: KUKA message number -> (text, where the simulated controller raises it)
KNOWN_MESSAGES: dict[int, tuple[str, str]] = {
    VALUE_INVALID: ("value invalid", "krl/semantics/values.py VALUE_INVALID, reference §8.2"),
    INTERRUPT_NOT_DECLARED: ("interrupt not declared", "krl/semantics/values.py INTERRUPT_NOT_DECLARED, "
                             "raised by interp/runtime/contexts.py"),
    NOT_AVAILABLE: ("Object is not available", "krl/semantics/values.py NOT_AVAILABLE, raised by interp/runtime/natives/fctcall.py"),
    WRITE_PROTECTED: ("variable write-protected", "interp/runtime/writerules.py WRITE_PROTECTED"),
    VALUE_INADMISSIBLE: ("value assignment inadmissible", "interp/runtime/writerules.py VALUE_INADMISSIBLE"),
}
