"""The kinematic families are declared once (issue 47): robot/kinematics/families.py registers each,
robot/kinematics/family.py declares the protocol. A registered family without one of its operations
fails here (as tests/frontend/test_visitor.py does for a pass without a node kind's handler), and
every family is shown at work on a robot of its own: detected from machine data (never a name),
its forward and inverse agreeing."""

from __future__ import annotations

import inspect
from pathlib import Path

import numpy as np
import pytest

from robot.kinematics import Kinematics
from robot.kinematics.family import OPERATIONS, KinematicFamily
from robot.kinematics.families import FAMILIES
from robot.mada import load_robot
from robot.machine import ROBOT_LIBRARY, load_machine

#: A robot of each family: a library robot's name, "yaml" for the KR 6 R900 yaml, or a test's fixture
EXAMPLES = {"opw": "yaml", "palletizer4": "kr180_r3200_pa", "palletizer5": "kr180_r3200_pa5",
            "scara": "kr6_r500_z200", "numeric": "numeric_robot", "redundant": "iiwa_robot"}
#: a seven-axis arm's description (read in place: ../shared is test data)
IIWA = (Path(__file__).resolve().parents[2].parent / "shared" / "robots" / "descriptions" / "kuka_experimental"
        / "kuka_lbr_iiwa_support" / "urdf" / "lbr_iiwa_14_r820.urdf")


def missing_operations(cls: type) -> list[str]:
    """The operations of the protocol that `cls` does not implement (left abstract or absent)."""
    out = [op for op in OPERATIONS if not callable(getattr(cls, op, None))]
    out += sorted(getattr(cls, "__abstractmethods__", ()))
    return sorted(set(out))


def test_the_check_finds_a_family_without_an_operation():
    """The completeness check itself: a family that lacks inverse_many (or anything else) is named."""
    class Incomplete(KinematicFamily):
        name = "incomplete"

        @classmethod
        def geometry(cls, values, source, prov, a4fix, a5link):
            return None

        @classmethod
        def detect(cls, kin):
            return None

        def forward(self, a):
            return np.eye(4)

        def forward_many(self, A):
            return np.zeros((len(A), 4, 4))

        def solutions(self, T, ref):
            return []

        def status_turn(self, q):
            return 0, 0

        def inverse(self, T, status, turn, ref):
            return np.zeros(4)

    assert missing_operations(Incomplete) == ["inverse_many"]
    with pytest.raises(TypeError):
        Incomplete(None)


@pytest.mark.parametrize("fam", FAMILIES, ids=lambda f: f.name)
def test_every_registered_family_has_every_operation(fam):
    assert issubclass(fam, KinematicFamily)
    assert not missing_operations(fam), f"{fam.__name__} lacks {missing_operations(fam)}"
    assert not inspect.isabstract(fam)
    assert fam.name and fam.title and fam.name in EXAMPLES, f"{fam.__name__}: its name, title and example robot"


def test_the_names_are_unique_and_the_registry_the_one_list():
    names = [f.name for f in FAMILIES]
    assert len(names) == len(set(names))
    # no module of robot/ outside the family modules tests a family by its name
    robot = Path(__file__).resolve().parents[2] / "robot"
    for path in robot.rglob("*.py"):
        if path.parent.name == "kinematics":
            continue
        text = path.read_text(encoding="utf-8")
        for name in names:
            assert f'family == "{name}"' not in text and f"family != \"{name}\"" not in text, (path, name)


@pytest.fixture()
def numeric_robot(tmp_path):
    """A six-axis arm no closed form covers: the library's KR 16-2 with a twisted $TX3P3 (as
    tests/robot/test_numeric_ik.py builds it)."""
    text = (ROBOT_LIBRARY / "kr16_2_krc2.dat").read_text(encoding="utf-8")
    old = "$TX3P3={X 670.000,Y 0.0,Z -35.0000,A 0.0,B 90.0000"
    assert old in text
    p = tmp_path / "$machine.dat"
    p.write_text(text.replace(old, "$TX3P3={X 670.000,Y 0.0,Z -35.0000,A 20.0,B 90.0000"), encoding="utf-8")
    return load_robot(str(p))


@pytest.fixture()
def iiwa_robot():
    """The seven-axis family's robot: KUKA's LBR iiwa 14 R820 as kuka_experimental describes it."""
    if not IIWA.exists():
        pytest.skip("../shared/robots/descriptions (kuka_lbr_iiwa_support) is not present")
    return load_robot(IIWA)


@pytest.mark.parametrize("fam", FAMILIES, ids=lambda f: f.name)
def test_each_family_is_detected_from_machine_data_and_solves(fam, request):
    example = EXAMPLES[fam.name]
    if example == "yaml":
        machine = load_machine()
    elif example in ("numeric_robot", "iiwa_robot"):
        machine = request.getfixturevalue(example)
    else:
        machine = load_robot(example)
    kin = Kinematics(machine)
    assert kin.family == fam.name and type(kin.impl) is fam
    rng = np.random.default_rng(49)
    home = np.array(machine.home_deg, dtype=float)
    solved = 0
    for _ in range(6 if fam.name in ("numeric", "redundant") else 40):   # the numeric solvers: 6
        q = home + rng.uniform(-15.0, 15.0, kin.n_axes)
        if machine.a4fix:
            q[3] = 0.0
        if machine.a5link:
            q[4] = home[4] + home[1] + home[2] - q[1] - q[2]
        q = np.clip(q, kin._lo, kin._hi)
        T = kin.forward(q)
        assert np.abs(kin.forward_many(q[None, :])[0] - T).max() < 1e-9
        s, t = kin.status_turn(q)
        got = kin.inverse(T, s, t, q)
        assert np.abs(kin.forward(got) - T).max() < 1e-6, (fam.name, q.tolist())
        many = kin.inverse_many(T[None], s, t, q)
        assert many.shape == (1, kin.n_axes) and np.abs(many[0] - got).max() < 1e-9
        assert any(np.abs(kin.forward(r) - T).max() < 1e-6 for r in kin.solutions(T))
        solved += 1
    assert solved
