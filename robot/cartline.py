"""A single LIN planned in C (issue 76: out of robot/planner.py): robot/cartpath.py ``plan_line``
gives the numbers of :func:`robot.cartplan.plan_cart` for a single LIN to a complete Cartesian
target, ``$ORI_TYPE #VAR``, outside T1, on a six-axis arm without external axes and
``$ROBROOT`` whose inverse is compiled; this module makes the segment of them."""

from __future__ import annotations

import numpy as np

from . import kinematics
from .cartlaw import CP_MAX_SAMPLES, CP_SAMPLE_STEP_DEG, SINGULAR_JUMP_DEG, cp_speeds
from .errors import RobotError
from .kinematics.compiled import COMPILED_AXES
from .motion import AXIS_KEYS, CART_KEYS, MotionRequest
from .pathpieces import LinePiece
from .planmemo import _inverse_of
from .profiles import Trapezoid
from .robotmodel import MIN_CHAIN, RobotModel
from .segments import CartSegment, _frames_gemm, _line_blas

_CART_SET = frozenset(CART_KEYS)


def _planned_line(req: MotionRequest, q0: np.ndarray, start_T: np.ndarray, tool_T: np.ndarray,
                  base_T: np.ndarray, model: RobotModel) -> CartSegment | None:
    """:func:`robot.cartplan.plan_cart` of a single LIN to a complete Cartesian target, ``$ORI_TYPE #VAR``,
    outside T1, on a six-axis arm without external axes and ``$ROBROOT`` whose inverse is compiled:
    the numbers in C (robot/cartpath.py ``plan_line``: the same operations in the same order,
    numpy's products and dot products through its BLAS, checked once a process by
    :func:`_line_blas`), the segment made here with the attributes ``CartSegment.__init__`` and
    :func:`robot.cartplan.plan_cart` give it, the same values bit for bit (tests/robot/test_simcore.py compares
    the two attribute by attribute). None where ``plan_line`` leaves the plan to the Python code
    (an orientation that turns along the line, a zero length, a walk it does not mirror) or
    anything above does not hold: :func:`robot.cartplan.plan_cart` plans it (and raises its errors)."""
    p = req.params
    t = req.target
    if (req.relative or p.ori_type != "VAR" or model.mode == "T1" or type(model) is not RobotModel
            or model.n_ext or not model._robroot_is_null or len(q0) != COMPILED_AXES
            or model.n != COMPILED_AXES or not t.keys() >= _CART_SET or not t.keys().isdisjoint(AXIS_KEYS)):
        return None
    sc = kinematics.compiled_module()
    opw = model.kin.compiled_core() if sc is not None else None
    blas = _line_blas(sc) if opw else None
    if blas is None:
        return None
    tool_inv, _, tool_null = _inverse_of(tool_T)
    base_inv, base_null, _ = _inverse_of(base_T)
    tool_inv_T, base_inv_T = tool_inv.copy(), base_inv.copy()
    ik_tool = None if tool_null else tool_inv_T
    ik_base = None if base_null else base_T
    framed = ik_tool is not None or ik_base is not None
    if framed and not _frames_gemm(sc):
        return None
    try:
        v_cp, v_ori, a_cp, a_ori = cp_speeds(p, model.mode)
    except RobotError:
        return None
    status = model.status_turn(q0)[0]
    got = sc.plan_line(opw, blas[0], blas[1], start_T, *[float(t[k]) for k in CART_KEYS], v_cp, v_ori, a_cp,
                       a_ori, status, q0, MIN_CHAIN if model.batch_ik else CP_MAX_SAMPLES + 1,
                       bool(getattr(model.machine, "ptp_ramp_deg", ())), model.v_max, model.a_max,
                       SINGULAR_JUMP_DEG, CP_SAMPLE_STEP_DEG, CP_MAX_SAMPLES, ik_base, ik_tool)
    if got is None:
        return None
    (p0, p1, direction, L, R0, R1, _theta, rv, still, w, u1, cp, q1, qd_start, qd_end, vel_peak, acc_peak,
     v_prog, vmax, amax) = got
    line = LinePiece.__new__(LinePiece)
    line.__dict__.update(p0=p0, p1=p1, length=L, dir=direction)
    rots = [R0, R1]
    seg = CartSegment.__new__(CartSegment)
    seg.__dict__.update(
        req=req, id=req.id, q0=q0, q1=q1, profile=Trapezoid.plan(vmax, amax), v_prog=v_prog, tool_T=tool_T,
        base_T=base_T, tool_inv_T=tool_inv_T, base_inv_T=base_inv_T, _ik_tool=ik_tool, _ik_base=ik_base,
        _c_ik=False if framed else opw, _c_path=cp, _c_framed=framed, model=model, status=status, triggers=[],
        limits=None, vel_peak=vel_peak, acc_peak=acc_peak, qd_start=qd_start, qd_end=qd_end, _last_q=q0.copy(),
        _end_frame=None, _ahead=None, e1=q0[model.n:].copy(), pieces=[line], rots=rots, ori=["VAR"],
        W=float(sum([w])), joint_ori=False, u_bounds=np.array([0.0, u1]), _ub=[0.0, u1], _lens=[L],
        lengths=np.array([L]), _sb=[0.0, L], s_bounds=np.array([0.0, L]), _R=rots, _rv=[rv], _R_still=[still],
        _path_end=None)
    return seg


__all__ = ["_planned_line"]
