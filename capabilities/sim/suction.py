"""The suction tool: a body with a handle that the gripper takes from its holster.

While the gripper holds the tool, the TCP is the cup tip (the cell switches the TCP offset).
``suction_on`` grips a movable part touching the cup (a fixed attachment, the simulator's
stand-in for vacuum), also one that touches it later while the vacuum stays on;
``suction_off`` releases it. ``has_part`` reads the simulated vacuum sensor.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from capabilities.bullet import pybullet
from capabilities.robot.commands import CommandHandle
from capabilities.sim.physics_thread import PhysicsThread
from capabilities.sim.robot import post_command
from capabilities.sim.tools import attach, body_frame_matrix, detach, is_dynamic
from engine.types import Pose

__all__ = ["SimSuctionTool", "SuctionController"]

_CUP_RADIUS = 0.02  # m, matches resources/robots/suction_tool.urdf
_REACH = 0.003  # m: a part this close to the cup face is sucked on
_FACE_BAND = 0.006  # m above the tip that still counts as the cup face


class SuctionController:
    """Vacuum state and part attachment (physics thread only)."""

    def __init__(self, client: int, tool: int, robot: int, in_hand: Callable[[], bool]) -> None:
        self._client = client
        self.tool = tool
        self._robot = robot
        self.in_hand = in_hand  # True while the gripper holds the tool (any thread may ask)
        self.on = False
        self.part: int | None = None
        self._constraint: int | None = None
        self._pending: CommandHandle | None = None

    def set_vacuum(self, handle: CommandHandle, on: bool) -> None:
        """Switch the vacuum; switching on needs the tool in the gripper."""
        if on and not self.in_hand():
            handle.resolve(False, "suction_on refused: the suction tool is not in the gripper")
            return
        self.on = on
        if not on:
            self._release()
            handle.resolve(True, "vacuum off")
            return
        self._pending = handle  # answered after the next contact check

    def shutdown(self, message: str) -> None:
        """Fail an unfinished command (the physics thread has ended)."""
        handle, self._pending = self._pending, None
        if handle is not None:
            handle.resolve(False, message)

    @property
    def has_work(self) -> bool:
        """True while a command waits for the next contact check, or the vacuum is on with
        no part yet (it grips one that comes to the cup).
        """
        return self._pending is not None or (self.on and self.part is None)

    def pre_step(self, _t: float) -> None:
        """Grip a part at the cup while the vacuum is on."""
        if self.on and self.part is None:
            part = self._part_at_cup()
            if part is not None:
                self._constraint = attach(self._client, self.tool, -1, part)
                self.part = part
        if self._pending is not None:
            handle, self._pending = self._pending, None
            handle.resolve(True, "part attached" if self.part is not None else "vacuum on, no part")

    def _release(self) -> None:
        if self._constraint is not None:
            detach(self._client, self._constraint)
        self._constraint, self.part = None, None

    def _part_at_cup(self) -> int | None:
        frame = body_frame_matrix(self._client, self.tool)
        tip = frame[:3, 3]
        half = _CUP_RADIUS + _REACH
        candidates = (
            pybullet.getOverlappingObjects(
                tuple(tip - half), tuple(tip + half), physicsClientId=self._client
            )
            or []
        )
        inverse = np.linalg.inv(frame)
        for body, _link in candidates:
            if body in (self.tool, self._robot) or not is_dynamic(self._client, body):
                continue
            points = pybullet.getClosestPoints(
                self.tool, body, _REACH, linkIndexA=-1, physicsClientId=self._client
            )
            for point in points:
                local = inverse @ np.array([*point[5], 1.0])
                if local[2] < _FACE_BAND and np.hypot(local[0], local[1]) <= _CUP_RADIUS + 1e-3:
                    return int(body)
        return None


class SimSuctionTool:
    """The suction tool as other threads see it.

    Args:
        holster_pose: world pose of the holster frame (configured, like a taught waypoint).
        handle_grasp: gripper TCP pose in the holster frame that grasps the tool's handle.
        tcp_offsets: the gripper's and the suction tool's TCP in the flange frame.
    """

    def __init__(
        self,
        physics: PhysicsThread,
        controller: SuctionController,
        holster_pose: Pose,
        handle_grasp: Pose,
        tcp_offsets: tuple[Pose, Pose],
    ) -> None:
        self._physics = physics
        self._ctl = controller
        self._holster = holster_pose
        self._grasp = handle_grasp
        gripper_tcp, suction_tcp = tcp_offsets
        self._tip_in_grasp = gripper_tcp.inverse().compose(suction_tcp)

    def suction_on(self) -> CommandHandle:
        """Switch the vacuum on (fails when the tool is not in the gripper)."""
        return self._switch("suction_on", True)

    def suction_off(self) -> CommandHandle:
        """Switch the vacuum off, releasing the part."""
        return self._switch("suction_off", False)

    def _switch(self, name: str, on: bool) -> CommandHandle:
        handle = CommandHandle(name)
        return post_command(self._physics, handle, lambda: self._ctl.set_vacuum(handle, on))

    def vacuum_on(self) -> bool:
        """True while the vacuum is switched on."""
        return self._ctl.on

    def has_part(self) -> bool:
        """The vacuum sensor: True while a part is held at the cup."""
        return self._ctl.part is not None

    def in_hand(self) -> bool:
        """True while the gripper holds the suction tool (the TCP is then the cup tip)."""
        return self._ctl.in_hand()

    def holster_pose(self) -> Pose:
        """World pose of the holster (configured fixture pose)."""
        return self._holster

    def handle_grasp_in_holster(self) -> Pose:
        """Gripper TCP pose, in the holster frame, that grasps the handle."""
        return self._grasp

    def handle_grasp_pose(self) -> Pose:
        """World gripper TCP pose that grasps the handle of the holstered tool."""
        return self._holster.compose(self._grasp)

    def holstered_tip_pose(self) -> Pose:
        """World TCP pose (cup tip, suction TCP) that puts the held tool back in the holster."""
        return self.handle_grasp_pose().compose(self._tip_in_grasp)
