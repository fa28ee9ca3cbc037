"""Jogging on any arm backend (a fake one here): the target of a jog in the base and tool
frames, the distance halved where the arm refuses, a held jog that ends on release and one
that cannot start at all.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence

import pytest

from capabilities.motion.jog import JogFailed, Jogger, jog_target
from capabilities.motion.targets import ResolvedTarget
from capabilities.robot.commands import CommandHandle
from engine.types import JointConfig, Pose

DOWN = (1.0, 0.0, 0.0, 0.0)  # the tool's z points down


def angle_between(a: Pose, b: Pose) -> float:
    dot = abs(sum(x * y for x, y in zip(a.orientation, b.orientation, strict=True)))
    return math.degrees(2 * math.acos(min(1.0, dot)))


def test_base_frame_moves_along_world_axes_and_turns_about_the_tcp() -> None:
    tool = Pose((0.4, 0.1, 0.3), DOWN)
    assert jog_target(tool, "base", "z", 0.01).position == pytest.approx((0.4, 0.1, 0.31))
    turned = jog_target(tool, "base", "rz", math.radians(10))
    assert turned.position == tool.position and angle_between(turned, tool) == pytest.approx(10)
    # Turning about world z keeps the tool's z (pointing down) where it is.
    assert turned.compose(Pose((0.0, 0.0, 0.1))).position == pytest.approx((0.4, 0.1, 0.2))


def test_tool_frame_moves_along_the_tools_own_axes() -> None:
    tool = Pose((0.4, 0.1, 0.3), DOWN)
    assert jog_target(tool, "tool", "z", 0.01).position == pytest.approx((0.4, 0.1, 0.29))
    assert jog_target(tool, "tool", "y", 0.01).position == pytest.approx((0.4, 0.09, 0.3))
    with pytest.raises(ValueError, match="jog frame"):
        jog_target(tool, "flange", "z", 0.01)


class FakeArm:
    """Refuses any linear target farther than ``reach`` m from its start, like an arm at the
    edge of its reach; accepted moves stay running until stopped.
    """

    def __init__(self, reach: float = 1.0) -> None:
        self.tool = Pose((0.4, 0.0, 0.3), DOWN)
        self.reach = reach
        self.sent: list[tuple[float, ...]] = []
        self.stopped = 0

    def tcp_pose(self) -> Pose:
        return self.tool

    def joint_positions(self) -> tuple[float, ...]:
        return (0.0,) * 6

    def inverse_kinematics(
        self, pose: Pose, near: Sequence[float] | None = None
    ) -> tuple[float, ...] | None:
        return (1.0,) * 6 if pose.position[2] > 0 else None

    def move_linear(self, pose: Pose, speed: float, accel: float) -> CommandHandle:
        self.sent.append(pose.position)
        if math.dist(pose.position, self.tool.position) > self.reach:
            return CommandHandle.failed("move_linear", "unreachable: too far")
        return CommandHandle("move_linear")

    def move_joints(self, q: Sequence[float], speed: float, accel: float) -> CommandHandle:
        self.sent.append(tuple(q))
        return CommandHandle.succeeded("move_joints")

    def stop(self, decel: float = 4.0) -> CommandHandle:
        self.stopped += 1
        return CommandHandle.succeeded("stop")


def test_a_held_jog_halves_where_refused_and_stops_on_release() -> None:
    arm = FakeArm(reach=0.05)
    released = threading.Event()
    result: list[str] = []
    worker = threading.Thread(
        target=lambda: result.append(Jogger(arm).hold("base", "x", 1, 1.0, released))
    )
    worker.start()
    while len(arm.sent) < 4:  # 0.375 m, 0.1875, 0.094: refused; 0.047 m: accepted
        threading.Event().wait(0.01)
    released.set()
    worker.join(5)
    assert result == [""] and arm.stopped == 1
    distances = [round(p[0] - 0.4, 4) for p in arm.sent]
    assert distances == [0.375, 0.1875, 0.0938, 0.0469]


def test_a_jog_that_cannot_start_says_so_and_speeds_are_checked() -> None:
    arm = FakeArm(reach=0.0)
    with pytest.raises(JogFailed, match="cannot jog base z any further"):
        Jogger(arm).hold("base", "z", -1, 0.5, threading.Event())
    with pytest.raises(ValueError, match="above 0 %"):
        Jogger(arm).step("base", "z", 0.01, 0.0)


def test_go_to_takes_the_first_reachable_pose_through_its_approach() -> None:
    arm = FakeArm()
    jogger, released = Jogger(arm), threading.Event()
    below, above = Pose((0.1, 0.0, -0.1)), Pose((0.1, 0.0, 0.1))
    assert jogger.go_to(ResolvedTarget("two", (below, above)), 0.5, released) == ""
    assert arm.sent[-1] == (1.0,) * 6  # the joints of the reachable one
    joints = ResolvedTarget("joints", joints=JointConfig((0.5,) * 6))
    assert jogger.go_to(joints, 0.5, released) == "" and arm.sent[-1] == (0.5,) * 6
    arm.sent.clear()
    grasp = ResolvedTarget("grasp", (Pose((0.4, 0.0, 0.31)),), approaches=(Pose((0.4, 0.0, 0.4)),))
    arm.move_linear = lambda pose, speed, accel: (  # type: ignore[method-assign]
        arm.sent.append(pose.position) or CommandHandle.succeeded("move_linear")
    )
    assert jogger.go_to(grasp, 0.5, released) == ""
    assert arm.sent == [(1.0,) * 6, (0.4, 0.0, 0.31)]  # to the approach, then down the line
    with pytest.raises(JogFailed, match="unreachable: none"):
        jogger.go_to(ResolvedTarget("none", (Pose((0.0, 0.0, -1.0)),)), 0.5, released)
