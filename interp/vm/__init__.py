"""The bytecode VM (issue 7; docs/architecture.md, "Bytecode VM").

Pipeline, one file per stage: ``opcodes.py`` (the single opcode table) ->
``compiler.py`` (routine AST -> instruction listing) -> ``assembler.py`` (listing -> code;
the readable text for `krl asm` and its round trip, never read at run time) -> ``vm.py`` (one dispatch loop on the shared runtime,
interp/runtime). ``cli.py`` is `krl asm`; ``bench/`` the compute benchmark of `krl bench`.
"""

from .vm import VM

__all__ = ["VM"]
