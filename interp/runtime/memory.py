"""Memory: storage locations (references) and call frames (reference §2.3, §2.5, §2.7).

A *reference* is what a name, an array element or a structure component denotes. Every
reference has ``type``, ``name`` (for messages), ``get()`` (the value; a Struct/Arr is
returned without copying; an unset leaf raises 1422), ``peek()`` (the raw value, possibly
UNSET) and ``set(value)`` (converts as an assignment, §3.9; structures and arrays are
written in place so that :OUT aliases stay valid).

* :class:`Slot` — a key in a dict (variables) or a position in a list (array elements) or
  a component dict (structure fields). :OUT parameters bind the callee's name to the
  caller's Slot, so writes go straight to the caller's variable, element or component.
* :class:`ProxyRef` — an element of a live system array ($IN, $OUT, $TIMER, ...).
* :class:`ComputedRef` — a live system variable ($POS_ACT, $AXIS_ACT, $DATE, ...).
* :class:`SignalRef` — a SIGNAL name: one bit (BOOL) or a group of bits (INT, LSB first).
* :class:`RowRef` — a row ``t[i,]`` of a 2-D CHAR array.

:class:`Frame` is one activation of a routine: its bindings (name -> reference), the
module it belongs to, its caller, and the interrupts it declared (removed on return).
"""

from __future__ import annotations

from krl.limits import MAX_DATA_ELEMENTS
from krl.semantics import types as T

from .convert import assign_into, convert_scalar
from .errors import KrlRuntimeError, ResourceError, value_invalid
from .values import UNSET, Arr, Struct, make_value
from .writerules import protected


class Ref:
    __slots__ = ()
    type = None
    name = "?"
    readonly = False

    def get(self):
        v = self.peek()
        if v is UNSET:
            raise value_invalid(self.name)
        return v

    def peek(self):  # pragma: no cover - abstract
        raise NotImplementedError

    def set(self, v) -> None:  # pragma: no cover - abstract
        raise NotImplementedError


class Slot(Ref):
    """The reference of one storage slot: the value ``c[k]`` of a container (a frame's or a
    data list's store, whose slots the front end numbered: krl/semantics/resolve.py
    ``LayoutSlot``; an array's ``data``; a structure's components). interp/runtime/slots.py
    holds the operations both interpreters apply on such references."""

    __slots__ = ("c", "k", "type", "name", "readonly", "on_write")

    def __init__(self, container, key, type_, name: str, readonly: bool = False, on_write=None) -> None:
        self.c = container
        self.k = key
        self.type = type_
        self.name = name
        self.readonly = readonly
        self.on_write = on_write

    def get(self):
        v = self.c[self.k]
        if v is UNSET:
            raise value_invalid(self.name)
        return v

    def peek(self):
        return self.c[self.k]

    def set(self, v) -> None:
        if self.readonly:
            raise protected(self.name)
        hook = self.on_write            # a system variable's write rules (writerules.WriteHook)
        cur = self.c[self.k]
        if isinstance(cur, (Struct, Arr)):
            if hook is not None:
                hook.before(self, v, False)
            if cur is not v:
                assign_into(cur, v)
        else:
            if self.type is not None:
                v = convert_scalar(v, self.type)
            if hook is not None:
                hook.before(self, v, True)
            self.c[self.k] = v
        if hook is not None and hook.after is not None:
            hook.after(self)


class LiveArray:
    """A 1-D system array whose elements live elsewhere (the I/O image: interp/runtime/sysvars.py
    makes ``$IN``, ``$OUT``, ``$TIMER`` ... as a :class:`ComputedRef` giving one); ``getter(i)`` and
    ``setter(i, v)`` take a 1-based index within ``size``."""

    is_live_array = True

    def __init__(self, name: str, size: int, type_, getter, setter=None) -> None:
        self.name = name
        self.size = size
        self.type = type_
        self.getter = getter
        self.setter = setter

    def get(self, i: int):
        return self.getter(i)

    def set(self, i: int, v) -> None:
        self.setter(i, v)


class ProxyRef(Ref):
    """Element ``index`` of a live array (:class:`LiveArray`)."""

    __slots__ = ("proxy", "index", "type", "name")

    def __init__(self, proxy, index: int, type_, name: str) -> None:
        self.proxy = proxy
        self.index = index
        self.type = type_
        self.name = name

    @property
    def readonly(self):
        return self.proxy.setter is None

    def peek(self):
        return self.proxy.get(self.index)

    def set(self, v) -> None:
        if self.proxy.setter is None:
            raise protected(self.name)
        self.proxy.set(self.index, convert_scalar(v, self.type))


class ComputedRef(Ref):
    __slots__ = ("getter", "setter", "type", "name")

    def __init__(self, getter, type_, name: str, setter=None) -> None:
        self.getter = getter
        self.setter = setter
        self.type = type_
        self.name = name

    @property
    def readonly(self):
        return self.setter is None

    def peek(self):
        return self.getter()

    def set(self, v) -> None:
        if self.setter is None:
            raise protected(self.name)
        self.setter(v)


class SignalRef(Ref):
    """``SIGNAL name $OUT[a] [TO $OUT[b]]``: BOOL for one bit, unsigned INT for a group."""

    __slots__ = ("proxy", "a", "b", "type", "name")

    def __init__(self, proxy, a: int, b: int | None, name: str) -> None:
        self.proxy = proxy
        self.a = a
        self.b = b
        self.name = name
        if proxy.type is T.REAL:
            self.type = T.REAL
        else:
            self.type = T.BOOL if b is None else T.INT

    @property
    def readonly(self):
        return self.proxy.setter is None

    def peek(self):
        if self.b is None:
            return self.proxy.get(self.a)
        v = 0
        for bit, n in enumerate(range(self.a, self.b + 1)):
            if self.proxy.get(n):
                v |= 1 << bit
        return v

    def set(self, v) -> None:
        if self.proxy.setter is None:
            raise protected(self.name)
        if self.b is None:
            self.proxy.set(self.a, convert_scalar(v, self.type))
            return
        v = convert_scalar(v, T.INT)
        for bit, n in enumerate(range(self.a, self.b + 1)):
            self.proxy.set(n, bool((v >> bit) & 1))


class RowRef(Ref):
    """Row ``i`` of a 2-D CHAR array (``NAMES[2,]``)."""

    __slots__ = ("arr", "row", "type", "name")

    def __init__(self, arr: Arr, row: int, name: str) -> None:
        if not 1 <= row <= arr.dims[0]:
            raise KrlRuntimeError(f"array index {row} outside 1..{arr.dims[0]} ({name})")
        self.arr = arr
        self.row = row
        self.name = name
        self.type = T.Array(T.CHAR, (arr.dims[1],))

    def _view(self) -> Arr:
        n = self.arr.dims[1]
        s = (self.row - 1) * n
        return Arr(self.type, (n,), self.arr.data[s:s + n])

    def peek(self):
        return self._view()

    def set(self, v) -> None:
        view = self._view()
        assign_into(view, v)
        n = self.arr.dims[1]
        s = (self.row - 1) * n
        self.arr.data[s:s + n] = view.data


def index_ref(base: Ref, idx: list, name: str) -> Ref:
    """The reference of ``base[idx]`` (``idx``: 1-based INTs; a trailing None selects a
    CHAR row, all None the whole array)."""
    if all(i is None for i in idx):
        return base
    v = base.peek()
    proxy = getattr(v, "is_live_array", False)
    if proxy:
        if len(idx) != 1 or idx[0] is None:
            raise KrlRuntimeError(f"{name}: one index expected")
        i = idx[0]
        if not 1 <= i <= v.size:
            raise KrlRuntimeError(f"array index {i} outside 1..{v.size} ({name})")
        return ProxyRef(v, i, v.type, f"{name}[{i}]")
    if not isinstance(v, Arr):
        if v is UNSET:
            raise value_invalid(base.name)
        raise KrlRuntimeError(f"{base.name} is not an array", name=base.name)
    if idx[-1] is None and len(idx) == 2 and len(v.dims) == 2:
        return RowRef(v, idx[0], f"{name}[{idx[0]},]")
    try:
        pos = v.flat(idx)
    except IndexError as exc:
        raise KrlRuntimeError(f"array index inadmissible: {name}[{','.join(map(str, idx))}] ({exc})") from None
    if isinstance(base, Slot):
        return Slot(v.data, pos, v.type.elem, f"{name}[{','.join(map(str, idx))}]", base.readonly, base.on_write)
    return Slot(v.data, pos, v.type.elem, f"{name}[{','.join(map(str, idx))}]")


def field_ref(base: Ref, comp: str, name: str, key: str | None = None) -> Ref:
    """The reference of component `comp` (as written: messages) of the structure `base` refers
    to; `key`: the component's key in the structure (the resolver's fact for an interpreter,
    krl/semantics/resolve.py Component; the upper-case spelling when not given: a tool's text)."""
    v = base.peek()
    if key is None:
        key = comp.upper()
    if not isinstance(v, Struct):
        if v is UNSET:
            raise value_invalid(base.name)
        raise KrlRuntimeError(f"{base.name} is not a structure")
    if key not in v.f:
        if v.type is not None and key in v.type.fields:
            v.f[key] = make_value(v.type.fields[key][1])
        else:
            raise KrlRuntimeError(f"{base.name} has no component {comp}")
    ft = v.type.fields[key][1] if v.type is not None and key in v.type.fields else None
    ro = base.readonly if isinstance(base, (Slot, ComputedRef)) else False
    return Slot(v.f, key, ft, f"{name}.{comp}", ro, base.on_write if isinstance(base, Slot) else None)


class Frame:
    """One activation of a routine.

    Attributes: routine (AST Routine), module (:class:`program.ModuleRT`), vars (frame slot ->
    Ref: the slots of the routine's Layout, krl/semantics/resolve.py: parameters, then
    locals; None until first asked for, :meth:`var`, for a variable the frame holds in its
    own store), store (frame slot -> the value of a variable the frame holds itself: a local
    or an :IN copy), layout, caller (Frame or None), depth, interrupts (numbers declared here,
    removed on return), task (the owning task), line (current line), data (the elements of
    the run's data memory it holds, given back on return), made (frame slot -> (type, name)
    of the Slot :meth:`var` makes for a slot whose ``vars`` entry is None; shared by every
    activation of the routine: interp/runtime/calls.py FramePlan).
    """

    __slots__ = ("routine", "module", "vars", "caller", "depth", "interrupts", "task", "line",
                 "store", "layout", "data", "made")

    def __init__(self, routine, module, caller: "Frame | None", task=None, layout=None,
                 store: list | None = None, vars_: list | None = None, made=None) -> None:
        self.routine = routine
        self.module = module
        self.layout = layout
        if store is None:
            n = len(layout.slots) if layout is not None else 0
            store, vars_ = [UNSET] * n, [None] * n
        self.vars: list = vars_
        self.store: list = store
        self.made = made
        self.caller = caller
        self.depth = caller.depth + 1 if caller is not None else 0
        self.interrupts: list[int] | tuple = ()     # a list once one is declared
        self.task = task
        self.line = 0
        self.data = 0       # elements of the run's data memory this activation holds (DataMemory)

    def var(self, k: int) -> Ref:
        """The reference of frame slot ``k``: made on first use (a Slot of the store) for a
        variable the frame holds itself, then kept, so every use sees the same Ref."""
        ref = self.vars[k]
        if ref is None:
            t, name = self.made[k]
            ref = self.vars[k] = Slot(self.store, k, t, name)
        return ref

    def ref(self, name: str) -> Ref | None:
        """The reference of the parameter or local `name` (any case), else None: for tools
        (VARSTATE's text, a debugger); the interpreters use each use's Storage slot."""
        k = self.layout.index(name) if self.layout is not None else None
        return self.var(k) if k is not None else None

    @property
    def name(self) -> str:
        return self.routine.name if self.routine is not None else "?"


class DataMemory:
    """The run's data memory (krl/limits.py MAX_DATA_ELEMENTS, counted by
    :func:`values.data_size`): data lists take their share when they are loaded, a routine
    call takes its locals and :IN copies when it is entered and gives them back when it
    returns. :meth:`take` checks before anything is allocated."""

    __slots__ = ("limit", "used")

    def __init__(self, limit: int | None = None) -> None:
        self.limit = MAX_DATA_ELEMENTS if limit is None else limit
        self.used = 0

    def take(self, n: int, name: str, file: str | None = None, line: int | None = None,
             what: str = "") -> int:
        """Reserve ``n`` elements for ``name`` (a `what` of it, e.g. "parameter": the message
        is put together only for its error); returns ``n``. Raises ResourceError "data memory
        exhausted" (at ``file``:``line`` when given) when they do not fit."""
        if self.used + n > self.limit:
            free = self.limit - self.used
            if what:
                name = f"{what} {name}"
            raise ResourceError(f"data memory exhausted: {name} needs {n} data elements, "
                                f"{free} of {self.limit} are free", None, file, line)
        self.used += n
        return n

    def give(self, n: int) -> None:
        self.used -= n
