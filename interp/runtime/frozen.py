"""A program model's values frozen, and the copies a run takes of them (interp/runtime/model.py).

:func:`freeze` makes a value read-only in place (a Struct's components a read-only mapping, an
Arr's elements a tuple, each component and element too) and returns how to copy it: a function
of no arguments that makes a fresh value equal to ``values.copy_value`` of it (the same
classes, types, components in the same order, elements; a structure or array of its own at
every level), or None for a value that is its own copy (a scalar, an enum value, UNSET). The
function holds the frozen value's own components (the mapping a read-only view shows, which
nothing else reaches) and the copiers of its compound parts, so that a copy costs one dict
copy per structure and one list per array: no type test and no recursion through the value's
leaves, which ``copy_value`` pays at each copy.

:class:`StoreImage` is a frozen store (a data list's slots, the system variables by name) with
the copiers of its compound values: :meth:`StoreImage.copy` gives a run its own store in one
step.
"""

from __future__ import annotations

from types import MappingProxyType

from .values import Arr, Struct

_COMPOUND = (Struct, Arr)


def freeze(v):
    """Make `v` read-only in place (module docstring); returns its copier or None."""
    if isinstance(v, Struct):
        return _freeze_struct(v)
    if isinstance(v, Arr):
        return _freeze_arr(v)
    return None


def _freeze_struct(v: Struct):
    own = {}
    nested = []
    for k, x in v.f.items():
        make = freeze(x)
        own[k] = x
        if make is not None:
            nested.append((k, make))
    v.f = MappingProxyType(own)
    t, copy = v.type, own.copy
    if not nested:
        def make_flat():
            return Struct(t, copy())
        make_flat.flat = (t, own)
        return make_flat
    nested = tuple(nested)

    def make():
        f = copy()
        for k, mk in nested:
            f[k] = mk()
        return Struct(t, f)
    return make


def _freeze_arr(v: Arr):
    makers = [freeze(x) for x in v.data]
    data = v.data = tuple(v.data)
    t, dims = v.type, v.dims
    if not (data and isinstance(data[0], _COMPOUND)):
        # (values.copy_value looks at the first element only: a copy of the elements list)
        def make_list():
            return Arr(t, dims, list(data))
        return make_list
    flat = [getattr(mk, "flat", None) for mk in makers]
    if all(f is not None for f in flat):          # an array of structures of scalars
        pairs = tuple((st, own.copy) for st, own in flat)

        def make_structs():
            return Arr(t, dims, [Struct(st, copy()) for st, copy in pairs])
        return make_structs
    parts = tuple(mk if mk is not None else _same(x) for mk, x in zip(makers, data))

    def make():
        return Arr(t, dims, [mk() for mk in parts])
    return make


def _same(x):
    """A copier of a value that is its own copy."""
    def make():
        return x
    return make


class StoreImage:
    """A frozen store and the copiers of its compound values: `store` a list (a data list's
    slots) or a dict (the system variables by name). ``values``: the frozen values, a tuple or
    a read-only mapping (what the model shows); :meth:`copy`: a run's own store."""

    __slots__ = ("values", "_own", "_compound")

    def __init__(self, store) -> None:
        if isinstance(store, dict):
            own = {}
            compound = []
            for k, v in store.items():
                make = freeze(v)
                own[k] = v
                if make is not None:
                    compound.append((k, make))
            self.values = MappingProxyType(own)
        else:
            compound = [(k, make) for k, make in enumerate(map(freeze, store)) if make is not None]
            own = self.values = tuple(store)
        self._own = own
        self._compound = tuple(compound)

    def copy(self):
        """A fresh store equal to a deep copy of the frozen one (values.copy_value of each value):
        a list or a dict, as the store was."""
        store = list(self._own) if self._own.__class__ is tuple else self._own.copy()
        for k, make in self._compound:
            store[k] = make()
        return store
