"""The UR5 body model: its kinematics agree with ur_analytic_ik and the simulated robot's URDF,
and its capsules enclose every surface point of the simulated arm and gripper.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pybullet
import pytest
from ur_analytic_ik import ur5

from capabilities.robot.kinematics import UR5_JOINT_NAMES, UR5Kinematics
from capabilities.robot_body import (
    LINK_NAMES,
    RobotBody,
    RobotBodyError,
    pose_matrix,
    robot_base_from_arm,
)
from capabilities.sim.robot_model import robot_urdf_path
from engine.types import Pose

BASE = Pose((0.1, -0.2, 0.05), (0.0, 0.0, 1.0, 0.0))  # turned 180 deg like the sim cell's
GRIPPER_TCP = Pose((0.0, 0.0, 0.145))


@pytest.fixture(scope="module")
def robot_client() -> Iterator[tuple[int, int, dict[str, int]]]:
    """A private pybullet client holding only the simulated cell's robot URDF."""
    client = pybullet.connect(pybullet.DIRECT)
    base_link = BASE.compose(Pose((0, 0, 0), (0, 0, 1, 0)))
    body = pybullet.loadURDF(
        str(robot_urdf_path()), base_link.position, base_link.orientation, useFixedBase=True,
        physicsClientId=client,
    )  # fmt: skip
    index = {}
    for i in range(pybullet.getNumJoints(body, physicsClientId=client)):
        info = pybullet.getJointInfo(body, i, physicsClientId=client)
        index[info[1].decode()] = i
        index[info[12].decode()] = i
    yield client, body, index
    pybullet.disconnect(client)


def _set_joints(client: int, body: int, index: dict[str, int], q: np.ndarray) -> None:
    for name, value in zip(UR5_JOINT_NAMES, q, strict=True):
        pybullet.resetJointState(body, index[name], float(value), physicsClientId=client)
    for finger in ("left_finger_joint", "right_finger_joint"):
        pybullet.resetJointState(body, index[finger], 0.0425, physicsClientId=client)


def test_flange_matches_ur_analytic_ik() -> None:
    rng = np.random.default_rng(3)
    body = RobotBody(BASE)
    kin = UR5Kinematics(BASE)
    for _ in range(50):
        q = rng.uniform(-math.pi, math.pi, 6)
        mine = body.link_matrices(q)[-1]
        assert np.allclose(mine, kin.flange_matrix(q), atol=1e-9)
        assert np.allclose(
            RobotBody(Pose()).link_matrices(q)[-1], ur5.forward_kinematics(*q), atol=1e-9
        )


def test_every_link_frame_matches_the_sim_robot(
    robot_client: tuple[int, int, dict[str, int]],
) -> None:
    client, robot, index = robot_client
    body = RobotBody(BASE)
    rng = np.random.default_rng(5)
    for _ in range(20):
        q = rng.uniform(-math.pi, math.pi, 6)
        _set_joints(client, robot, index, q)
        poses = body.link_poses(q)
        for name in LINK_NAMES[1:]:
            state = pybullet.getLinkState(
                robot, index[name], computeForwardKinematics=True, physicsClientId=client
            )
            assert np.allclose(
                pose_matrix(poses[name]), pose_matrix(Pose(state[4], state[5])), atol=1e-6
            ), name


def _surface_points(
    client: int, robot: int, targets: np.ndarray, rng: np.random.Generator
) -> np.ndarray:
    """Points where rays from 1.5 m away, aimed near the link origins, hit the robot."""
    ends = targets[rng.integers(0, len(targets), 3000)] + rng.uniform(-0.1, 0.1, (3000, 3))
    starts = rng.normal(size=(3000, 3))
    starts = ends + 1.5 * starts / np.linalg.norm(starts, axis=1, keepdims=True)
    hits = pybullet.rayTestBatch(starts.tolist(), ends.tolist(), physicsClientId=client)
    return np.array([h[3] for h in hits if h[0] == robot])


def test_capsules_enclose_the_sim_robot_and_gripper(
    robot_client: tuple[int, int, dict[str, int]],
) -> None:
    client, robot, index = robot_client
    body = RobotBody(BASE)
    rng = np.random.default_rng(9)
    total = 0
    for _ in range(12):
        q = rng.uniform(-math.pi, math.pi, 6)
        q[2] = rng.uniform(-2.5, 2.5)  # an elbow folded onto itself is not a pose the arm takes
        _set_joints(client, robot, index, q)
        targets = np.array([pose.position for pose in body.link_poses(q).values()])
        points = _surface_points(client, robot, targets, rng)
        assert len(points) > 300
        inside = body.contains(points, q, GRIPPER_TCP, inflate=0.003)
        assert inside.all(), f"{(~inside).sum()} of {len(points)} surface points outside"
        total += len(points)
    assert total > 5000


def test_tool_capsule_reaches_past_the_tcp() -> None:
    body = RobotBody(BASE)
    q = (0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0)
    tcp = pose_matrix(body.flange_pose(q)) @ pose_matrix(GRIPPER_TCP)
    beyond = tcp[:3, :3] @ np.array([0.0, 0.0, 0.015]) + tcp[:3, 3]
    assert body.contains(beyond[None, :], q, GRIPPER_TCP).all()
    assert not body.contains(beyond[None, :], q, None).all()


class _ArmWithFk:
    def __init__(self, base: Pose) -> None:
        self._kin = UR5Kinematics(base)

    def joint_positions(self) -> tuple[float, ...]:
        return (0.3, -1.2, 1.4, -1.6, -1.5, 0.2)

    def tcp_offset(self) -> Pose:
        return GRIPPER_TCP

    def forward_kinematics(self, q: tuple[float, ...]) -> Pose:
        return self._kin.forward(q, GRIPPER_TCP)


class _ArmWithFlange(_ArmWithFk):
    def flange_pose(self) -> Pose:
        return self._kin.forward(self.joint_positions())

    forward_kinematics = None  # type: ignore[assignment]  # an arm without forward kinematics on purpose


def test_robot_base_is_found_from_the_arm_or_settings() -> None:
    for arm in (_ArmWithFk(BASE), _ArmWithFlange(BASE)):
        found = robot_base_from_arm(arm)
        assert np.allclose(pose_matrix(found), pose_matrix(BASE), atol=1e-9)
    assert robot_base_from_arm(object(), Pose((1, 2, 3))) == Pose((1, 2, 3))
    with pytest.raises(RobotBodyError, match="robot_base"):
        robot_base_from_arm(_NoFk())


class _NoFk:
    def joint_positions(self) -> tuple[float, ...]:
        return (0.0,) * 6


def test_bad_joints_are_refused() -> None:
    with pytest.raises(RobotBodyError, match="6 finite"):
        RobotBody(BASE).capsules((0.0, 1.0))
