"""Errors raised by the simulated KR C4 controller (reference §8.2).

Every error carries a KSS-style ``message`` text and an optional KSS message
``number`` (None where no public evidence for the number exists).
"""

from __future__ import annotations


class RobotError(Exception):
    """Base class of all controller errors.

    Attributes:
        message: KSS-style message text, e.g. ``"software limit switch -A2"``.
        number: KSS message number, or None when unknown (reference §8.2).
    """

    def __init__(self, message: str, number: int | None = None) -> None:
        super().__init__(message)
        self.message = message
        self.number = number

    def __str__(self) -> str:
        return self.message


class WorkspaceError(RobotError):
    """Cartesian target not reachable: the inverse kinematics has no solution
    (or none with the requested status S) (reference §8.2, "workspace error")."""


class SoftLimitError(RobotError):
    """An axis value lies outside ``$SOFTN_END``/``$SOFTP_END`` (reference §8.2).

    Attributes:
        axis: 1-based axis number (1 = A1).
        value_deg: the offending axis value in degrees.
        message: ``"software limit switch +A1"`` (above ``$SOFTP_END``) or
            ``"software limit switch -A2"`` (below ``$SOFTN_END``).
    """

    def __init__(self, axis: int, value_deg: float, positive: bool | None = None,
                 message: str | None = None, number: int | None = None) -> None:
        self.axis = int(axis)
        self.value_deg = float(value_deg)
        if positive is None:
            positive = self.value_deg > 0.0
        self.positive = bool(positive)
        if message is None:
            message = f"software limit switch {'+' if self.positive else '-'}A{self.axis}"
        super().__init__(message, number)
