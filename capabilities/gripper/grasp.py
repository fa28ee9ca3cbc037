"""gripper.grasp: "grasp CUP at CUP_POSE", with a grasp taught once in the object's model.

The object model (``resources/objects/<name>/model.json``) carries its grasps relative to the
object: the TCP pose that holds it and the approach pose it comes from (see
:class:`capabilities.object_library.GraspSpec`). Given the object's detected pose, the grasp
and its approach are composed with it, every equivalent under the object's symmetry is
tried (least wrist turn first) and the first whose approach and hold are both reachable is
used: a joint move to the approach, straight down to the hold, close the fingers (or switch
the suction tool's vacuum on), check the object is held, lift straight back to the approach.
This is the original CoSTAR's SmartGrasp: the user names the object and its pose, never a
tool pose.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import ClassVar

from capabilities.base import CapabilityEnv, CapabilityError
from capabilities.gripper.backend import GRIPPER, SUCTION, GripperBackend, HeldSuctionTool
from capabilities.jobs import chain_jobs, job_from_handle
from capabilities.kit import manifest
from capabilities.motion.backend import ARM, ArmBackend
from capabilities.motion.geometry import format_pose_mm
from capabilities.motion.operations import JOINT_ACCEL, JOINT_SPEED
from capabilities.motion.symmetry import SymmetryTable
from capabilities.motion.targets import symmetric_rotations
from capabilities.object_library import GraspSpec, ObjectLibraryError
from engine.error_types import ErrorType
from engine.operations import (
    Job,
    OperationCall,
    OperationFailed,
    OperationKind,
    OperationManifest,
    object_model,
    pose,
    text,
)
from engine.types import Pose

__all__ = ["FIRST", "GRASP", "OBJECT", "POSE", "Grasp", "GraspPlan", "grasp_manifest", "plan_grasp"]

FIRST = "first"
"""The ``grasp`` port's value that means the model's first grasp (the default)."""
_LINEAR_SPEED, _LINEAR_ACCEL = 0.15, 1.0  # m/s, m/s^2: gentle near the object


OBJECT = object_model("object", doc="the object (by its model name)")
POSE = pose("pose", doc="where the object is (from a markers or perception pose query)")
GRASP = text(
    "grasp", FIRST, doc="which grasp of the object's model ('first': the model's first grasp)"
)


def grasp_manifest(capability: str, grasp_names: tuple[str, ...]) -> OperationManifest:
    """The manifest of ``<capability>.grasp``; ``grasp_names`` are the library's grasps."""
    return manifest(
        capability,
        "grasp",
        OperationKind.ACTION,
        "Takes an object at its pose with a grasp of its model: approach, straight down, "
        "close (or vacuum on), check it is held, lift back.",
        OBJECT,
        POSE,
        replace(GRASP, choices=(FIRST, *(n for n in grasp_names if n != FIRST))),
    )


@dataclass(frozen=True)
class GraspPlan:
    """World poses of a grasp: the approach (with its joints) and the hold."""

    grasp: GraspSpec
    approach: Pose
    approach_joints: tuple[float, ...]
    hold: Pose
    equivalent: int  # index of the symmetric equivalent used (0: the taught one)


def plan_grasp(
    arm: ArmBackend, grasp: GraspSpec, object_pose: Pose, table: SymmetryTable, object_class: str
) -> GraspPlan:
    """The first symmetric equivalent of ``grasp`` whose approach and hold are reachable.

    Raises:
        OperationFailed: none is reachable; the message says "unreachable" and the pose in mm.
    """
    symmetry, _note = table.lookup(object_class)
    current = arm.tcp_pose()
    rotations = symmetric_rotations(object_pose, grasp.pose, symmetry, current)
    for index, rotation in enumerate(rotations):
        turned = object_pose.compose(rotation)
        approach, hold = turned.compose(grasp.approach), turned.compose(grasp.pose)
        q = arm.inverse_kinematics(approach)
        if q is not None and arm.inverse_kinematics(hold, near=q) is not None:
            return GraspPlan(grasp, approach, tuple(q), hold, index)
    tried = f" (none of {len(rotations)} symmetric equivalents)" if len(rotations) > 1 else ""
    first = object_pose.compose(rotations[0]).compose(grasp.pose)
    raise OperationFailed(
        f"unreachable: grasp {grasp.name!r} of the {object_class} at "
        f"{format_pose_mm(object_pose)}: tool pose {format_pose_mm(first)}{tried}"
    )


class Grasp:
    """gripper.grasp: approach, descend, take (fingers or vacuum), check, lift.

    Its manifest lists the grasps of a library, so the capability adds the class that
    :meth:`of_grasps` makes; ``env.state`` is the capability's symmetry table.
    """

    MANIFEST: ClassVar[OperationManifest]

    @classmethod
    def of_grasps(cls, capability: str, grasp_names: tuple[str, ...]) -> type[Grasp]:
        """The operation whose ``grasp`` port offers ``grasp_names``."""
        return type(cls.__name__, (cls,), {"MANIFEST": grasp_manifest(capability, grasp_names)})

    def __init__(self, env: CapabilityEnv) -> None:
        self._arm: ArmBackend = env.interface(ARM)
        self._gripper: GripperBackend = env.interface(GRIPPER)
        self._suction: HeldSuctionTool | None
        try:
            self._suction = env.interface(SUCTION)
        except CapabilityError:
            self._suction = None  # grasps made with the suction tool then say the cell has none
        self._table: SymmetryTable = env.state

    def start(self, call: OperationCall) -> Job:
        model = call.input(OBJECT)
        name = call.input(GRASP)
        try:
            grasp = self._table.grasp(model.name, "" if name == FIRST else name)
        except (ObjectLibraryError, OSError) as exc:
            raise OperationFailed(str(exc)) from exc
        take, held = self._tool_steps(grasp, model.name)
        plan = plan_grasp(self._arm, grasp, call.input(POSE), self._table, model.name)
        turned = f" (symmetric equivalent {plan.equivalent})" if plan.equivalent else ""
        call.log(f"grasp {grasp.name!r} of the {model.name}{turned}")
        steps: list[tuple[str, Callable[[], Job]]] = []
        if grasp.tool == "gripper":
            steps.append(("open the gripper", lambda: job_from_handle(self._gripper.open())))
        return chain_jobs(
            [
                *steps,
                ("approach", self._joint_move(plan.approach_joints)),
                ("descend", self._straight(plan.hold)),
                *take,
                ("check the grasp", lambda: _check(held, f"the {model.name} is not held")),
                ("lift", self._straight(plan.approach)),
            ]
        )

    def _tool_steps(
        self, grasp: GraspSpec, object_class: str
    ) -> tuple[list[tuple[str, Callable[[], Job]]], Callable[[], bool]]:
        """The take steps and the held sensor of the grasp's tool, after checking that
        tool is the one in hand; raises OperationFailed saying what to do first.
        """
        suction = self._suction
        in_hand = suction is not None and suction.in_hand()
        if grasp.tool == "suction":
            if suction is None:
                raise OperationFailed(
                    f"grasp {grasp.name!r} needs a suction tool; this cell has none"
                )
            if not in_hand:
                raise OperationFailed(
                    f"grasp {grasp.name!r} of the {object_class} is made with the suction tool: "
                    "take it first (tool.unholster)"
                )
            if suction.has_part():
                raise OperationFailed("the suction tool holds a part already: release it first")
            return [("vacuum on", lambda: job_from_handle(suction.suction_on()))], suction.has_part
        if in_hand:
            raise OperationFailed(
                f"grasp {grasp.name!r} of the {object_class} is made with the gripper, which holds "
                "the suction tool: put it back first (tool.holster)"
            )
        if self._gripper.is_holding():
            raise OperationFailed("the gripper holds something already: release it first")
        close = ("close the gripper", lambda: job_from_handle(self._gripper.close()))
        return [close], self._gripper.is_holding

    def _joint_move(self, q: tuple[float, ...]) -> Callable[[], Job]:
        return lambda: job_from_handle(self._arm.move_joints(q, JOINT_SPEED, JOINT_ACCEL))

    def _straight(self, pose: Pose) -> Callable[[], Job]:
        return lambda: job_from_handle(self._arm.move_linear(pose, _LINEAR_SPEED, _LINEAR_ACCEL))


def _check(test: Callable[[], bool], problem: str) -> Job:
    return Job.done() if test() else Job.failed(problem, ErrorType.GRASP_FAILED)
