"""Operations of the gripper capability: open, close, is_closed, is_holding, and grasp (an
object at its pose with a grasp of its model, :mod:`capabilities.gripper.grasp`).
"""

from __future__ import annotations

from capabilities.base import Capability, CapabilityEnv, CapabilityError
from capabilities.gripper.backend import GRIPPER, SUCTION, GripperBackend, HeldSuctionTool
from capabilities.gripper.grasp import Grasp, grasp_manifest
from capabilities.jobs import job_from_handle
from capabilities.kit import manifest
from capabilities.motion.backend import ARM
from capabilities.motion.symmetry import SymmetryTable
from engine.operations import Job, OperationCall, OperationKind

__all__ = ["capability"]

CAP = "gripper"


OPEN = manifest(
    CAP, "open", OperationKind.ACTION, "Opens the gripper fully, releasing what it holds."
)
CLOSE = manifest(
    CAP,
    "close",
    OperationKind.ACTION,
    "Closes the gripper until the fingers meet or stop on an object (see gripper.is_holding).",
)
IS_CLOSED = manifest(CAP, "is_closed", OperationKind.CONDITION, "True when the gripper is closed.")
IS_HOLDING = manifest(
    CAP, "is_holding", OperationKind.CONDITION, "True when the closed gripper holds something."
)


class Open:
    """gripper.open: a Job until the fingers stop."""

    def __init__(self, gripper: GripperBackend) -> None:
        self._gripper = gripper

    def start(self, call: OperationCall) -> Job:
        return job_from_handle(self._gripper.open(), "open the gripper")


class Close:
    """gripper.close: a Job until the fingers stop (on an object or each other)."""

    def __init__(self, gripper: GripperBackend) -> None:
        self._gripper = gripper

    def start(self, call: OperationCall) -> Job:
        return job_from_handle(self._gripper.close(), "close the gripper")


class IsClosed:
    """gripper.is_closed."""

    def __init__(self, gripper: GripperBackend) -> None:
        self._gripper = gripper

    def start(self, call: OperationCall) -> Job:
        return Job.answer(self._gripper.is_closed())


class IsHolding:
    """gripper.is_holding."""

    def __init__(self, gripper: GripperBackend) -> None:
        self._gripper = gripper

    def start(self, call: OperationCall) -> Job:
        return Job.answer(self._gripper.is_holding())


def _suction(env: CapabilityEnv) -> HeldSuctionTool | None:
    try:
        return env.interface(SUCTION)
    except CapabilityError:
        return None  # grasps made with the suction tool then say the cell has none


def capability(symmetries: SymmetryTable | None = None) -> Capability:
    """The gripper capability (requires ``gripper`` and ``arm``; grasp reads ``suction``
    when the cell has one).
    """
    table = symmetries if symmetries is not None else SymmetryTable()
    cap = Capability(
        CAP,
        "Opens and closes the parallel gripper; grasps objects with their models' grasps.",
        requires=(GRIPPER, ARM),
    )

    def gripper(env: CapabilityEnv) -> GripperBackend:
        return env.interface(GRIPPER)

    cap.add(OPEN, lambda env: Open(gripper(env)))
    cap.add(CLOSE, lambda env: Close(gripper(env)))
    cap.add(IS_CLOSED, lambda env: IsClosed(gripper(env)))
    cap.add(IS_HOLDING, lambda env: IsHolding(gripper(env)))
    cap.add(
        grasp_manifest(CAP, table.grasp_names()),
        lambda env: Grasp(env.interface(ARM), gripper(env), _suction(env), table),
    )
    return cap
