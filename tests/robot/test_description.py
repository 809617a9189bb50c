"""A robot description given to --robot (issue 64; robot/description.py): a xacro file of
ROS-Industrial's kuka_experimental (../shared/robots/descriptions, read in place) expanded by the
xacro package, parsed by yourdfpy, its meshes loaded by trimesh. The model's forward kinematics is
the description's own chain (computed here by tests/robot/test_catalogue.py's plain-numpy walk) and
the catalogue's model of the same robot; each link's mesh sits where the description puts it
(its bounding box at a random pose, MuJoCo's body against the description's chain); a description
that does not use KUKA's angles is refused naming the joint."""

from __future__ import annotations

import io

import mujoco
import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from robot.kinematics import Kinematics
from robot.mada import MachineDataError, catalogue_robot, load_robot
from robot.mjcf import ArmModel
from tests.robot.test_catalogue import DESCRIPTIONS, chain_forward, experimental_chain

KR150 = "kuka_kr150_support/urdf/kr150r3100_2.xacro"


@pytest.fixture(scope="module")
def kr150():
    if not DESCRIPTIONS.is_dir():
        pytest.skip("../shared/robots/descriptions is not present")
    return load_robot(DESCRIPTIONS / KR150)


def test_the_description_is_the_robot(kr150):
    chain = experimental_chain("kuka_kr150_support/urdf/kr150r3100_2_macro.xacro", "kuka_kr150r3100_2")
    cat = Kinematics(catalogue_robot("KR 150 R3100-2"))
    k = Kinematics(kr150)
    for q in np.random.default_rng(7).uniform(-100, 100, size=(20, 6)):
        np.testing.assert_allclose(k.forward(q), chain_forward(chain, q), atol=1e-6)
        np.testing.assert_allclose(k.forward(q), cat.forward(q), atol=1e-9)
    assert [j.limit_deg for j in kr150.joints][1] == pytest.approx((-140.0, -5.0))
    assert kr150.provenance["$TIRORO"].endswith("kr150r3100_2.xacro (joint origins at A = 0)")


def test_each_mesh_sits_where_the_description_puts_it(kr150):
    """The bounding box of each link's mesh at a random pose: the model's (MuJoCo's body, the mesh
    moved into its frame) against the original STL carried by the description's chain."""
    meshes = kr150.raw["meshes"]
    assert sorted(meshes) == ["base_link"] + [f"link_{i}" for i in range(1, 7)]
    arm = ArmModel(kr150)
    q = np.array([25.0, -70.0, 80.0, 40.0, -35.0, 60.0])
    arm.set_axes(q)
    chain = experimental_chain("kuka_kr150_support/urdf/kr150r3100_2_macro.xacro", "kuka_kr150r3100_2")
    joints = chain[0]
    # the description's link frames at q (m), from the chain's joints (origins then rotations)
    frames = [np.eye(4)]
    T = np.eye(4)
    for (xyz, rpy, axis), a in zip(joints, q):
        F = np.eye(4)
        F[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()
        F[:3, 3] = xyz
        J = np.eye(4)
        J[:3, :3] = Rotation.from_rotvec(np.asarray(axis) * np.radians(a)).as_matrix()
        T = T @ F @ J
        frames.append(T.copy())
    stl = DESCRIPTIONS / "kuka_kr150_support/meshes/kr150r3100_2/collision"
    for i, link in enumerate(["base_link"] + [f"link_{n}" for n in range(1, 7)]):
        original = trimesh.load(str(stl / f"{link}.stl"), force="mesh")
        original.apply_transform(frames[i])          # the collision origins of this description are identity
        ours = trimesh.load(io.BytesIO(meshes[link]), file_type="stl", force="mesh")
        b = arm.model.body(link).id
        M = np.eye(4)
        M[:3, :3] = arm.data.xmat[b].reshape(3, 3)
        M[:3, 3] = arm.data.xpos[b]
        ours.apply_transform(M)
        np.testing.assert_allclose(ours.bounds, original.bounds, atol=1e-6, err_msg=link)
    assert arm.model.nmesh == 7 and all(arm.model.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH for g in range(7))


def test_a_description_without_kukas_angles_is_refused():
    if not DESCRIPTIONS.is_dir():
        pytest.skip("../shared/robots/descriptions is not present")
    with pytest.raises(MachineDataError, match=r"kr210l150.xacro: joint 1 turns about \[0.0, 0.0, 1.0\].*not KUKA's"):
        load_robot(DESCRIPTIONS / "kuka_kr210_support/urdf/kr210l150.xacro")
