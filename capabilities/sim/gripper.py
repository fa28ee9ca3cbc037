"""The parallel gripper on the flange: two prismatic fingers driven by force-limited motors.

``GripperController`` lives on the physics thread; ``SimGripper`` is what other threads call.
When the fingers close on an object and both touch it, the object is fixed to the gripper
body (see ``tools.attach``); opening releases it. ``is_holding`` is judged like a real
gripper's position sensor: closed, yet the fingers stopped apart.

A command ends as a Robotiq's does: when the fingers reach the requested position or stop on
an object. Stopped means stalled, or making no headway over ``_STALL_WINDOW`` (a finger jammed
on a part lying askew trembles in its contacts but gets no further), and no command outlasts
``_MAX_TIME`` (the firmware's end of a motion that cannot finish).
"""

from __future__ import annotations

import contextlib

from capabilities.bullet import pybullet
from capabilities.robot.commands import CommandHandle
from capabilities.sim.physics_thread import PhysicsThread
from capabilities.sim.robot import post_command
from capabilities.sim.tools import attach, detach, is_dynamic

__all__ = ["OPEN_POSITION", "GripperController", "SimGripper"]

OPEN_POSITION = 0.0425  # m per finger: 85 mm stroke
_FORCE = 60.0  # N per finger
_SPEED = 0.15  # m/s per finger
_HOLD_GAP = 0.002  # m: closed with a larger gap means an object is between the fingers
_STALLED = 1e-4  # m/s
_MIN_TIME = 0.05  # s before a stalled finger counts as done
_STALL_WINDOW = 0.1  # s: a finger that moved less than _STALL_TRAVEL in this long has stopped
_STALL_TRAVEL = 5e-4  # m
_MAX_TIME = 2 * OPEN_POSITION / _SPEED + 0.5  # s: twice a full stroke, then the motion ends


class GripperController:
    """Finger motors, grasp attachment and the gap sensor (physics thread only)."""

    def __init__(self, client: int, robot: int, body_link: int, fingers: tuple[int, int]) -> None:
        self._client = client
        self._robot = robot
        self._body_link = body_link
        self._fingers = fingers
        self.closed = False
        self.gap = 2 * OPEN_POSITION
        self.attached: int | None = None
        self._constraint: int | None = None
        self._passing: int | None = None  # a body the fingers do not collide with (held)
        self._handle: CommandHandle | None = None
        self._elapsed = 0.0
        self._mark: tuple[float, float, float] = (0.0, OPEN_POSITION, OPEN_POSITION)
        for finger in fingers:
            pybullet.resetJointState(robot, finger, OPEN_POSITION, physicsClientId=client)
        self._drive(OPEN_POSITION)

    @property
    def moving(self) -> bool:
        """True while an open or close command runs."""
        return self._handle is not None

    def command(self, handle: CommandHandle, close: bool) -> None:
        """Start closing or opening; ``handle`` finishes when the fingers stop."""
        if self._handle is not None:
            self._handle.resolve(False, f"{self._handle.name} preempted by {handle.name}")
        self.closed = close
        self._handle, self._elapsed = handle, 0.0
        self._mark = (0.0, *self._positions())
        if not close:
            self.release()
        self._drive(0.0 if close else OPEN_POSITION)

    def shutdown(self, message: str) -> None:
        """Fail an unfinished command (the physics thread has ended)."""
        handle, self._handle = self._handle, None
        if handle is not None:
            handle.resolve(False, message)

    def release(self) -> None:
        """Drop whatever is attached."""
        if self._constraint is not None:
            detach(self._client, self._constraint)
        self._constraint, self.attached = None, None
        self._collide_again()

    def pre_step(self, _t: float) -> None:
        """Forget a hold that is gone; attach an object both closing fingers touch.

        A hold is gone when its constraint is (the part came apart or slipped out); the
        fingers then close on, but grasp anew only during a close command.
        """
        if self._constraint is not None and not self._hold_exists():
            self._constraint, self.attached = None, None
            self._collide_again()
            if self.closed:
                self._drive(0.0)  # nothing left between them: they close on, as a real one's
        if self.closed and self._handle is not None and self.attached is None:
            body = self._grasped_body()
            if body is not None:
                self._constraint = attach(self._client, self._robot, self._body_link, body)
                self.attached = body

    def post_step(self, dt: float) -> None:
        """Update the gap sensor and finish a command whose fingers have stopped."""
        states = pybullet.getJointStates(self._robot, self._fingers, physicsClientId=self._client)
        self.gap = float(states[0][0] + states[1][0])
        if self.attached is not None and self.gap < _HOLD_GAP:
            self.release()  # the fingers closed past it: it squeezed out from between them
        if self._handle is None:
            return
        self._elapsed += dt
        target = 0.0 if self.closed else OPEN_POSITION
        arrived = all(abs(s[0] - target) < 5e-4 for s in states)
        stalled = self._elapsed > _MIN_TIME and all(abs(s[1]) < _STALLED for s in states)
        if arrived or stalled or self._no_headway(states[0][0], states[1][0]):
            self._finish("")
        elif self._elapsed > _MAX_TIME:
            self._finish(" (the fingers did not settle)")

    def _no_headway(self, left: float, right: float) -> bool:
        """True once neither finger got further than _STALL_TRAVEL over a _STALL_WINDOW."""
        since, left_then, right_then = self._mark
        if self._elapsed - since < _STALL_WINDOW:
            return False
        self._mark = (self._elapsed, left, right)
        return abs(left - left_then) < _STALL_TRAVEL and abs(right - right_then) < _STALL_TRAVEL

    def _finish(self, note: str) -> None:
        if self.closed and self.attached is not None:
            # Stay where they stopped on it. Driven on, the fingers crept into the held part
            # and in the end past it, so what they held depended on when the next command came.
            for finger, position in zip(self._fingers, self._positions(), strict=True):
                self._drive(position, (finger,))
            # And no longer collide with it: fixed to the gripper, it cannot give way, and the
            # contacts of fingers sunk into it (12 -> 5 mm on an 8 mm wire) pushed them about
            # until they crept past it and dropped it on the way (a broken weld's piece).
            self._pass_through(self.attached)
        handle, self._handle = self._handle, None
        if handle is not None:
            handle.resolve(True, f"gap {self.gap * 1000:.1f} mm after {self._elapsed:.2f} s{note}")

    def _pass_through(self, body: int) -> None:
        self._set_collision(body, False)
        self._passing = body

    def _collide_again(self) -> None:
        """The fingers collide with what they held again (once it is let go or gone)."""
        body, self._passing = self._passing, None
        if body is not None:
            # It may be gone from the world (a broken weld's part, taken out of the cell).
            with contextlib.suppress(pybullet.error):
                self._set_collision(body, True)

    def _set_collision(self, body: int, collide: bool) -> None:
        for finger in self._fingers:
            pybullet.setCollisionFilterPair(
                self._robot, body, finger, -1, int(collide), physicsClientId=self._client
            )

    def _positions(self) -> tuple[float, float]:
        states = pybullet.getJointStates(self._robot, self._fingers, physicsClientId=self._client)
        return float(states[0][0]), float(states[1][0])

    def _hold_exists(self) -> bool:
        """False once the attachment's constraint is gone (its body was removed or let go)."""
        try:
            pybullet.getConstraintInfo(self._constraint, physicsClientId=self._client)
        except pybullet.error:
            return False
        return True

    def _grasped_body(self) -> int | None:
        touching = []
        for finger in self._fingers:
            points = pybullet.getContactPoints(
                bodyA=self._robot, linkIndexA=finger, physicsClientId=self._client
            )
            touching.append({p[2] for p in points if p[2] != self._robot})
        for body in touching[0] & touching[1]:
            if is_dynamic(self._client, body):
                return int(body)
        return None

    def _drive(self, position: float, fingers: tuple[int, ...] | None = None) -> None:
        for finger in fingers or self._fingers:
            pybullet.setJointMotorControl2(
                self._robot,
                finger,
                pybullet.POSITION_CONTROL,
                targetPosition=position,
                force=_FORCE,
                maxVelocity=_SPEED,
                physicsClientId=self._client,
            )


class SimGripper:
    """The parallel gripper as other threads see it."""

    def __init__(self, physics: PhysicsThread, controller: GripperController) -> None:
        self._physics = physics
        self._ctl = controller

    def close(self) -> CommandHandle:
        """Close the fingers (until they meet or stall on an object)."""
        return self._command("gripper_close", True)

    def open(self) -> CommandHandle:
        """Open the fingers fully, releasing what they hold."""
        return self._command("gripper_open", False)

    def _command(self, name: str, closed: bool) -> CommandHandle:
        handle = CommandHandle(name)
        return post_command(self._physics, handle, lambda: self._ctl.command(handle, closed))

    def is_closed(self) -> bool:
        """True after a close command (the gripper's closed state)."""
        return self._ctl.closed

    def gap(self) -> float:
        """Distance between the finger pads (m), from the finger position sensors."""
        return self._ctl.gap

    def is_holding(self) -> bool:
        """Closed but the fingers stopped apart: something is between them."""
        return self._ctl.closed and not self._ctl.moving and self._ctl.gap > _HOLD_GAP
