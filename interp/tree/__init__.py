"""The tree interpreter: a visitor over the (annotated) AST on the shared runtime."""
from .interpreter import TreeInterpreter

__all__ = ["TreeInterpreter"]
