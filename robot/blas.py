"""The BLAS numpy itself calls, for the compiled hot path (robot/build.py ``PURE``): the address of a
CBLAS function of the OpenBLAS a numpy wheel bundles (ILP64, exported as ``scipy_cblas_NAME64_``).
A compiled product that calls the same function with numpy's arguments gives numpy's ``@`` bit
for bit (OpenBLAS's kernels use fused multiply-adds, a plain C loop does not); its users check
that at set-up. Issue 39, "Simulator".

An address is found once per process and name (:func:`numpy_cblas` is memoised): numpy's library
does not move while the process lives, and looking for it (a listing of numpy's library folder,
a ``dlopen``) was 0.34 ms of CPU a call, two calls in every controller's build (issue 87)."""

from __future__ import annotations

import ctypes
import functools
import glob
import os

import numpy as np


@functools.cache
def numpy_cblas(name: str) -> int:
    """The address of numpy's bundled ``cblas_NAME`` (e.g. ``"dgemm"``, ``"dgemv"``), 0 when
    there is none at hand (a numpy built against another BLAS: the callers fall back to numpy);
    found at the first call for `name`, the same answer afterwards (module docstring)."""
    root = os.path.dirname(np.__file__)
    for lib in sorted(glob.glob(os.path.join(root, "..", "numpy.libs", "*openblas64*"))
                      + glob.glob(os.path.join(root, ".dylibs", "*openblas64*"))):
        try:
            return int(ctypes.cast(getattr(ctypes.CDLL(lib), f"scipy_cblas_{name}64_"), ctypes.c_void_p).value or 0)
        except (OSError, AttributeError):
            continue
    return 0
