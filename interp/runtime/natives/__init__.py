"""The simulator's system functions and procedures, declared once (issue 47): one module per
family, each routine declared with its KRL signature beside its implementation
(interp/runtime/natives/registry.py says how), and this list of the families.

**Adding a system function:** declare it in its family's module (``@FAMILY.native("REAL
NAME(REAL X :IN)")`` above ``def _name(ctx, args)``), then regenerate the front end's table
with ``python -m interp.runtime.natives.tables`` (krl/semantics/data/functions.yaml is made
from :data:`REGISTRY`; tests/interp/test_natives.py fails while it is stale). A new family is a
new module here and one line in :data:`FAMILIES`.

:data:`REGISTRY` maps each routine's upper-case name to its :class:`~.registry.Native`;
:data:`LINKS` each implemented one to its function ``fn(ctx, args)`` (ctx: context.py NativeContext). A run's workspace links
every call of a built-in to its function once, when the resolver places the call
(``Callee.native``, krl/semantics/resolve.py; interp/runtime/program.py passes :data:`LINKS`);
a routine with no function here (KRL of the BASIS, a stand-in) links to None: the stand-in
policy for KUKA's software (interp/runtime/kss.py).
"""

from __future__ import annotations

from .args import ValueRef
from .basis import BASIS
from .cast import CAST
from .eki import EKI
from .geometry import GEOMETRY
from .io import IO
from .krlmsg import MESSAGES
from .maths import MATHS
from .packages import FRI, KSS, SYSTEM_MODULES
from .registry import Native, build
from .rsi import RSI, RSI_CONSTANTS
from .strings import STRINGS
from .swrite import FORMATTED
from .system import SYSTEM
from .variables import VARIABLES

#: the families, in the order of the generated table: the one registration of a family module
FAMILIES = (MATHS, GEOMETRY, VARIABLES, STRINGS, MESSAGES, SYSTEM, CAST, FORMATTED, IO, KSS, BASIS,
            SYSTEM_MODULES, EKI, RSI, FRI)

REGISTRY: dict[str, Native] = build(FAMILIES)
LINKS: dict = {name: n.fn for name, n in REGISTRY.items() if n.fn is not None}

__all__ = ["FAMILIES", "LINKS", "REGISTRY", "RSI_CONSTANTS", "Native", "ValueRef"]
