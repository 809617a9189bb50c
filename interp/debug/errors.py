"""The debugger's refusal: a request that cannot be served (:class:`Refused`). Its own module so
that the engine (interp/debug/engine.py) and the launch configuration (interp/debug/launch.py),
which the engine reads when it launches, both raise it without importing each other."""

from __future__ import annotations


class Refused(Exception):
    """A request that cannot be served (its message is for the user)."""


__all__ = ["Refused"]
