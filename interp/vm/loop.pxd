# The C types of the generated dispatch loop's locals, for its Cython build (interp/vm/build.py;
# a .pxd beside a pure-Python module: loop.py itself stays plain Python, the fallback).
# ip and op are C integers (the dispatch compares them in C); the containers are known lists
# and tuples (indexing without a generic call); x1, x2, x3 hold a handler's slot numbers and
# in-range element indexes (y1, y2, y3: the row, row length and column of a 2-D element) (list indexing by a C integer); proceed and dirty are C flags.
import cython

@cython.locals(prog=list, ins=tuple, op=cython.Py_ssize_t, store=list, fvars=list, mrefs=list,
               grefs=list, cold=list, argc=cython.Py_ssize_t, left=cython.Py_ssize_t,
               unsaved=cython.Py_ssize_t,
               x1=cython.Py_ssize_t, x2=cython.Py_ssize_t, x3=cython.Py_ssize_t,
               y1=cython.Py_ssize_t, y2=cython.Py_ssize_t, y3=cython.Py_ssize_t, proceed=cython.bint, dirty=cython.bint)
cpdef object run(object self, object code, object frame, list temps, Py_ssize_t ip, list stack, bint thunk=*)
