"""Time-parametrised arm trajectories: trapezoidal joint moves and straight-line tool moves.

A trajectory maps trajectory time (s) to joint positions and velocities. Stopping is done by
the controller slowing trajectory time down to zero, so a stopped move stays on its path (a
moveL stays on its line).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from capabilities.errors import CapabilityError
from capabilities.robot.kinematics import Joints, UR5Kinematics
from capabilities.sim.transforms import (
    matrix_to_pose,
    matrix_to_quat,
    pose_text_mm,
    quat_to_matrix,
    rotation_angle,
    slerp,
)

__all__ = [
    "CartesianTrajectory",
    "JointTrajectory",
    "LinearPathError",
    "Trapezoid",
    "plan_linear",
]

# Limits of a moveL's joint motion: the UR5's joint speed limit with some margin; a faster
# step means the IK jumped to another branch or the line passes near a singularity.
_MAX_JOINT_SPEED = 3.0
_ROT_SPEED = 1.0  # rad/s of tool rotation for a moveL (UR's default tool rotation speed order)
_ROT_ACCEL = 4.0


class LinearPathError(CapabilityError):
    """A straight-line move cannot be carried out (message says where and why)."""


@dataclass(frozen=True)
class Trapezoid:
    """A trapezoidal (or triangular) velocity profile over ``distance`` >= 0."""

    distance: float
    speed: float
    accel: float

    @property
    def _ramp(self) -> tuple[float, float]:
        """(peak speed, ramp time)."""
        peak = min(self.speed, math.sqrt(max(self.distance, 0.0) * self.accel))
        return peak, peak / self.accel

    @property
    def duration(self) -> float:
        """Total time of the profile (s)."""
        if self.distance <= 0:
            return 0.0
        peak, ramp = self._ramp
        return 2 * ramp + (self.distance - peak * ramp) / peak

    def at(self, t: float) -> tuple[float, float]:
        """(position, speed) along the profile at time ``t``."""
        total = self.duration
        if self.distance <= 0 or t >= total:
            return max(self.distance, 0.0), 0.0
        if t <= 0:
            return 0.0, 0.0
        peak, ramp = self._ramp
        if t < ramp:
            return 0.5 * self.accel * t * t, self.accel * t
        if t <= total - ramp:
            return 0.5 * peak * ramp + peak * (t - ramp), peak
        left = total - t
        return self.distance - 0.5 * self.accel * left * left, self.accel * left


def _progress(profiles: Sequence[Trapezoid]) -> tuple[Trapezoid, float]:
    """The profile that takes longest (it times the move) and its duration."""
    slowest = max(profiles, key=lambda p: p.duration)
    return slowest, slowest.duration


class JointTrajectory:
    """A synchronised joint move: every joint starts and ends together (moveJ)."""

    def __init__(self, q0: Joints, q1: Joints, speed: float, accel: float) -> None:
        self.q0 = np.asarray(q0, dtype=float)
        self.q1 = np.asarray(q1, dtype=float)
        self._delta = self.q1 - self.q0
        self._span = float(np.max(np.abs(self._delta))) if len(self._delta) else 0.0
        self._profile = Trapezoid(self._span, speed, accel)
        self.duration = self._profile.duration

    def sample(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Joint positions and velocities at trajectory time ``t``."""
        if self._span <= 0:
            return self.q1.copy(), np.zeros_like(self.q1)
        s, v = self._profile.at(t)
        unit = self._delta / self._span
        return self.q0 + unit * s, unit * v


class CartesianTrajectory:
    """A straight-line TCP move, solved to joints at every control step (moveL)."""

    def __init__(self, joints: np.ndarray, dt: float) -> None:
        self._q = joints
        self._dt = dt
        self.duration = (len(joints) - 1) * dt

    def sample(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """Joint positions (interpolated) and velocities at trajectory time ``t``."""
        last = len(self._q) - 1
        if last == 0 or t >= self.duration:
            return self._q[-1].copy(), np.zeros(6)
        x = max(t, 0.0) / self._dt
        i = min(int(x), last - 1)
        frac = x - i
        vel = (self._q[i + 1] - self._q[i]) / self._dt
        return self._q[i] + frac * (self._q[i + 1] - self._q[i]), vel


def plan_linear(
    kin: UR5Kinematics,
    q_start: Joints,
    tcp: np.ndarray,
    target: np.ndarray,
    speed: float,
    accel: float,
    dt: float,
) -> CartesianTrajectory:
    """Solve a straight-line move of the TCP from ``q_start`` to the world matrix ``target``.

    Position is interpolated linearly and orientation by slerp on one common time law; IK is
    solved at every control step, nearest to the previous step's joints.

    Raises:
        LinearPathError: a point on the line is unreachable, or consecutive points need a joint
            jump (branch flip, singularity).
    """
    start = kin.tcp_matrix(q_start, tcp)
    p0, p1 = start[:3, 3], target[:3, 3]
    r0, r1 = start[:3, :3], target[:3, :3]
    q0, q1 = matrix_to_quat(r0), matrix_to_quat(r1)
    lin = Trapezoid(float(np.linalg.norm(p1 - p0)), speed, accel)
    rot = Trapezoid(rotation_angle(r1 @ r0.T), _ROT_SPEED, _ROT_ACCEL)
    law, duration = _progress((lin, rot))
    steps = max(1, math.ceil(duration / dt))
    joints = np.empty((steps + 1, 6))
    joints[0] = np.asarray(q_start, dtype=float)
    point = np.eye(4)
    for k in range(1, steps + 1):
        u = 1.0 if law.distance <= 0 else law.at(k * dt)[0] / law.distance
        point[:3, 3] = p0 + u * (p1 - p0)
        point[:3, :3] = quat_to_matrix(slerp(q0, q1, u))
        sol = kin.nearest(point, tcp, joints[k - 1])
        if sol is None:
            raise LinearPathError(
                f"moveL path unreachable at {pose_text_mm(matrix_to_pose(point))}"
            )
        if float(np.max(np.abs(sol - joints[k - 1]))) > _MAX_JOINT_SPEED * dt:
            raise LinearPathError(
                "moveL needs a branch flip or passes a singularity near "
                f"{pose_text_mm(matrix_to_pose(point))}; use a joint move"
            )
        joints[k] = sol
    return CartesianTrajectory(joints, dt)
