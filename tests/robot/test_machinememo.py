"""robot/machinememo.py: what a robot model derives from its machine data is derived once per
machine object (issue 87: a run's start), read-only, and never shared between two machines;
the objects that hold a run's state (the Kinematics, its solver, its memo) stay each model's own."""

from __future__ import annotations

import gc
from dataclasses import replace

import numpy as np
import pytest

from robot import machinememo
from robot.kinematics import Kinematics
from robot.machine import library_robots, load_machine
from robot.mada import load_robot
from robot.machinememo import derived
from robot.robotmodel import RobotModel


def test_derived_once_per_machine_and_key():
    m = load_machine()
    other = replace(m, name="another")
    calls = []

    def build(tag):
        calls.append(tag)
        return (np.arange(3.0), tag)

    first = derived(m, "test key", lambda: build("m"))
    assert derived(m, "test key", lambda: build("again")) is first
    assert derived(other, "test key", lambda: build("other"))[1] == "other"
    assert derived(m, "another key", lambda: build("m2"))[1] == "m2"
    assert calls == ["m", "other", "m2"]
    with pytest.raises(ValueError):             # read-only: a write cannot reach another model
        first[0][0] = 1.0


def test_a_failed_build_is_not_kept():
    m = replace(load_machine(), name="failing")

    def fail():
        raise RuntimeError("no")
    with pytest.raises(RuntimeError):
        derived(m, "test failing", fail)
    assert derived(m, "test failing", lambda: "built") == "built"


def test_the_entry_goes_with_its_machine():
    m = replace(load_machine(), name="short-lived")
    derived(m, "test key", lambda: 1)
    ident = id(m)
    assert ident in machinememo._MEMO
    del m
    gc.collect()
    assert ident not in machinememo._MEMO or machinememo._MEMO[ident][0]() is not None


def test_a_second_kinematics_of_machine_data_skips_the_detection_and_solves_the_same(monkeypatch):
    """The kinematic family of machine data is found by solving sample poses of their chain (the
    costly part of a build): once per machine. The second Kinematics has a solver of its own and
    gives the first one's forward and inverse bit for bit."""
    machine = replace(load_robot(library_robots()["kr16_2_krc2"]), name="kr16 memo test")
    first = Kinematics(machine)
    assert first.family == "opw"
    detect = type(first.impl).detect
    seen = []
    monkeypatch.setattr(type(first.impl), "detect", classmethod(lambda cls, kin: seen.append(kin) or detect(kin)))
    second = Kinematics(machine)
    assert seen == []
    assert second.impl is not first.impl and second._fk_memo is not first._fk_memo
    assert second.joints is not first.joints and second.joints.origins is first.joints.origins
    rng = np.random.default_rng(87)
    for u in rng.uniform(0.1, 0.9, size=(16, 6)):
        q = first._lo + (first._hi - first._lo) * u
        T = first.forward(q)
        assert T.tobytes() == second.forward(q).tobytes()
        assert first.inverse(T, reference_deg=q).tobytes() == second.inverse(T, reference_deg=q).tobytes()
    # a machine that equals it but is another object is detected again
    Kinematics(replace(machine))
    assert len(seen) == 1


def test_robot_models_of_one_machine_keep_their_own_mode():
    m = load_machine()
    a, b = RobotModel(m, mode="T1"), RobotModel(m, mode="AUT")
    assert (a.mode, b.mode) == ("T1", "AUT")
    assert a.v_max is b.v_max and not a.v_max.flags.writeable
    assert a.kin is not b.kin


def test_an_object_without_weak_references_is_built_each_time():
    class Slotted:
        __slots__ = ()
    calls = []
    for _ in range(2):
        assert derived(Slotted(), "test key", lambda: calls.append(1) or "value") == "value"
    assert len(calls) == 2
