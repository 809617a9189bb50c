"""The palletizers' inverse in one compiled call (issue 86 item 1): what robot/kinematics/
palletizer4.py and palletizer5.py share, :class:`RowsFamily`.

A palletizer's candidate rows are a pure-Python-mode module's (pal4rows.py, pal5rows.py; compiled
where built, robot/build.py ``PURE``). Until 2026-11-28 only the rows were compiled: the status of
each row, the rows with the status and the choice among them ran in Python (robot/kinematics/
family.py ``select``), so the IPO cycle's inverse of a CP motion on a palletizer cost a Python call
chain per cycle, and robot/segments.py, robot/cartpath.py and robot/cartline.py, which run the
compiled inverse of the OPW arms (fastpath.py ``OPWCore``), ran their Python code for it.

Here the rows object is the rows source of an ``OPWCore`` of the palletizer's arm (fastpath.py
``OPWCore.use_rows``): its ``core`` gives the palletizer's rows, and its status (the OPW arm's:
robot/kinematics/opwsolver.py, which does not depend on ``c4``), its S/T filter and its choice
(fastpath's ``Chooser``, the limits and free bits of the family) are those ``select`` applies, in
the same order, so ``inverse``, ``inverse_rp`` and the compiled paths answer as ``select`` over the
family's ``solutions`` does, bit for bit, and None where it raises (the Python code then gives the
error). tests/robot/test_kinematics_compiled.py compares the two, and the run as Python.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import SoftLimitError, WorkspaceError
from . import compiled as _compiled
from .arm import ArmFamily
from .family import select_solutions

#: numpy's float64 (a reference and a flange pose that are float64 arrays are used as they stand)
_F64 = np.dtype(float)


class RowsFamily(ArmFamily):
    """An arm family whose rows are a pure-Python-mode module's (module docstring). A subclass
    gives :meth:`make_rows` (its rows object, on an OPW core it names) and ``solver`` (the
    robot/kinematics/opwsolver.py ``OPWSolver`` of its status)."""

    _rows: Any = None           # the rows object (made on first use)
    _rows_compiled = False      # whether it is the compiled module's
    _front: Any = None          # the OPWCore that solves with it (made on first use)
    _compiled_core: Any = None  # compiled()'s answer with USE_COMPILED on (made on first use)

    def make_rows(self, python: bool = False) -> tuple[Any, bool]:
        """(the rows object of this robot, whether it is the compiled module's): compiled where
        built and current, unless `python` (the module's .py on fastpath.py's OPW core as Python)."""
        raise NotImplementedError

    def rows_object(self) -> Any:
        """The rows object :meth:`solutions` asks (kept)."""
        rows = self._rows
        if rows is None:
            rows, self._rows_compiled = self.make_rows()
            self._rows = rows
        return rows

    def row_core(self, python: bool = False) -> Any:
        """fastpath.py's ``OPWCore`` of this robot's status, limits and free bits, solving with its
        rows (``use_rows``): compiled with the rows compiled (kept), or, with `python`, fastpath.py
        and the rows module as Python (a new one: the reference the compiled core is checked with)."""
        if python:
            rows, _ = self.make_rows(python=True)
            return self._core_on(rows, False)
        front = self._front
        if front is None:
            rows = self.rows_object()
            front = self._front = self._core_on(rows, self._rows_compiled)
        return front

    def _core_on(self, rows: Any, compiled: bool) -> Any:
        mod = _compiled._fastpath if compiled else _compiled._python_fastpath()
        core = mod.OPWCore(*self.solver._core_args)
        core.use_rows(rows)
        return core

    def compiled(self) -> Any:
        """The compiled ``OPWCore`` solving with the compiled rows (:meth:`row_core`), or False (not
        built, or a robot of other than six axes)."""
        if not _compiled.USE_COMPILED:
            return False
        got = self._compiled_core
        if got is None:             # (kept: the build, the rows and their core do not change)
            got = self._compiled_core = (self.kin.n_axes == 6 and _compiled.fastpath_compiled()
                                         and self._rows_compiled_core())
        return got

    def _rows_compiled_core(self) -> Any:
        core = self.row_core()
        return core if self._rows_compiled else False

    def compiled_core(self) -> Any:
        return self.compiled()

    def inverse(self, flange_T: np.ndarray, status: int | None, turn: int | None,
                ref: np.ndarray | None) -> np.ndarray:
        """``select`` over :meth:`solutions` (robot/kinematics/family.py ``select_solutions``): one call of
        the compiled core where built (the same axes, or the same error: :meth:`_raise_error`), the
        Python code where that does not decide or nothing is compiled."""
        c, q, ref = self._compiled_inverse(flange_T, status, turn, ref)
        if q is not None:
            return q
        if c:
            self._raise_error(c, status, turn, ref)
        return select_solutions(self, flange_T, status, turn, ref)

    def _compiled_inverse(self, flange_T: np.ndarray, status: int | None, turn: int | None,
                          ref: np.ndarray | None) -> tuple[Any, np.ndarray | None, np.ndarray]:
        """(the compiled core or None, its axes or None, the reference used: `ref`, else home)."""
        if ref is None:
            ref = self.kin._home.copy()
        c = self.compiled()
        if not c:
            return c, None, ref
        # float64 arrays as they stand (np.asarray's answer for them: INVERSE's 512 calls a point)
        if flange_T.__class__ is not np.ndarray or flange_T.dtype is not _F64:
            flange_T = np.asarray(flange_T, dtype=float)
        if ref.__class__ is not np.ndarray or ref.dtype is not _F64:
            ref = np.asarray(ref, dtype=float)
        return c, c.inverse(flange_T, status, turn, ref), ref

    def inverse_or_error(self, flange_T: np.ndarray, status: int | None, turn: int | None,
                         ref: np.ndarray | None) -> tuple[np.ndarray | None, type | None]:
        """robot/kinematics/family.py ``Family.inverse_or_error``: the compiled core's answer, its error's
        class (:meth:`_failure`: the error :meth:`inverse` raises) without making the error, the Python
        code where that does not decide."""
        c, q, ref = self._compiled_inverse(flange_T, status, turn, ref)
        if q is not None:
            return q, None
        if c:
            failed = self._failure(c, status, turn, ref, False)
            if failed is not None:
                return None, failed[0]
        return super().inverse_or_error(flange_T, status, turn, ref)

    def _failure(self, c: Any, status: int | None, turn: int | None, ref: np.ndarray,
                 texts: bool = True) -> tuple | None:
        """The error ``select`` raises where the compiled core `c` answered None, as (class, args,
        keywords) (the args and keywords only with `texts`), from what its ``solve`` left
        (``n_rows``, ``n_match``, the rows with the status in its registers): WorkspaceError without
        rows or without one of the status, SoftLimitError with the axis and value of fastpath's
        ``Chooser.limit_error``; None where the Python code decides (more rows than the core holds,
        no axis from ``limit_error``)."""
        if c.n_rows < 0:
            return None
        if c.n_rows == 0:
            return WorkspaceError, ("workspace error: target not reachable",), {}
        if c.n_match == 0:
            if not texts:
                return WorkspaceError, (), {}
            s_target = int(status) & 7 if status is not None else self.status_row(ref.tolist())[0]
            return WorkspaceError, (f"workspace error: target not reachable with status S={s_target}",), {}
        kin = self.kin
        got = c.limit_error(c.n_match, turn, kin._lo_l0, kin._hi_l0)
        if got is None:
            return None
        if not texts:
            return SoftLimitError, (), {}
        return SoftLimitError, (got[0] + 1, got[1]), {"positive": bool(got[1] > kin._hi[got[0]])}

    def _raise_error(self, c: Any, status: int | None, turn: int | None, ref: np.ndarray) -> None:
        """Raise the error ``select`` raises where the compiled core `c` answered None, from what
        its ``solve`` left (``n_rows``, ``n_match``, the rows with the status in its registers):
        WorkspaceError without rows or without one of the status, SoftLimitError with the axis
        and value of fastpath's ``Chooser.limit_error``; return where the Python code decides (more
        rows than the core holds, no axis from ``limit_error``). Raised here, never held in a
        local of the raising frame: a held exception and its traceback's frame make a reference
        cycle per failed call, and a status/turn search fails most of its calls (the garbage
        collector's passes made the search slower than the Python selection, measured)."""
        failed = self._failure(c, status, turn, ref)
        if failed is not None:
            raise failed[0](*failed[1], **failed[2])


__all__ = ["RowsFamily"]
