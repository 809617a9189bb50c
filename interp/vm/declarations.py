"""The declarations of interp/vm/instructions.py's language (issue 76: out of that file, which
holds the instructions themselves): the decorators ``@inst``, ``macro`` and ``@inline`` (they
only mark a definition; interp/vm/gen_loop.py reads the text, nothing here runs in the VM), the
operand kinds :data:`KINDS` and :data:`INT_KINDS`, and the C types of the loop's locals and
arguments :data:`C_LOCALS`, :data:`C_ARGS` (interp/vm/loop.pxd is generated from them). The
generator reads the four tables from this file's text."""

from __future__ import annotations


def inst(effect: str = "", *, freq: int = 0, cold: bool = False, replaces: tuple = ()):
    """Declares an instruction (interp/vm/gen_loop.py reads the declaration from the text).
    ``replaces``: the sequence of instructions (defined above) that this one, with a handler of
    its own, replaces (the compiler's peephole fuses it as a macro's): its operands are theirs,
    concatenated, and its stack effect theirs."""
    return lambda fn: fn


def macro(*parts, freq: int = 0, errors_from: int | None = None, doc: str = ""):
    """Declares a superinstruction: ``parts`` in a row. ``errors_from``: the one part that can
    raise (the others cannot), so the compiler may fuse it across error regions, the fused
    instruction taking that part's region."""
    return parts


def inline(fn):
    """Declares a helper spliced into the handlers that call it (no call at run time)."""
    return fn


#: Operand kinds (the text of `krl asm`, the compiler's and the VM's forms: interp/vm/opcodes.py's
#: docstring). A kind with fields is linked as its object and then each field's value, so that
#: ``stmt.line`` is one tuple read in the loop (interp/vm/vm.py ``link``).
KINDS = {
    "i": (), "c": (), "n": (), "l": (), "h": (), "s": (), "v": (), "m": (), "g": (), "t": (), "f": (),
    "y": (), "r": (), "a": (), "p": (),
    "x": ("line", "stops", "cond_stops"),
    "o": ("op", "fn", "mask"),
    "k": ("name", "key"),
}

#: Kinds whose linked value is an integer the compiled loop holds in a C integer.
INT_KINDS = "svtimg"

#: The C types of the loop's locals and arguments (interp/vm/loop.pxd is generated from these;
#: the operands of INT_KINDS get C integers x1, x2, ... of their own). c1, c2, c3: an in-range
#: element index, a 2-D element's row, row length and column, two INTs a comparison compares.
C_LOCALS = {
    "prog": "list", "ins": "tuple", "op": "Py_ssize_t", "store": "list", "fvars": "list", "mrefs": "list",
    "grefs": "list", "cold": "list", "left": "Py_ssize_t", "unsaved": "Py_ssize_t", "proceed": "bint", "calm": "bint",
    "dirty": "bint", "go": "bint", "d": "list", "ops": "bytes", "adata": "list", "agrid": "list",
    "grid": "tuple", "c1": "Py_ssize_t", "c2": "Py_ssize_t", "c3": "Py_ssize_t",
}
C_ARGS = {"temps": "list", "ip": "Py_ssize_t", "stack": "list", "thunk": "bint"}
