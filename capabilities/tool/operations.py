"""Operations of the tool capability: take the suction tool, put it back, vacuum on/off.

Unholstering and holstering are scripted moves (chain_jobs): each step starts when the one
before has finished, targets are computed when their step starts (the TCP changes once the
tool is in the gripper), and halting the node cancels the step under way, which stops the
arm. A failed step fails the node with the step's name and the cell's message.
"""

from __future__ import annotations

from collections.abc import Callable

from capabilities.base import Capability, CapabilityEnv
from capabilities.gripper.backend import GRIPPER, SUCTION, GripperBackend
from capabilities.jobs import chain_jobs, job_from_handle
from capabilities.kit import OperationKind, manifest
from capabilities.motion.backend import ARM, ArmBackend
from capabilities.tool.backend import SuctionBackend
from engine.operations import Job, OperationCall
from engine.types import Pose

__all__ = ["capability", "APPROACH_HEIGHT", "LIFT_HEIGHT"]

CAP = "tool"
APPROACH_HEIGHT = 0.10  # m above the handle (or holster) where the straight descent starts
LIFT_HEIGHT = 0.15  # m the tool is lifted straight out of the holster
_JOINT_SPEED, _JOINT_ACCEL = 1.05, 1.4  # rad/s, rad/s^2
_LINEAR_SPEED, _LINEAR_ACCEL = 0.15, 1.0  # m/s, m/s^2: gentle near the holster


def _above(pose: Pose, dz: float) -> Pose:
    x, y, z = pose.position
    return Pose((x, y, z + dz), pose.orientation)


def _check(test: Callable[[], bool], problem: str) -> Job:
    job = Job()
    if test():
        job.succeed()
    else:
        job.fail(problem)
    return job


class _Scripted:
    """Shared by holster and unholster: the three devices and the move steps."""

    def __init__(self, env: CapabilityEnv) -> None:
        self.arm: ArmBackend = env.interface(ARM)
        self.gripper: GripperBackend = env.interface(GRIPPER)
        self.suction: SuctionBackend = env.interface(SUCTION)

    def approach(self, target: Callable[[], Pose]) -> Callable[[], Job]:
        def step() -> Job:
            handle = self.arm.move_pose_joint_space(target(), _JOINT_SPEED, _JOINT_ACCEL)
            return job_from_handle(handle)

        return step

    def straight(self, target: Callable[[], Pose]) -> Callable[[], Job]:
        def step() -> Job:
            return job_from_handle(self.arm.move_linear(target(), _LINEAR_SPEED, _LINEAR_ACCEL))

        return step


class Unholster(_Scripted):
    """tool.unholster: open, approach above the handle, descend, close, lift out."""

    MANIFEST = manifest(
        CAP,
        "unholster",
        OperationKind.ACTION,
        "Takes the suction tool out of its holster with the gripper (nothing to do if held).",
    )

    def start(self, call: OperationCall) -> Job:
        if self.suction.in_hand():
            call.log("the suction tool is already in the gripper")
            return Job.done()
        if self.gripper.is_holding():
            return _check(lambda: False, "the gripper holds something: put it down first")
        grasp = self.suction.handle_grasp_pose
        return chain_jobs(
            [
                ("open the gripper", lambda: job_from_handle(self.gripper.open())),
                ("approach the holster", self.approach(lambda: _above(grasp(), APPROACH_HEIGHT))),
                ("descend to the handle", self.straight(grasp)),
                ("grasp the handle", lambda: job_from_handle(self.gripper.close())),
                (
                    "check the grasp",
                    lambda: _check(self.suction.in_hand, "the gripper did not take the tool"),
                ),
                (
                    "lift the tool out",
                    self.straight(lambda: _above(self.arm.tcp_pose(), LIFT_HEIGHT)),
                ),
            ]
        )


class Holster(_Scripted):
    """tool.holster: vacuum off, approach above the holster, lower, open, move clear."""

    MANIFEST = manifest(
        CAP,
        "holster",
        OperationKind.ACTION,
        "Puts the suction tool back in its holster and lets go of it (nothing to do if not held).",
    )

    def start(self, call: OperationCall) -> Job:
        if not self.suction.in_hand():
            call.log("the suction tool is not in the gripper: nothing to put back")
            return Job.done()
        tip = self.suction.holstered_tip_pose
        return chain_jobs(
            [
                ("switch the vacuum off", self._vacuum_off),
                ("approach the holster", self.approach(lambda: _above(tip(), APPROACH_HEIGHT))),
                ("lower into the holster", self.straight(tip)),
                ("release the handle", lambda: job_from_handle(self.gripper.open())),
                (
                    "check the release",
                    lambda: _check(lambda: not self.suction.in_hand(), "the tool is still held"),
                ),
                ("move clear", self.straight(lambda: _above(self.arm.tcp_pose(), APPROACH_HEIGHT))),
            ]
        )

    def _vacuum_off(self) -> Job:
        if not self.suction.vacuum_on():
            return _check(lambda: True, "")
        return job_from_handle(self.suction.suction_off())


class _SuctionOp:
    """An operation on the cell's suction tool."""

    def __init__(self, env: CapabilityEnv) -> None:
        self._suction: SuctionBackend = env.interface(SUCTION)


class SuctionOn(_SuctionOp):
    """tool.suction_on."""

    MANIFEST = manifest(
        CAP, "suction_on", OperationKind.ACTION, "Switches the vacuum on (the tool must be held)."
    )

    def start(self, call: OperationCall) -> Job:
        return job_from_handle(self._suction.suction_on(), "suction on")


class SuctionOff(_SuctionOp):
    """tool.suction_off."""

    MANIFEST = manifest(
        CAP, "suction_off", OperationKind.ACTION, "Switches the vacuum off, dropping the part."
    )

    def start(self, call: OperationCall) -> Job:
        return job_from_handle(self._suction.suction_off(), "suction off")


class HasPart(_SuctionOp):
    """tool.has_part: the vacuum sensor."""

    MANIFEST = manifest(
        CAP, "has_part", OperationKind.CONDITION, "True when the vacuum sensor feels a part."
    )

    def start(self, call: OperationCall) -> Job:
        return Job.answer(self._suction.has_part())


def capability() -> Capability:
    """The tool capability (requires ``arm``, ``gripper`` and ``suction``)."""
    cap = Capability(
        CAP,
        "The suction tool: take it from its holster, vacuum on and off, put it back.",
        requires=(ARM, GRIPPER, SUCTION),
    )
    cap.add(Unholster, Holster, SuctionOn, SuctionOff, HasPart)
    return cap
