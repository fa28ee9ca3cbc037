"""UR5 (CB3) kinematics in the world frame, on top of ur_analytic_ik.

ur_analytic_ik works in the UR controller's frames: ``base`` (the URDF's ``base`` link, which
is ``base_link`` turned 180 degrees about z) to ``tool0`` (the flange). Its FK matches the
URDF's base->tool0 chain to 1e-8 (checked by the tests against pybullet). This class adds the
robot's mounting (world pose of the UR base frame) and a TCP offset (tool pose in the flange
frame), picks the IK solution nearest to given joints, and checks joint limits.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from ur_analytic_ik import ur5

from capabilities.geometry import matrix_to_pose, pose_to_matrix, rotation_vector
from engine.types import Pose

__all__ = ["UR5Kinematics", "UR5_JOINT_LIMITS", "UR5_JOINT_NAMES", "Joints"]

Joints = Sequence[float] | np.ndarray

UR5_JOINT_NAMES = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
# The URDF's limits: +-2 pi on every joint but the elbow (+-pi).
UR5_JOINT_LIMITS: tuple[tuple[float, float], ...] = tuple(
    (-math.pi, math.pi) if name == "elbow_joint" else (-2 * math.pi, 2 * math.pi)
    for name in UR5_JOINT_NAMES
)
_TWO_PI = 2.0 * math.pi
_TURNS = np.array([0.0, -1.0, 1.0])  # extra turns tried per joint, in tie-break order


class UR5Kinematics:
    """Forward and inverse kinematics of a UR5 mounted at ``base`` (world pose of UR base).

    All poses are world-frame; ``tcp`` is the tool pose in the flange (tool0) frame.
    """

    def __init__(
        self, base: Pose, limits: Sequence[tuple[float, float]] = UR5_JOINT_LIMITS
    ) -> None:
        self.base = base
        self.limits = tuple(limits)
        self._base_m = pose_to_matrix(base)
        self._base_inv = np.linalg.inv(self._base_m)
        self._lo = np.array([lo for lo, _ in self.limits], dtype=float)[None, :, None]
        self._hi = np.array([hi for _, hi in self.limits], dtype=float)[None, :, None]

    def flange_matrix(self, q: Joints) -> np.ndarray:
        """World 4x4 matrix of tool0 for joints ``q``."""
        return self._base_m @ ur5.forward_kinematics(*[float(v) for v in q])

    def tcp_matrix(self, q: Joints, tcp: np.ndarray) -> np.ndarray:
        """World 4x4 matrix of the TCP (``tcp`` is the 4x4 offset in the flange frame)."""
        return self.flange_matrix(q) @ tcp

    def forward(self, q: Joints, tcp: Pose | None = None) -> Pose:
        """World pose of the TCP (the flange when ``tcp`` is None)."""
        m = self.flange_matrix(q)
        if tcp is not None:
            m = m @ pose_to_matrix(tcp)
        return matrix_to_pose(m, project=False)

    def within_limits(self, q: Joints) -> bool:
        """True when every joint is inside its limits."""
        return all(lo - 1e-9 <= v <= hi + 1e-9 for v, (lo, hi) in zip(q, self.limits, strict=True))

    def solutions(self, tcp_world: np.ndarray, tcp: np.ndarray) -> list[np.ndarray]:
        """All IK solutions (wrapped to [-pi, pi]) for a world TCP matrix."""
        flange_base = self._base_inv @ tcp_world @ np.linalg.inv(tcp)
        return [np.asarray(s, dtype=float) for s in ur5.inverse_kinematics(flange_base)]

    def nearest(self, tcp_world: np.ndarray, tcp: np.ndarray, near: Joints) -> np.ndarray | None:
        """The IK solution inside the limits closest to ``near`` (None when there is none).

        Each joint may be shifted by a multiple of 2 pi to come closest to ``near`` while
        staying inside its limits, since the UR joints turn more than one revolution.
        """
        found = self.solutions(tcp_world, tcp)
        if not found:
            return None
        sols = np.asarray(found, dtype=float).reshape(-1, 6)
        near_arr = np.asarray(near, dtype=float)
        sols = sols[np.all(np.isfinite(sols), axis=1)]
        # Numpy over every solution at once: a linear move solves this at each control step.
        # For each joint the turn nearest ``near``, then one less and one more (the order a
        # tie is broken in), and of those inside the limits the one closest to ``near``.
        k = np.round((near_arr - sols) / _TWO_PI)
        options = sols[:, :, None] + (k[:, :, None] + _TURNS) * _TWO_PI
        inside = (options >= self._lo - 1e-9) & (options <= self._hi + 1e-9)
        distance = np.where(inside, np.abs(options - near_arr[None, :, None]), np.inf)
        pick = np.argmin(distance, axis=2)
        ok = np.all(inside.any(axis=2), axis=1)
        if not ok.any():
            return None
        unwrapped = np.take_along_axis(options, pick[:, :, None], axis=2)[:, :, 0][ok]
        costs = np.sum((unwrapped - near_arr) ** 2, axis=1)
        return unwrapped[int(np.argmin(costs))].copy()

    def inverse(
        self, pose: Pose, near: Joints, tcp: Pose | None = None
    ) -> tuple[float, ...] | None:
        """Joints reaching world ``pose`` with the TCP, nearest to ``near``; None if unreachable."""
        tcp_m = pose_to_matrix(tcp) if tcp is not None else np.eye(4)
        sol = self.nearest(pose_to_matrix(pose), tcp_m, near)
        return None if sol is None else tuple(float(v) for v in sol)

    def jacobian(self, q: Joints, tcp: np.ndarray, eps: float = 1e-6) -> np.ndarray:
        """6x6 world-frame Jacobian of the TCP (rows: linear velocity, angular velocity)."""
        q0 = np.asarray(q, dtype=float)
        m0 = self.tcp_matrix(q0, tcp)
        jac = np.empty((6, 6))
        for j in range(6):
            dq = q0.copy()
            dq[j] += eps
            m1 = self.tcp_matrix(dq, tcp)
            jac[:3, j] = (m1[:3, 3] - m0[:3, 3]) / eps
            jac[3:, j] = rotation_vector(m1[:3, :3] @ m0[:3, :3].T) / eps
        return jac
