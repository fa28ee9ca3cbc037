"""A cell-neutral model of the UR5's body: capsules per link at given joint positions.

Used to tell the robot apart from what stands around it (occupancy masks the points of its
own arm out of a point cloud). The link frames follow the UR5 URDF (example-robot-data's
``ur5_robot.urdf``, the same kinematics as the UR5 CB3 controller and ur_analytic_ik); each
link carries one capsule (a segment in the link frame and a radius) that encloses the
link's collision mesh; the tool is a capsule from the flange to a little beyond the TCP.

Frames: ``base`` is the world pose of the UR controller's base frame (what the teach pendant
calls "base", and what ``CellConfig.robot_base`` configures); the URDF's ``base_link`` is
that frame turned 180 degrees about z.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from capabilities.errors import CapabilityError
from capabilities.geometry import matrix_to_pose, pose_to_matrix
from engine.types import Pose

__all__ = [
    "Capsule",
    "LINK_NAMES",
    "RobotBody",
    "RobotBodyError",
    "pose_matrix",
    "matrix_pose",
    "robot_base_from_arm",
]

LINK_NAMES = (
    "base_link",
    "shoulder_link",
    "upper_arm_link",
    "forearm_link",
    "wrist_1_link",
    "wrist_2_link",
    "wrist_3_link",
    "tool0",
)
_HALF_PI = math.pi / 2

# (parent -> child origin xyz, rpy) of the revolute joints, each turning about its child's z
# axis, then wrist_3 -> tool0 (fixed), as in the URDF.
_JOINT_ORIGINS: tuple[tuple[tuple[float, float, float], tuple[float, float, float]], ...] = (
    ((0.0, 0.0, 0.089159), (0.0, 0.0, 0.0)),
    ((0.0, 0.13585, 0.0), (0.0, _HALF_PI, 0.0)),
    ((0.0, -0.1197, 0.425), (0.0, 0.0, 0.0)),
    ((0.0, 0.0, 0.39225), (0.0, _HALF_PI, 0.0)),
    ((0.0, 0.093, 0.0), (0.0, 0.0, 0.0)),
    ((0.0, 0.0, 0.09465), (0.0, 0.0, 0.0)),
)
# wrist_1 and wrist_3 turn about their y axis in the URDF (axis 0 1 0); the others about z.
_JOINT_AXES = ("z", "y", "y", "y", "z", "y")
_TOOL0_ORIGIN = ((0.0, 0.0823, 0.0), (-_HALF_PI, 0.0, 0.0))

# One capsule per link: (link index in LINK_NAMES, end a, end b (link frame), radius). The
# radii are the largest distance of a collision-mesh vertex from the segment, rounded up;
# tests/capabilities/occupancy/test_robot_body.py checks that they enclose the simulated arm.
_LINK_CAPSULES: tuple[tuple[int, tuple[float, ...], tuple[float, ...], float], ...] = (
    (0, (0.0, 0.0, 0.009), (0.0, -0.035, 0.009), 0.077),
    (1, (0.0, -0.01, 0.0), (0.0, 0.02, 0.0), 0.089),
    (2, (0.0, 0.0, 0.0), (0.0, 0.0, 0.425), 0.090),
    (3, (0.0, 0.0, 0.0), (0.0, 0.0, 0.39225), 0.082),
    (4, (0.0, 0.093, -0.02), (0.0, 0.093, 0.01), 0.061),
    (5, (0.0, -0.02, 0.09465), (0.0, 0.01, 0.09465), 0.061),
    (6, (0.0, 0.05, 0.0), (0.0, 0.08, 0.0), 0.045),
)


pose_matrix = pose_to_matrix  # 4x4 matrix of a pose


def matrix_pose(m: np.ndarray) -> Pose:
    """The pose of a 4x4 homogeneous matrix (rotation part orthonormal)."""
    return matrix_to_pose(m, project=False)


class RobotBodyError(CapabilityError):
    """The robot's body cannot be placed (unknown base pose, bad joints)."""


@dataclass(frozen=True)
class Capsule:
    """All points within ``radius`` of the segment from ``a`` to ``b`` (world, m)."""

    a: np.ndarray
    b: np.ndarray
    radius: float
    link: str

    def distance(self, points: np.ndarray) -> np.ndarray:
        """Signed distance of Nx3 points from the capsule's surface (negative inside)."""
        ab = self.b - self.a
        denom = float(ab @ ab)
        t = (
            np.zeros(len(points))
            if denom < 1e-12
            else np.clip((points - self.a) @ ab / denom, 0, 1)
        )
        closest = self.a + t[:, None] * ab
        return np.linalg.norm(points - closest, axis=1) - self.radius


def _rpy(xyz: Sequence[float], rpy: Sequence[float]) -> np.ndarray:
    """A URDF origin (fixed-axis roll, pitch, yaw) as a 4x4 matrix."""
    cr, sr = math.cos(rpy[0]), math.sin(rpy[0])
    cp, sp = math.cos(rpy[1]), math.sin(rpy[1])
    cy, sy = math.cos(rpy[2]), math.sin(rpy[2])
    m = np.eye(4)
    m[:3, :3] = (
        np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
        @ np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
        @ np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    )
    m[:3, 3] = xyz
    return m


def _turn(axis: str, angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    m = np.eye(4)
    if axis == "z":
        m[:2, :2] = [[c, -s], [s, c]]
    else:
        m[0, 0], m[0, 2], m[2, 0], m[2, 2] = c, s, -s, c
    return m


_ORIGINS = tuple(_rpy(xyz, rpy) for xyz, rpy in _JOINT_ORIGINS)
_TOOL0 = _rpy(*_TOOL0_ORIGIN)
_BASE_LINK_IN_BASE = _turn("z", math.pi)  # base_link is the UR base frame turned 180 deg


class RobotBody:
    """The UR5's links as capsules, placed by forward kinematics.

    Args:
        base: world pose of the UR controller's base frame.
        tool_radius: radius (m) of the tool's capsule (a parallel gripper is ~7 cm wide).
        tool_beyond_tcp: how far (m) the tool reaches past its TCP (fingertips).
    """

    def __init__(
        self, base: Pose, tool_radius: float = 0.07, tool_beyond_tcp: float = 0.02
    ) -> None:
        self.base = base
        self.tool_radius = tool_radius
        self.tool_beyond_tcp = tool_beyond_tcp
        self._base_link = pose_matrix(base) @ _BASE_LINK_IN_BASE

    def link_matrices(self, q: Sequence[float]) -> list[np.ndarray]:
        """World 4x4 matrices of the links in ``LINK_NAMES`` order for joints ``q`` (rad)."""
        values = [float(v) for v in q]
        if len(values) != 6 or not all(math.isfinite(v) for v in values):
            raise RobotBodyError(f"the UR5 needs 6 finite joint positions, got {list(q)}")
        frames = [self._base_link]
        m = self._base_link
        for origin, axis, angle in zip(_ORIGINS, _JOINT_AXES, values, strict=True):
            m = m @ origin @ _turn(axis, angle)
            frames.append(m)
        frames.append(m @ _TOOL0)
        return frames

    def link_poses(self, q: Sequence[float]) -> dict[str, Pose]:
        """World poses of the links by name."""
        return {
            name: matrix_pose(m) for name, m in zip(LINK_NAMES, self.link_matrices(q), strict=True)
        }

    def flange_pose(self, q: Sequence[float]) -> Pose:
        """World pose of tool0 (the flange)."""
        return matrix_pose(self.link_matrices(q)[-1])

    def capsules(
        self, q: Sequence[float], tcp_offset: Pose | None = None, inflate: float = 0.0
    ) -> list[Capsule]:
        """The body's capsules at joints ``q``, each ``inflate`` m fatter.

        Args:
            q: joint positions (rad), base to wrist.
            tcp_offset: the tool's TCP in the flange frame; None for a bare flange.
            inflate: added to every radius (a safety margin for masking).
        """
        frames = self.link_matrices(q)
        out = []
        for link, a, b, radius in _LINK_CAPSULES:
            m = frames[link]
            out.append(
                Capsule(
                    m[:3, :3] @ a + m[:3, 3],
                    m[:3, :3] @ b + m[:3, 3],
                    radius + inflate,
                    LINK_NAMES[link],
                )
            )
        if tcp_offset is not None:
            flange = frames[-1]
            tip = np.asarray(tcp_offset.position, dtype=float)
            length = float(np.linalg.norm(tip))
            if length > 1e-6:
                tip = tip * (length + self.tool_beyond_tcp) / length
            far = flange[:3, :3] @ tip + flange[:3, 3]
            out.append(Capsule(flange[:3, 3].copy(), far, self.tool_radius + inflate, "tool"))
        return out

    def contains(
        self,
        points: np.ndarray,
        q: Sequence[float],
        tcp_offset: Pose | None = None,
        inflate: float = 0.0,
    ) -> np.ndarray:
        """A boolean mask of the Nx3 world points inside the (inflated) body."""
        inside = np.zeros(len(points), dtype=bool)
        if len(points) == 0:
            return inside
        for capsule in self.capsules(q, tcp_offset, inflate):
            inside |= capsule.distance(points) <= 0.0
        return inside


def robot_base_from_arm(arm: Any, settings_base: Any = None) -> Pose:
    """Where the robot's base frame is in the world, as well as the cell can tell.

    In order: a configured pose (``settings_base``), the arm's own ``robot_base()``, or
    derived from the arm's forward kinematics (``forward_kinematics(q)`` with
    ``tcp_offset()``, or ``flange_pose()`` read at standing joints).

    Raises:
        RobotBodyError: none of those is there.
    """
    if isinstance(settings_base, Pose):
        return settings_base
    if callable(getattr(arm, "robot_base", None)):
        found = arm.robot_base()
        if isinstance(found, Pose):
            return found
    q = tuple(arm.joint_positions())
    bare = RobotBody(Pose())  # the base at the world origin: FK in the base frame
    in_base = bare.link_matrices(q)[-1]
    if callable(getattr(arm, "forward_kinematics", None)) and callable(
        getattr(arm, "tcp_offset", None)
    ):
        # forward_kinematics(q) is a pure function of q: no race with a moving arm.
        flange_world = pose_matrix(arm.forward_kinematics(q)) @ np.linalg.inv(
            pose_matrix(arm.tcp_offset())
        )
        return matrix_pose(flange_world @ np.linalg.inv(in_base))
    if callable(getattr(arm, "flange_pose", None)):
        for _ in range(20):
            flange_world = pose_matrix(arm.flange_pose())
            if tuple(arm.joint_positions()) == q:
                return matrix_pose(flange_world @ np.linalg.inv(in_base))
            q = tuple(arm.joint_positions())
            in_base = bare.link_matrices(q)[-1]
        raise RobotBodyError("the arm kept moving while its base pose was worked out")
    raise RobotBodyError(
        "cannot tell where the robot's base is: configure the setting 'robot_base'"
    )
