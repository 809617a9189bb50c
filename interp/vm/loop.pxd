# The C types of the generated dispatch loop's locals, for its Cython build (interp/vm/build.py;
# a .pxd beside a pure-Python module: loop.py itself stays plain Python, the fallback).
# ip and op are C integers (the dispatch compares them in C); the containers are known lists
# and tuples (indexing without a generic call).
import cython

@cython.locals(prog=list, ins=tuple, op=cython.Py_ssize_t, store=list, fvars=list, mrefs=list,
               grefs=list, cold=list, argc=cython.Py_ssize_t, left=cython.Py_ssize_t,
               unsaved=cython.Py_ssize_t)
cpdef object run(object self, object code, object frame, list temps, Py_ssize_t ip, list stack, bint thunk=*)
