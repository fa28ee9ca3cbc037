"""Ground truth of the simulated world, for tests and scores only.

Nothing that a capability uses to decide what to do may read from here: perception works on
rendered images, the gripper and suction tool report through their sensors. Every query
runs on the physics thread.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

from capabilities.bullet import pybullet
from capabilities.sim.gripper import GripperController
from capabilities.sim.physics_thread import PhysicsThread
from capabilities.sim.suction import SuctionController
from capabilities.sim.tools import body_frame_pose
from capabilities.sim.world import World
from engine.types import Pose

__all__ = ["GroundTruth"]

T = TypeVar("T")


class GroundTruth:
    """Exact poses, contacts and attachments of bodies (tests and scoring only)."""

    def __init__(
        self,
        physics: PhysicsThread,
        world: World,
        gripper: GripperController,
        suction: SuctionController,
    ) -> None:
        self._physics = physics
        self.world = world
        self._gripper = gripper
        self._suction = suction

    def _call(self, fn: Callable[[int], T]) -> T:
        return self._physics.call(fn)

    def body_pose(self, body: int) -> Pose:
        """World pose of a body's URDF/base frame."""
        return self._call(lambda c: body_frame_pose(c, body))

    def suction_tool_pose(self) -> Pose:
        """World pose of the suction tool (frame at its cup tip)."""
        return self.body_pose(self.world.suction_tool)

    def in_contact(self, body_a: int, body_b: int) -> bool:
        """True when two bodies touch now."""
        return self._call(
            lambda c: bool(pybullet.getContactPoints(bodyA=body_a, bodyB=body_b, physicsClientId=c))
        )

    def gripper_attached(self) -> int | None:
        """Body fixed to the gripper by a grasp, if any."""
        return self._gripper.attached

    def suction_attached(self) -> int | None:
        """Body held at the suction cup, if any."""
        return self._suction.part

    def flange_pose(self) -> Pose:
        """World pose of tool0 as pybullet has it (to check the kinematics)."""

        def read(c: int) -> Pose:
            state = pybullet.getLinkState(
                self.world.robot,
                self.world.flange_link,
                computeForwardKinematics=True,
                physicsClientId=c,
            )
            return Pose(state[4], state[5])

        return self._call(read)
