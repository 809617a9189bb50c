"""Motion statements -> robot.motion.MotionRequest (reference §6.1-§6.3, §6.10).

* :func:`params_from` snapshots the motion system variables ($VEL, $ACC, $VEL_AXIS,
  $ACC_AXIS, $APO, $TOOL, $BASE, $ORI_TYPE, $CIRC_TYPE, $IPO_MODE, $OV_PRO, $LOAD, $LOAD_A3) at planning
  time (advance run);
* :func:`target_of` turns an evaluated target (a Struct: variable, aggregate, ``:`` chain,
  function result) into the request's component dict. Components that are not given —
  absent from a partial aggregate, or never assigned in a variable — are left out, so
  the controller takes them from the start position (absolute motions) or uses 0
  (``_REL``). A target with no component at all is "value invalid" (1422).
"""

from __future__ import annotations

from robot.axismap import ROBOT_KEYS
from robot.motion import MotionParams, MotionRequest, SplineSegment

from .convert import FRAME_KEYS, num, trunc_int
from .errors import KrlRuntimeError, value_invalid
from .values import UNSET, Struct
from dataclasses import replace
from operator import is_

TARGET_KEYS = ("X", "Y", "Z", "A", "B", "C", "S", "T", "A1", "A2", "A3", "A4", "A5", "A6",
               "E1", "E2", "E3", "E4", "E5", "E6")


def _enum_name(v, default: str) -> str:
    return getattr(v, "name", default) if v is not UNSET else default


def _f(v, default: float) -> float:
    return float(num(v)) if v is not UNSET else default


def _frame(s: Struct) -> tuple:
    return tuple(_f(s.f.get(k, 0.0), 0.0) for k in FRAME_KEYS)


frame_of = _frame     # a FRAME value as (X, Y, Z, A, B, C) mm/deg ($TOOL, $BASE)


#: the defaults of an unset value (a frozen MotionParams, made once)
_INITMOV = MotionParams()


class ParamsMemo:
    """The last snapshot :func:`params_from` made for one run, with the values it was made of
    (the objects themselves: :func:`_read`)."""

    __slots__ = ("raw", "params")

    def __init__(self) -> None:
        self.raw: tuple = ()
        self.params: MotionParams | None = None


def _read(store: dict) -> tuple:
    """Every value :func:`params_from` reads from `store` (without `link`), in one tuple: the
    value objects themselves, as the store holds them (:func:`_snapshot` makes the MotionParams
    of it: one list of what is read, for the snapshot and for its memo's key)."""
    n = len(ROBOT_KEYS)
    vel, acc, apo = store["$VEL"].f, store["$ACC"].f, store["$APO"].f
    tool, base = store["$TOOL"].f, store["$BASE"].f
    return (vel["CP"], vel["ORI1"], vel["ORI2"], acc["CP"], acc["ORI1"], acc["ORI2"],
            apo["CPTP"], apo["CDIS"], apo["CVEL"], apo["CORI"],
            *store["$VEL_AXIS"].data[:n], None, *store["$ACC_AXIS"].data[:n], None,
            *[tool.get(k, 0.0) for k in FRAME_KEYS], *[base.get(k, 0.0) for k in FRAME_KEYS],
            store["$ORI_TYPE"], store["$CIRC_TYPE"], store["$OV_PRO"], store["$IPO_MODE"],
            *_load_reads(store.get("$LOAD")), *_load_reads(store.get("$LOAD_A3")))


#: the leaves of a LOAD value in :func:`_read`'s order: M, CM's frame, J's X, Y, Z
_LOAD_LEAVES = 1 + len(FRAME_KEYS) + 3


def _load_reads(v) -> tuple:
    """The leaves of the LOAD value `v` (``$LOAD``, ``$LOAD_A3``): M, CM X..C, J X..Z, as stored
    (UNSET where not assigned; all UNSET when `v` is not a LOAD)."""
    if not isinstance(v, Struct):
        return (UNSET,) * _LOAD_LEAVES
    cm, j = v.f.get("CM"), v.f.get("J")
    cm_f = cm.f if isinstance(cm, Struct) else {}
    j_f = j.f if isinstance(j, Struct) else {}
    return (v.f.get("M", UNSET), *[cm_f.get(k, UNSET) for k in FRAME_KEYS], *[j_f.get(k, UNSET) for k in "XYZ"])


def _load_of(raw: tuple) -> tuple | None:
    """MotionParams.load of :func:`_load_reads`'s leaves: None when M is not set."""
    if raw[0] is UNSET:
        return None
    return tuple(_f(v, 0.0) for v in raw)


def _snapshot(raw: tuple) -> MotionParams:
    """The MotionParams of :func:`_read`'s tuple (unset values: the INITMOV defaults)."""
    d = _INITMOV
    vcp, vo1, vo2, acp, ao1, ao2, cptp, cdis, cvel, cori = raw[:10]
    i = raw.index(None, 10)                     # the end of $VEL_AXIS's A1..A6 (robot/axismap.py)
    j = raw.index(None, i + 1)                  # the end of $ACC_AXIS's
    va, aa = raw[10:i], raw[i + 1:j]
    k = len(FRAME_KEYS)
    tool, base = raw[j + 1:j + 1 + k], raw[j + 1 + k:j + 1 + 2 * k]
    ori, circ, ov, ipo = raw[j + 1 + 2 * k:j + 5 + 2 * k]
    loads = raw[j + 5 + 2 * k:]
    return MotionParams(
        vel_cp=_f(vcp, d.vel_cp), vel_ori1=_f(vo1, d.vel_ori1), vel_ori2=_f(vo2, d.vel_ori2),
        acc_cp=_f(acp, d.acc_cp), acc_ori1=_f(ao1, d.acc_ori1), acc_ori2=_f(ao2, d.acc_ori2),
        vel_axis=tuple(_f(v, 100.0) for v in va), acc_axis=tuple(_f(v, 100.0) for v in aa),
        apo_cptp=_f(cptp, d.apo_cptp), apo_cdis=_f(cdis, d.apo_cdis),
        apo_cvel=_f(cvel, d.apo_cvel), apo_cori=_f(cori, d.apo_cori),
        tool=tuple(_f(v, 0.0) for v in tool), base=tuple(_f(v, 0.0) for v in base),
        ori_type=_enum_name(ori, "VAR"), circ_type=_enum_name(circ, "BASE"),
        ov_pro=_f(ov, 100.0), ipo_mode=_enum_name(ipo, "BASE"),
        load=_load_of(loads[:_LOAD_LEAVES]), load_a3=_load_of(loads[_LOAD_LEAVES:]),
    )


def params_from(store: dict, link=None, memo: ParamsMemo | None = None) -> MotionParams:
    """A MotionParams snapshot of the system-variable store (unset values: INITMOV defaults);
    `link`: ``(system, root, offset)`` when ``$BASE`` is linked to a BASE kinematic (KSS ``EK``:
    interp/runtime/sysvars.py ``base_link``): the motion's base is then the offset on the
    kinematic's flange, which turns with its external axes.

    `memo` (a run's :class:`ParamsMemo`): when every value read is the very object the last
    snapshot was made of (``is``: a value is immutable, and the memo holds it, so its id is not
    reused), that snapshot is the answer (MotionParams is frozen); a program that sets no motion
    variable between its motions reads about 40 values instead of converting them and making a
    MotionParams (TopSquare's store: 24 -> 4 us a motion, 2026-11-26). Identity, not equality:
    -0.0 == 0.0. The snapshot and the memo's key are made of the same reads (:func:`_read`)."""
    if link is not None:
        return _linked(store, link)
    raw = _read(store)
    if memo is None:
        return _snapshot(raw)
    last = memo.raw
    if len(raw) == len(last) and all(map(is_, raw, last)):
        return memo.params
    memo.params = params = _snapshot(raw)
    memo.raw = raw
    return params


def _linked(store: dict, link) -> MotionParams:

    system, root, offset = link
    return replace(params_from(store), base=offset, base_kin=system, base_root=root)


def target_of(v, what: str = "motion target") -> dict:
    """Component dict of a motion target value (see the module docstring)."""
    if not isinstance(v, Struct):
        if v is UNSET:
            raise value_invalid(what)
        raise KrlRuntimeError(f"{what} is not a position: {v!r}")
    out = {}
    for k, x in v.f.items():
        if k not in TARGET_KEYS or x is UNSET:
            continue
        out[k] = trunc_int(x, k) if k in ("S", "T") else float(num(x))
    if not out:
        raise value_invalid(what)
    return out


def request(kind: str, target: dict, params: MotionParams, approx: list, aux=None, ca=None,
            frame: str | None = None, triggers=(), file=None, line=None) -> MotionRequest:
    """Build the MotionRequest of one motion statement."""
    a1 = approx[0] if approx else None
    a2 = approx[1] if len(approx) > 1 else None
    rel_frame = (frame or "#BASE").lstrip("#")
    return MotionRequest(kind, target, params, approx=a1, approx2=a2, aux=aux, ca=ca,
                         rel_frame=rel_frame, triggers=tuple(triggers), file=file, line=line)


def segment(kind: str, target: dict, aux=None, ca=None, params=None, triggers=(), line=None) -> SplineSegment:
    return SplineSegment(kind, target, aux, ca, params, tuple(triggers), line)
