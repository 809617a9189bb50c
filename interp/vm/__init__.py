"""The bytecode VM (issue 7; docs/architecture.md, "Bytecode VM").

Pipeline, one file per stage: ``opcodes.py`` (the single opcode table) ->
``compiler.py`` (routine AST -> instruction listing, from the front end's typed facts) ->
``vm.py`` (``link``: the listing's executed form, kept per checked workspace; ``Bound``: one
run's storage and call sites; one dispatch loop on the shared runtime, interp/runtime).
``assembler.py`` writes a listing as the readable text of `krl asm` (interp/asm.py) and reads
it back for the round-trip tests; no text is read at run time. ``gen_loop.py`` generates the
dispatch loop ``loop.py`` from ``vm.py``; ``build.py`` compiles it with Cython (``make
vm-loop``; loop.py is the pure-Python fallback). The compute benchmark of `krl bench` is
interp/bench.
"""

from .vm import VM

__all__ = ["VM"]
