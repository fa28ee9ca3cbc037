"""Operations of the gripper capability: open, close, is_closed, is_holding, and grasp (an
object at its pose with a grasp of its model, :mod:`capabilities.gripper.grasp`).
"""

from __future__ import annotations

from capabilities.base import Capability, CapabilityEnv
from capabilities.gripper.backend import GRIPPER, GripperBackend
from capabilities.gripper.grasp import Grasp
from capabilities.jobs import job_from_handle
from capabilities.kit import OperationKind, manifest
from capabilities.motion.backend import ARM
from capabilities.motion.symmetry import SymmetryTable
from engine.operations import Job, OperationCall

__all__ = ["capability"]

CAP = "gripper"


class _GripperOp:
    """An operation on the cell's gripper."""

    def __init__(self, env: CapabilityEnv) -> None:
        self._gripper: GripperBackend = env.interface(GRIPPER)


class Open(_GripperOp):
    """gripper.open: a Job until the fingers stop."""

    MANIFEST = manifest(
        CAP, "open", OperationKind.ACTION, "Opens the gripper fully, releasing what it holds."
    )

    def start(self, call: OperationCall) -> Job:
        return job_from_handle(self._gripper.open(), "open the gripper")


class Close(_GripperOp):
    """gripper.close: a Job until the fingers stop (on an object or each other)."""

    MANIFEST = manifest(
        CAP,
        "close",
        OperationKind.ACTION,
        "Closes the gripper until the fingers meet or stop on an object (see gripper.is_holding).",
    )

    def start(self, call: OperationCall) -> Job:
        return job_from_handle(self._gripper.close(), "close the gripper")


class IsClosed(_GripperOp):
    """gripper.is_closed."""

    MANIFEST = manifest(
        CAP, "is_closed", OperationKind.CONDITION, "True when the gripper is closed."
    )

    def start(self, call: OperationCall) -> Job:
        return Job.answer(self._gripper.is_closed())


class IsHolding(_GripperOp):
    """gripper.is_holding."""

    MANIFEST = manifest(
        CAP, "is_holding", OperationKind.CONDITION, "True when the closed gripper holds something."
    )

    def start(self, call: OperationCall) -> Job:
        return Job.answer(self._gripper.is_holding())


def capability(symmetries: SymmetryTable | None = None) -> Capability:
    """The gripper capability.

    It requires ``gripper`` and ``arm``; grasp reads ``suction`` when the cell has one.
    Its per-cell state is the symmetry table grasps are planned with.
    """
    table = symmetries if symmetries is not None else SymmetryTable()
    cap = Capability(
        CAP,
        "Opens and closes the parallel gripper; grasps objects with their models' grasps.",
        requires=(GRIPPER, ARM),
        setup=lambda env: table,
    )
    cap.add(Open, Close, IsClosed, IsHolding, Grasp.of_grasps(CAP, table.grasp_names()))
    return cap
