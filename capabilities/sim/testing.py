"""Helpers for tests and benchmarks of the simulated cell (like ``numpy.testing``)."""

from __future__ import annotations

import math

from capabilities.bullet import pybullet
from capabilities.robot.commands import CommandHandle
from capabilities.sim.cell import SimCell
from engine.types import Pose

__all__ = ["DOWN", "add_box", "angle_between", "distance", "down_at", "run"]

DOWN = (1.0, 0.0, 0.0, 0.0)  # tool z axis pointing at the table


def run(handle: CommandHandle, timeout: float = 60.0) -> CommandHandle:
    """Wait for a command (real-time ``timeout``) and insist that it succeeded."""
    assert handle.wait(timeout), f"{handle.name} did not finish"
    assert handle.ok, f"{handle.name} failed: {handle.message}"
    return handle


def down_at(x: float, y: float, z: float, yaw: float = 0.0) -> Pose:
    """A TCP pose pointing down at (x, y, z), turned ``yaw`` (rad) about the vertical."""
    return Pose((x, y, z), (math.cos(yaw / 2), -math.sin(yaw / 2), 0.0, 0.0))


def distance(a: Pose, b: Pose) -> float:
    """Distance between two poses' positions (m)."""
    return math.dist(a.position, b.position)


def angle_between(a: Pose, b: Pose) -> float:
    """Rotation angle (rad) between two poses' orientations."""
    dot = abs(sum(x * y for x, y in zip(a.orientation, b.orientation, strict=True)))
    return 2 * math.acos(min(1.0, dot))


def add_box(
    cell: SimCell,
    size: tuple[float, float, float],
    xy: tuple[float, float],
    mass: float = 0.2,
    rgba: tuple[float, float, float, float] = (0.8, 0.2, 0.2, 1.0),
) -> int:
    """Drop a dynamic box (full ``size`` m) on the table at ``xy``; returns its body id."""
    half = [s / 2 for s in size]
    center = (xy[0], xy[1], cell.table_top_z + half[2] + 1e-4)

    def create(client: int) -> int:
        shape = pybullet.createCollisionShape(
            pybullet.GEOM_BOX, halfExtents=half, physicsClientId=client
        )
        visual = pybullet.createVisualShape(
            pybullet.GEOM_BOX, halfExtents=half, rgbaColor=rgba, physicsClientId=client
        )
        body = pybullet.createMultiBody(
            mass, shape, visual, basePosition=center, physicsClientId=client
        )
        pybullet.changeDynamics(body, -1, lateralFriction=0.8, physicsClientId=client)
        return int(body)

    return cell.call(create)
