"""The bytecode VM (issue 7): compiler (AST -> assembly text), assembler (text <-> code),
VM (one dispatch loop on the shared runtime). Pipeline: compiler.py -> assembler.py ->
vm.py; opcodes.py is the single opcode table."""

from .vm import VM

__all__ = ["VM"]
