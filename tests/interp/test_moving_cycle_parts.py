"""The per-call and per-cycle parts a moving cell runs most (issue 86): the INVERSE native's
structures (interp/runtime/sysvars.py ``axis_struct``, interp/runtime/convert.py ``frame_tuple``,
interp/runtime/natives/geometry.py ``_model_axes``, its kept START_AXIS ``_start_ref``), the timers' count (robot/io.py
``tick_timers``) and the reached-stimuli test (robot/signals.py ``reach_waits``), each against
values written here by hand."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from interp.runtime.convert import frame_tuple
from interp.runtime.natives.geometry import _model_axes, _start_ref
from interp.runtime.sysvars import axis_struct, struct_of
from interp.runtime.values import Struct
from robot.axismap import AxisMap
from robot.io import IOImage
from robot.signals import Signals
from robot.stimuli import Stimulus

AXES = ["A1", "A2", "A3", "A4", "A5", "A6", "E1", "E2", "E3", "E4", "E5", "E6"]


def test_axis_struct_gives_every_component_in_the_types_order_and_zeros_past_the_values():
    s = axis_struct(np.array([1.5, -0.0, 3.0, 4.0, 5.0, 6.25]))
    assert s.type is struct_of("E6AXIS", {}).type
    assert list(s.f) == AXES
    assert [math.copysign(1.0, v) for v in s.f.values()][:2] == [1.0, -1.0]     # -0.0 kept
    assert list(s.f.values()) == [1.5, 0.0, 3.0, 4.0, 5.0, 6.25] + [0.0] * 6
    s = axis_struct([1, 2, 3, 4, 5, 6, 7, 8])            # ints as REALs, E1 and E2 given
    assert list(s.f.items()) == list(zip(AXES, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 0.0, 0.0, 0.0, 0.0]))
    assert all(v.__class__ is float for v in s.f.values())
    assert list(axis_struct(list(range(14))).f.values()) == [float(i) for i in range(12)]


def test_frame_tuple_of_a_typed_value_and_of_one_that_lacks_components():
    pos = struct_of("E6POS", {"X": 1.0, "Y": 2.0, "Z": 3.0, "A": 4.0, "B": 5.0, "C": 6.0, "S": 2, "T": 10})
    assert frame_tuple(pos) == (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)
    assert frame_tuple(Struct(None, {"X": 7.0, "C": -1.0})) == (7.0, 0.0, 0.0, 0.0, 0.0, -1.0)
    assert frame_tuple(Struct(None, {"X": 7, "Y": 1.0})) == (7.0, 1.0, 0.0, 0.0, 0.0, 0.0)


def test_model_axes_reads_the_robot_axes_and_the_missing_ones_as_zero():
    ctl = SimpleNamespace(model=SimpleNamespace(axes=AxisMap(6, 0, (False,) * 6, (0.0,) * 6)))
    ax = axis_struct([10.0, -20.0, 30.0, 0.5, 90.0, -0.0])
    q = _model_axes(ctl, ax)
    assert q.tolist() == [10.0, -20.0, 30.0, 0.5, 90.0, 0.0] and math.copysign(1.0, q[5]) == -1.0
    assert _model_axes(ctl, Struct(None, {"A1": 1.0, "A2": 2.0, "A3": 3.0})).tolist() == [1.0, 2.0, 3.0, 0.0, 0.0, 0.0]


def test_inverse_keeps_start_axes_while_their_floats_are_the_same_objects():
    """``_start_ref``: the reference of one START_AXIS is made once (read-only) while its robot axes
    are the very float objects of the last call; another value, a new float of the same value, another
    model or an E6AXIS with a non-REAL axis make it anew or take the general path; a failed call's
    answer is a new E6AXIS each time, the axes of START and zeros past them."""
    amap = AxisMap(6, 0, (False,) * 6, (0.0,) * 6)
    ctl = SimpleNamespace(model=SimpleNamespace(axes=amap, to_krl=amap.to_krl))
    start = axis_struct([10.0, -20.0, 30.0, 0.0, 90.0, -0.0])
    ref, kept = _start_ref(ctl, start, None)
    assert kept is not None and kept.ref is ref
    assert ref.tolist() == [10.0, -20.0, 30.0, 0.0, 90.0, 0.0] and math.copysign(1.0, ref[5]) == -1.0
    assert not ref.flags.writeable
    again, same = _start_ref(ctl, Struct(start.type, dict(start.f)), None)      # the same floats: kept
    assert again is ref and same is kept
    a1, a2 = kept.answer_of(ctl), kept.answer_of(ctl)
    assert a1 is not a2 and a1.f is not a2.f and a1.type is start.type
    assert list(a1.f.values()) == [10.0, -20.0, 30.0, 0.0, 90.0, 0.0] + [0.0] * 6 == list(a2.f.values())
    a1.f["A1"] = 5.0
    assert kept.answer_of(ctl).f["A1"] == 10.0                                  # an answer shares nothing
    moved = Struct(start.type, dict(start.f))
    moved.f["A1"] = float("1" + "0.0")                                          # the same value, a new float
    new, other = _start_ref(ctl, moved, None)
    assert new is not ref and other is not kept and new.tolist() == ref.tolist()
    moved.f["A2"] = -25.0
    got, k2 = _start_ref(ctl, moved, None)
    assert got.tolist() == [10.0, -25.0, 30.0, 0.0, 90.0, 0.0] and k2.answer_of(ctl).f["A2"] == -25.0
    assert kept.answer_of(ctl).f["A2"] == -20.0                                 # an earlier START keeps its own
    ctl2 = SimpleNamespace(model=SimpleNamespace(axes=amap, to_krl=amap.to_krl))
    assert _start_ref(ctl2, moved, None)[0] is not got                          # another model
    ints = Struct(start.type, dict(start.f, A3=30))                             # an INT: the general path
    got, k3 = _start_ref(ctl, ints, None)
    assert k3 is None and got.tolist() == [10.0, -20.0, 30.0, 0.0, 90.0, 0.0] and got.flags.writeable


def test_tick_timers_counts_the_running_timers_only():
    io = IOImage()
    io.tick_timers(12)
    assert io.timer_ms[1:] == [0] * 64                  # all stopped
    for n in (1, 5, 64):
        io.set_timer_stop(n, False)
    io.tick_timers(12)
    io.tick_timers(12)
    assert [i for i, ms in enumerate(io.timer_ms) if ms] == [1, 5, 64]
    assert io.timer_ms[1] == io.timer_ms[5] == io.timer_ms[64] == 24
    io.set_timer_stop(5, True)
    io.tick_timers(12)
    assert (io.timer_ms[1], io.timer_ms[5], io.timer_ms[64]) == (36, 24, 36)


def test_reach_waits_only_for_a_stimulus_on_a_distance_not_yet_due():
    timed = Stimulus(set={"$IN[1]": True}, at=1.0)
    sig = Signals(IOImage(), [timed], [], None, 0.012)
    assert not sig.reach_waits()
    near = Stimulus(set={"$IN[2]": True}, motion=1, reached_mm=5.0)
    sig.stimuli.append(near)
    assert sig.reach_waits()
    near.due = 2.0                      # its distance reached, its delay runs
    assert not sig.reach_waits()
    near.due, near.fired = None, True
    assert not sig.reach_waits()
