"""Freedrive (hand guiding) of the simulated arm; runs on the physics thread only.

The arm behaves as gravity-compensated, damped joints: a wrench at the TCP produces joint
torques J^T w, and each joint moves at torque / damping (an admittance: no sagging, no
drift, it stops when the push stops). A dragged target pose (the GUI's handle, or a test)
pulls the TCP towards it at a bounded speed through damped least squares.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from capabilities.robot.commands import CommandHandle
from capabilities.robot.kinematics import UR5Kinematics
from capabilities.sim.transforms import rotation_angle, rotation_vector

__all__ = ["Freedrive"]

_DAMPING = np.array([30.0, 30.0, 15.0, 4.0, 4.0, 4.0])  # N m s / rad
_MAX_JOINT_SPEED = 1.0  # rad/s
_DRAG_GAIN = 4.0  # 1/s
_DRAG_SPEED = 0.25  # m/s
_DRAG_ROT_SPEED = 1.0  # rad/s
_DRAG_TOL_M = 3e-4
_DRAG_TOL_RAD = math.radians(0.2)
_DRAG_TIMEOUT = 10.0  # s


class Freedrive:
    """Admittance of the arm while the operator guides it."""

    def __init__(self, kin: UR5Kinematics, dt: float, tcp: Callable[[], np.ndarray]) -> None:
        self._kin = kin
        self._dt = dt
        self._tcp = tcp
        self.active = False
        self._force = np.zeros(3)
        self._torque = np.zeros(3)
        self._push_left = 0.0
        self._drag: np.ndarray | None = None
        self._drag_handle: CommandHandle | None = None
        self._drag_time = 0.0

    def start(self, _q: np.ndarray) -> None:
        """Enter freedrive."""
        self.active = True
        self._push_left = 0.0

    def stop(self) -> None:
        """Leave freedrive; a drag under way fails."""
        self.active = False
        self._push_left = 0.0
        self._end_drag(False, "freedrive stopped")

    def apply_wrench(
        self, force: Sequence[float], torque: Sequence[float], duration: float
    ) -> None:
        """Push at the TCP with a world-frame force (N) and torque (N m) for ``duration`` s."""
        self._force = np.asarray(force, dtype=float)
        self._torque = np.asarray(torque, dtype=float)
        self._push_left = duration

    def drag_to(self, handle: CommandHandle, target: np.ndarray) -> None:
        """Pull the TCP to the world matrix ``target``; ``handle`` finishes on arrival."""
        if not self.active:
            handle.resolve(False, "freedrive_drag_to refused: freedrive is not active")
            return
        self._end_drag(False, "replaced by a new drag")
        self._drag, self._drag_handle, self._drag_time = target, handle, 0.0

    def cancel_drag(self, handle: CommandHandle) -> None:
        """Stop the drag of ``handle``."""
        if handle is self._drag_handle:
            self._end_drag(False, "drag cancelled")
        else:
            handle.resolve(False, "drag cancelled")

    def step(self, q_cmd: np.ndarray, q_actual: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Next commanded joints and velocities."""
        tcp = self._tcp()
        qd = np.zeros(6)
        if self._push_left > 0:
            self._push_left -= self._dt
            jac = self._kin.jacobian(q_cmd, tcp)
            qd += jac.T @ np.concatenate([self._force, self._torque]) / _DAMPING
        if self._drag is not None:
            qd += self._drag_velocity(q_cmd, tcp)
        peak = float(np.max(np.abs(qd)))
        if peak > _MAX_JOINT_SPEED:
            qd *= _MAX_JOINT_SPEED / peak
        q_new = q_cmd + qd * self._dt
        lows = np.array([lo for lo, _ in self._kin.limits])
        highs = np.array([hi for _, hi in self._kin.limits])
        return np.clip(q_new, lows, highs), qd

    def _drag_velocity(self, q: np.ndarray, tcp: np.ndarray) -> np.ndarray:
        assert self._drag is not None
        now = self._kin.tcp_matrix(q, tcp)
        dp = self._drag[:3, 3] - now[:3, 3]
        rot = self._drag[:3, :3] @ now[:3, :3].T
        if np.linalg.norm(dp) < _DRAG_TOL_M and rotation_angle(rot) < _DRAG_TOL_RAD:
            self._end_drag(True, "reached")
            return np.zeros(6)
        self._drag_time += self._dt
        if self._drag_time > _DRAG_TIMEOUT:
            self._end_drag(False, "drag did not reach the pose (out of reach?)")
            return np.zeros(6)
        v = _clip_norm(_DRAG_GAIN * dp, _DRAG_SPEED)
        w = _clip_norm(_DRAG_GAIN * rotation_vector(rot), _DRAG_ROT_SPEED)
        jac = self._kin.jacobian(q, tcp)
        damping = 1e-3 * np.eye(6)
        return jac.T @ np.linalg.solve(jac @ jac.T + damping, np.concatenate([v, w]))

    def _end_drag(self, ok: bool, message: str) -> None:
        handle, self._drag, self._drag_handle = self._drag_handle, None, None
        if handle is not None:
            handle.resolve(ok, message)


def _clip_norm(v: np.ndarray, limit: float) -> np.ndarray:
    norm = float(np.linalg.norm(v))
    return v if norm <= limit else v * (limit / norm)
