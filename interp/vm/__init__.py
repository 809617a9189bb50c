"""The bytecode VM (issue 7; docs/architecture.md, "Bytecode VM").

Pipeline, one file per stage: ``opcodes.py`` (the single opcode table) ->
``compiler.py`` (routine AST -> instruction listing) -> ``assembler.py`` (listing -> code;
the readable text for `krl asm` and its round trip, never read at run time) -> ``vm.py`` (one dispatch loop on the shared runtime,
interp/runtime). ``gen_loop.py`` generates the dispatch loop ``loop.py`` from ``vm.py``;
``build.py`` compiles it with Cython (``make vm-loop``; loop.py is the pure-Python fallback).
``cli.py`` is `krl asm`; ``bench/`` the compute benchmark of `krl bench`.
"""

__all__ = ["VM"]


def __getattr__(name: str):
    # loaded on first use (PEP 562), so that `krl` commands that run no program stay quick
    if name == "VM":
        from .vm import VM  # noqa: PLC0415

        return VM
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
