# The C types of the generated dispatch loop's locals, for its Cython build (interp/vm/build.py;
# a .pxd beside a pure-Python module: loop.py itself stays plain Python, the fallback).
# ip and op are C integers (the dispatch compares them in C; op is read from ops, the code's
# opcodes as bytes, without a Python integer); the containers are known lists
# and tuples (indexing without a generic call); x1, x2, x3 hold a handler's slot numbers and
# in-range element indexes (y1, y2, y3: the row, row length and column of a 2-D element; y1, y2
# also two INTs compared in C) (list indexing by a C integer); proceed, dirty and go (a jump's
# condition) are C flags; d is an array's data (values.Arr: always a list; adata keeps them, agrid
# the (data, rows, columns) grid of each 2-D array), f a comparison's
# (operator, runtime function, mask) (vm._COMPARE).
# The module's names the handlers read (the runtime's constants, classes and functions) are C
# globals: no dictionary lookup per use.
import cython

@cython.locals(prog=list, ins=tuple, op=cython.Py_ssize_t, store=list, fvars=list, mrefs=list,
               grefs=list, cold=list, argc=cython.Py_ssize_t, left=cython.Py_ssize_t,
               unsaved=cython.Py_ssize_t,
               x1=cython.Py_ssize_t, x2=cython.Py_ssize_t, x3=cython.Py_ssize_t,
               y1=cython.Py_ssize_t, y2=cython.Py_ssize_t, y3=cython.Py_ssize_t, proceed=cython.bint, dirty=cython.bint,
               go=cython.bint, d=list, f=tuple, ops=bytes, adata=list, agrid=list, grid=tuple)
cpdef object run(object self, object code, object frame, list temps=*, Py_ssize_t ip=*, list stack=*, bint thunk=*)

cdef object UNSET, Struct, Slot, ValueRef, T_BOOL, T_INT, T_REAL
cdef object _load, _store, _element, _element1, _element2, _set_element, _set_element1, _component
cdef object _set_component, _add, _sub, _mul, _lt, _le, _gt, _ge, _eq, _ne, _for_next, _for_limits
cdef object _read_value, _array_index
