"""Jogging the arm as a teach pendant does: by a step, or while a button is held.

Works on any :class:`capabilities.motion.backend.ArmBackend` (the simulated arm, the UR
backend): a step is one move of the chosen size; a held jog is a chain of moves towards a
target a little ahead, each issued when the last one ends, until the caller says stop. Where
the arm cannot go further (the edge of its reach, a joint limit), the move is retried with
half the distance down to ``_MIN_FRACTION`` of it, and then the jog ends with a message.

Everything here may wait for the arm's answer: call it on a worker thread, never on the GUI
thread or the engine's.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from dataclasses import dataclass

from capabilities.errors import CapabilityError
from capabilities.jobs import CommandHandleLike
from capabilities.motion.backend import ArmBackend
from capabilities.motion.geometry import axis_rotation, format_pose_mm
from capabilities.motion.targets import ResolvedTarget
from engine.types import Pose

__all__ = [
    "AXES",
    "FRAMES",
    "JogFailed",
    "Jogger",
    "JogSpeeds",
    "jog_target",
]

AXES = ("x", "y", "z", "rx", "ry", "rz")
FRAMES = ("base", "tool")
_UNIT = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}
_SEGMENT_S = 1.5  # seconds of motion per move of a held jog
_MIN_FRACTION = 1 / 64  # the shortest retry, as a part of the wanted distance
_POLL_S = 0.01


class JogFailed(CapabilityError):
    """A jog could not start (the arm refused every distance tried); the message says why."""


@dataclass(frozen=True)
class JogSpeeds:
    """Top speeds of a jog at 100 % on the speed slider (PolyScope's jog is as slow)."""

    linear: float = 0.25  # m/s
    joint: float = 0.8  # rad/s
    linear_accel: float = 1.2  # m/s^2
    joint_accel: float = 1.4  # rad/s^2


def jog_target(current: Pose, frame: str, axis: str, amount: float) -> Pose:
    """The tool pose after a jog of ``amount`` (m, or rad for rx/ry/rz) along ``axis``.

    In the base frame the tool moves along (turns about) a world axis through the TCP; in the
    tool frame along (about) its own axis, as on PolyScope's Move tab.
    """
    if frame not in FRAMES or axis not in AXES:
        raise ValueError(f"jog frame must be one of {FRAMES} and axis one of {AXES}")
    rotation = axis.startswith("r")
    unit = _UNIT[axis[-1]]
    if frame == "tool":
        step = axis_rotation(unit, amount) if rotation else Pose.of([amount * u for u in unit])
        return current.compose(step)
    if rotation:
        turned = axis_rotation(unit, amount).compose(Pose((0.0, 0.0, 0.0), current.orientation))
        return Pose(current.position, turned.orientation)
    moved = tuple(p + amount * u for p, u in zip(current.position, unit, strict=True))
    return Pose.of(moved, current.orientation)


class Jogger:
    """Step and held jogs of one arm.

    Args:
        arm: the arm backend.
        speeds: top speeds at 100 %.
    """

    def __init__(self, arm: ArmBackend, speeds: JogSpeeds | None = None) -> None:
        self._arm = arm
        self.speeds = speeds or JogSpeeds()

    # ---------------------------------------------------------------- steps

    def step(self, frame: str, axis: str, amount: float, fraction: float) -> CommandHandleLike:
        """One straight-line move of the tool by ``amount``; returns the arm's handle."""
        target = jog_target(self._arm.tcp_pose(), frame, axis, amount)
        return self._arm.move_linear(target, *self._linear(fraction))

    def step_joint(self, joint: int, amount: float, fraction: float) -> CommandHandleLike:
        """One joint move of ``joint`` (0 = base) by ``amount`` rad."""
        q = list(self._arm.joint_positions())
        q[joint] += amount
        return self._arm.move_joints(q, *self._joint(fraction))

    # ---------------------------------------------------------------- held

    def hold(
        self, frame: str, axis: str, sign: int, fraction: float, released: threading.Event
    ) -> str:
        """Jog the tool along ``axis`` (``sign`` +1 or -1) until ``released`` is set.

        Blocks; returns why it ended ("" when released). Raises JogFailed when no move
        could start at all.
        """
        linear, accel = self._linear(fraction)
        rotation = axis.startswith("r")
        # A rotation's speed is the arm's own (the backend's moveL has one speed, in m/s).
        distance = (0.6 if rotation else linear * _SEGMENT_S) * sign

        def issue(scale: float) -> CommandHandleLike:
            target = jog_target(self._arm.tcp_pose(), frame, axis, distance * scale)
            return self._arm.move_linear(target, linear, accel)

        return self._chain(issue, released, f"{frame} {axis}")

    def hold_joint(self, joint: int, sign: int, fraction: float, released: threading.Event) -> str:
        """Turn one joint until ``released`` is set (as :meth:`hold`)."""
        speed, accel = self._joint(fraction)

        def issue(scale: float) -> CommandHandleLike:
            q = list(self._arm.joint_positions())
            q[joint] += sign * speed * _SEGMENT_S * scale
            return self._arm.move_joints(q, speed, accel)

        return self._chain(issue, released, f"joint {joint + 1}")

    def go_to(self, target: ResolvedTarget, fraction: float, released: threading.Event) -> str:
        """Drive to a resolved target until there or ``released`` (blocks; as :meth:`follow`).

        The first reachable candidate is used; a candidate with an approach (a grasp) is
        reached as motion.move_to reaches it: a joint move to the approach, then a straight
        line to the pose.

        Raises:
            JogFailed: no candidate pose is reachable.
        """
        speed, accel = self._joint(fraction)
        if target.joints is not None:
            return self.follow(
                self._arm.move_joints(target.joints.positions, speed, accel), released
            )
        approaches = target.approaches or (None,) * len(target.poses)
        for pose, approach in zip(target.poses, approaches, strict=True):
            first = approach if approach is not None else pose
            q = self._arm.inverse_kinematics(first)
            if q is None or (approach is not None and self._arm.inverse_kinematics(pose) is None):
                continue
            problem = self.follow(self._arm.move_joints(q, speed, accel), released)
            if problem or approach is None or released.is_set():
                return problem
            return self.follow(self._arm.move_linear(pose, *self._linear(fraction)), released)
        where = format_pose_mm(target.poses[0]) if target.poses else "no pose"
        raise JogFailed(f"unreachable: {target.describe}: tool pose {where}")

    def follow(self, handle: CommandHandleLike, released: threading.Event) -> str:
        """Wait for ``handle`` or ``released``; on release stop the arm. Returns the failure
        message ("" when it arrived or was released).
        """
        while not handle.done():
            if released.wait(_POLL_S):
                handle.cancel()
                _wait(self._arm.stop(), 2.0)
                return ""
        return "" if handle.ok else (handle.message or "the move failed")

    # ---------------------------------------------------------------- internals

    def _chain(
        self, issue: Callable[[float], CommandHandleLike], released: threading.Event, what: str
    ) -> str:
        started = False
        while not released.is_set():
            handle = self._first_accepted(issue, released)
            if handle is None:
                if not started:
                    raise JogFailed(f"cannot jog {what} any further from here")
                return f"jog {what} stopped: the arm cannot go further"
            started = True
            problem = self.follow(handle, released)
            if problem:
                return f"jog {what} stopped: {problem}"
        return ""

    def _first_accepted(
        self, issue: Callable[[float], CommandHandleLike], released: threading.Event
    ) -> CommandHandleLike | None:
        """The first move the arm accepts, halving the distance after each refusal."""
        scale = 1.0
        while scale >= _MIN_FRACTION and not released.is_set():
            handle = issue(scale)
            if not _refused(handle):
                return handle
            scale /= 2
        return None

    def _linear(self, fraction: float) -> tuple[float, float]:
        f = _fraction(fraction)
        return self.speeds.linear * f, self.speeds.linear_accel

    def _joint(self, fraction: float) -> tuple[float, float]:
        f = _fraction(fraction)
        return self.speeds.joint * f, self.speeds.joint_accel


def _fraction(value: float) -> float:
    if not (0.0 < value <= 1.0 and math.isfinite(value)):
        raise ValueError(f"the speed must be above 0 % and at most 100 %, not {value:.0%}")
    return value


def _refused(handle: CommandHandleLike, wait_s: float = 0.2) -> bool:
    """True when the arm refused the move at once (it fails before it starts)."""
    deadline = threading.Event()
    handle.add_done_callback(lambda _h: deadline.set())
    if not deadline.wait(wait_s):
        return False  # still running: accepted
    return not handle.ok and _is_refusal(handle.message)


def _is_refusal(message: str) -> bool:
    words = ("unreachable", "outside the joint limits", "branch flip", "singularity", "refused")
    return any(word in message for word in words)


def _wait(handle: CommandHandleLike, timeout: float) -> None:
    finished = threading.Event()
    handle.add_done_callback(lambda _h: finished.set())
    finished.wait(timeout)
