"""The bytecode VM (issue 7; docs/architecture.md, "Bytecode VM").

Pipeline, one file per stage: ``opcodes.py`` (the single opcode table) ->
``compiler.py`` (routine AST -> readable assembly text) -> ``assembler.py`` (text <-> code,
the disassembler) -> ``vm.py`` (one dispatch loop on the shared runtime,
interp/runtime). ``cli.py`` is `krl asm`; ``bench/`` the compute benchmark of `krl bench`.
"""

from .vm import VM

__all__ = ["VM"]
