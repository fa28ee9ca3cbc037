"""The UR5 kinematics agree with pybullet's model of the robot."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pybullet

from capabilities.robot.cell_file import CellConfig
from capabilities.robot.kinematics import UR5_JOINT_NAMES, UR5Kinematics
from capabilities.robot.robot_model import ROBOTS_DIR, find_ur5_urdf
from capabilities.sim.cell import SimCell
from capabilities.sim.robot_model import build_robot_urdf, robot_urdf_path
from capabilities.sim.testing import angle_between, distance
from engine.types import Pose


def _pybullet_flange_poses(cell: SimCell, configs: list[np.ndarray]) -> list[Pose]:
    """tool0 poses of a second copy of the robot, placed like the cell's, at each config."""
    base_link = cell.config.robot_base.compose(Pose((0, 0, 0), (0, 0, 1, 0)))

    def measure(client: int) -> list[Pose]:
        body = pybullet.loadURDF(
            str(robot_urdf_path()), base_link.position, base_link.orientation, useFixedBase=True,
            physicsClientId=client,
        )  # fmt: skip
        pybullet.setCollisionFilterGroupMask(body, -1, 0, 0, physicsClientId=client)
        names = {}
        for i in range(pybullet.getNumJoints(body, physicsClientId=client)):
            info = pybullet.getJointInfo(body, i, physicsClientId=client)
            names[info[1].decode()] = i
            names[info[12].decode()] = i
        poses = []
        for q in configs:
            for name, value in zip(UR5_JOINT_NAMES, q, strict=True):
                pybullet.resetJointState(body, names[name], float(value), physicsClientId=client)
            state = pybullet.getLinkState(
                body, names["tool0"], computeForwardKinematics=True, physicsClientId=client
            )
            poses.append(Pose(state[4], state[5]))
        pybullet.removeBody(body, physicsClientId=client)
        return poses

    return cell.call(measure)


def test_forward_kinematics_matches_pybullet_below_a_tenth_of_a_millimetre(cell: SimCell) -> None:
    rng = np.random.default_rng(7)
    configs = [rng.uniform(-math.pi, math.pi, 6) for _ in range(25)]
    measured = _pybullet_flange_poses(cell, configs)
    for q, pose in zip(configs, measured, strict=True):
        mine = cell.kinematics.forward(q)
        assert distance(mine, pose) < 1e-4
        assert angle_between(mine, pose) < math.radians(0.01)


def test_inverse_kinematics_round_trips_through_pybullet(cell: SimCell) -> None:
    rng = np.random.default_rng(11)
    configs = [rng.uniform(-math.pi, math.pi, 6) for _ in range(25)]
    measured = _pybullet_flange_poses(cell, configs)
    for q, pose in zip(configs, measured, strict=True):
        solution = cell.kinematics.inverse(pose, near=q)
        assert solution is not None
        assert np.allclose(solution, q, atol=1e-6)
        again = cell.kinematics.forward(solution)
        assert distance(again, pose) < 1e-4


def test_robot_state_agrees_with_pybullet_link_state(cell: SimCell) -> None:
    assert distance(cell.robot.flange_pose(), cell.ground_truth.flange_pose()) < 1e-4
    tcp = cell.robot.tcp_pose()
    expected = cell.robot.flange_pose().compose(cell.config.tcp_offsets["gripper"])
    assert distance(tcp, expected) < 1e-9


def test_inverse_kinematics_picks_the_solution_nearest_the_given_joints() -> None:
    kin = UR5Kinematics(CellConfig().robot_base)
    q = (0.3, -1.2, 1.4, -1.8, -1.5, 0.2)
    pose = kin.forward(q)
    shifted = (0.3 - 2 * math.pi, -1.2, 1.4, -1.8, -1.5, 0.2 - 2 * math.pi)
    solution = kin.inverse(pose, near=shifted)
    assert solution is not None
    assert np.allclose(solution, shifted, atol=1e-6)
    assert kin.inverse(Pose((3.0, 0.0, 0.5)), near=q) is None


def test_robot_urdf_has_resolved_meshes_and_the_gripper() -> None:
    text = build_robot_urdf(find_ur5_urdf(), "<fragment><link name='gripper_body'/></fragment>")
    assert "package://" not in text
    assert 'name="world"' not in text
    assert "gripper_body" in text


def test_the_light_robot_draws_its_links_with_converted_collision_meshes(tmp_path: Path) -> None:
    """The live view's light variant: every visual mesh replaced, joints and links the same."""
    full = robot_urdf_path(tmp_path)
    light = robot_urdf_path(tmp_path, light=True)
    assert light != full and ".dae" not in light.read_text()
    meshes = sorted((tmp_path / "ur5_light_meshes").glob("*.obj"))
    assert [m.stem for m in meshes] == sorted(
        ["base", "shoulder", "upperarm", "forearm", "wrist1", "wrist2", "wrist3"]
    )
    assert all("\nvn " in m.read_text() for m in meshes)  # normals: not drawn black
    client = pybullet.connect(pybullet.DIRECT)
    try:
        bodies = [pybullet.loadURDF(str(u), physicsClientId=client) for u in (full, light)]
        joints = [
            [pybullet.getJointInfo(b, i, physicsClientId=client)[1] for i in range(
                pybullet.getNumJoints(b, physicsClientId=client))]
            for b in bodies
        ]  # fmt: skip
        assert joints[0] == joints[1]
        shapes = pybullet.getVisualShapeData(bodies[1], physicsClientId=client)
        assert sum(s[4].endswith(b".obj") for s in shapes) == 7
    finally:
        pybullet.disconnect(client)


def _render(urdf: str) -> tuple[np.ndarray, np.ndarray]:
    """The UR5 of ``urdf`` bent at the elbow, seen from the side (RGB, depth buffer)."""
    client = pybullet.connect(pybullet.DIRECT)
    try:
        robot = pybullet.loadURDF(urdf, useFixedBase=True, physicsClientId=client)
        for joint, value in zip(range(1, 7), (0.3, -1.2, 1.5, -1.0, -1.57, 0.4), strict=True):
            pybullet.resetJointState(robot, joint, value, physicsClientId=client)
        view = pybullet.computeViewMatrix([1.2, 0.8, 0.9], [0, 0, 0.4], [0, 0, 1])
        projection = pybullet.computeProjectionMatrixFOV(50, 4 / 3, 0.1, 5)
        _, _, rgb, depth, _ = pybullet.getCameraImage(
            320, 240, view, projection, renderer=pybullet.ER_TINY_RENDERER,
            flags=pybullet.ER_NO_SEGMENTATION_MASK, physicsClientId=client,
        )  # fmt: skip
        return np.asarray(rgb, np.uint8).reshape(240, 320, 4), np.asarray(depth).reshape(240, 320)
    finally:
        pybullet.disconnect(client)


def test_the_robot_draws_its_collada_meshes_converted_to_obj_pixel_for_pixel(
    tmp_path: Path,
) -> None:
    """The visual meshes converted to OBJ files (a tenth of the COLLADA files' load time)
    draw the arm the same to the pixel; the physics cell draws them thinned to a tenth of
    their triangles, and a camera sees the same arm but for a few pixels at its edges.
    """
    converted = robot_urdf_path(tmp_path)
    assert ".dae" not in converted.read_text()
    thinned = sorted((tmp_path / "ur5_visual_meshes").glob("*_thinned*.obj"))
    assert len(thinned) == 7 and all(str(obj) in converted.read_text() for obj in thinned)
    fragment = (ROBOTS_DIR / "parallel_gripper.urdf.xml").read_text(encoding="utf-8")
    full = {
        obj.stem.split("_")[0]: obj
        for obj in (tmp_path / "ur5_visual_meshes").glob("*.obj")
        if "_thinned" not in obj.name
    }
    assert len(full) == 7
    whole, collada = tmp_path / "whole.urdf", tmp_path / "collada.urdf"
    whole.write_text(build_robot_urdf(find_ur5_urdf(), fragment, visual_objs=full), "utf-8")
    collada.write_text(build_robot_urdf(find_ur5_urdf(), fragment), encoding="utf-8")
    rgb, depth = _render(str(whole))
    rgb_collada, depth_collada = _render(str(collada))
    assert (depth < 1.0).mean() > 0.05  # the arm is in view
    assert np.array_equal(rgb, rgb_collada)
    assert np.allclose(depth, depth_collada, atol=1e-6)

    rgb_thin, depth_thin = _render(str(converted))
    differ = np.abs(rgb_thin[:, :, :3].astype(int) - rgb[:, :, :3].astype(int)).max(axis=2) > 30
    assert differ.mean() < 0.005, differ.mean()  # a few pixels at the silhouette
    assert ((depth_thin < 1.0) != (depth < 1.0)).mean() < 0.005
    assert robot_urdf_path(tmp_path) == converted  # converted once
