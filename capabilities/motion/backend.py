"""What the motion capability needs from a cell: an arm, and (optionally) a world model.

The simulated cell's ``SimRobot`` implements :class:`ArmBackend` as it is; the ur_rtde
backend implements the same methods (moveJ, moveL, moveJ_IK, stopJ, getInverseKinematics).
Commands return at once with a handle that the cell finishes later; a refused command
returns an already failed handle.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

from capabilities.jobs import CommandHandleLike
from engine.types import Pose

__all__ = ["ARM", "WORLD", "ArmBackend", "DetectionLike", "WorldBackend"]

ARM = "arm"
WORLD = "world"


class ArmBackend(Protocol):
    """The robot arm: state, inverse kinematics, moves and stop (SI units, world frame)."""

    def joint_positions(self) -> tuple[float, ...]:
        """Measured joint positions (rad), base to wrist."""
        ...

    def tcp_pose(self) -> Pose:
        """World pose of the current tool's TCP."""
        ...

    def is_moving(self) -> bool:
        """True while a move runs or a joint still turns."""
        ...

    def home_joints(self) -> tuple[float, ...]:
        """The configured home joints (rad)."""
        ...

    def inverse_kinematics(
        self, pose: Pose, near: Sequence[float] | None = None
    ) -> tuple[float, ...] | None:
        """Joints putting the TCP at ``pose`` nearest ``near`` (default: now); None if none."""
        ...

    def move_joints(self, q: Sequence[float], speed: float, accel: float) -> CommandHandleLike:
        """A joint move (rad/s, rad/s^2)."""
        ...

    def move_linear(self, pose: Pose, speed: float, accel: float) -> CommandHandleLike:
        """A straight-line TCP move (m/s, m/s^2)."""
        ...

    def move_pose_joint_space(self, pose: Pose, speed: float, accel: float) -> CommandHandleLike:
        """The TCP to ``pose`` by a joint move (rad/s, rad/s^2)."""
        ...

    def stop(self, decel: float = 4.0) -> CommandHandleLike:
        """Decelerate any move to a halt; the handle finishes when the arm stands."""
        ...

    def clear_protective_stop(self) -> CommandHandleLike:
        """Unlock a protective stop once the robot allows it; the handle finishes when the
        arm can move again (at once when it is not stopped) and fails, in the fault's
        words, on a stop only the operator may clear (an emergency stop, power off).
        """
        ...


class DetectionLike(Protocol):
    """A detection as the world model keeps it (only what motion reads)."""

    @property
    def pose(self) -> Pose: ...

    @property
    def stamp(self) -> float: ...


class WorldBackend(Protocol):
    """The cell's world model: where objects and markers were last seen."""

    def best(self, object_class: str, newer_than: float | None = None) -> DetectionLike | None:
        """The most confident current detection of a class, or None."""
        ...

    def marker(self, marker_id: int) -> tuple[Pose, float] | None:
        """(pose in the world, stamp) of a marker last seen, or None."""
        ...
