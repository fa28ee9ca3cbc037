"""Helpers of the occupancy tests: run one operation outside a tree, place boxes in the sim."""

from __future__ import annotations

import threading
import time
from typing import Any

import pybullet

from capabilities.base import CapabilityRegistry
from capabilities.sim.session import SimCellSession
from engine.operations import OperationCall, OperationFailed, typed_input
from engine.status import RUNNING, SUCCESS, Status
from engine.types import Pose

__all__ = ["Outcome", "run_op", "add_fixed_box", "remove_body"]


class Outcome:
    """How an operation ended: status, message, outputs."""

    def __init__(self, status: Status, message: str, outputs: dict[str, Any]) -> None:
        self.status, self.message, self.outputs = status, message, outputs

    @property
    def ok(self) -> bool:
        return self.status is SUCCESS

    def __repr__(self) -> str:
        return f"Outcome({self.status.value}, {self.message!r})"


def run_op(
    registry: CapabilityRegistry, op_id: str, deadline: float = 60.0, **args: Any
) -> Outcome:
    """Start an operation with its defaults and ``args``, poll its job to the end (woken by
    the job, as the engine is; ``deadline`` is a generous real-time bound).
    """
    operation = registry.create(op_id)
    manifest = registry.manifest(op_id)
    woken = threading.Event()
    outputs: dict[str, Any] = {}
    call = OperationCall(
        "node", op_id, {p.name: p.name for p in manifest.outputs},
        lambda key, value, _w: outputs.__setitem__(key, value),
        lambda _n, _m: None, woken.set, registry.cell.clock,
    )  # fmt: skip
    given = {p.name: p.default for p in manifest.inputs} | args
    call.args = {p.name: typed_input(p, given[p.name]) for p in manifest.inputs if p.name in given}
    try:
        result = operation.start(call)
    except OperationFailed as exc:  # the leaf turns a raise into FAILURE with the message
        return Outcome(Status.FAILURE, str(exc), outputs)
    result.bind_wake(woken.set)
    end = time.monotonic() + deadline
    while (status := result.poll()) is RUNNING:
        assert time.monotonic() < end, f"{op_id} did not finish"
        woken.wait(0.02)  # also polls on a timer, as the executor ticks at a rate
        woken.clear()
    return Outcome(status, result.message, {**outputs, **result.outputs})


def add_fixed_box(session: SimCellSession, pose: Pose, size: float = 0.05) -> int:
    """A static cube of side ``size`` at ``pose`` (no physics: it stays where it is put)."""
    half = [size / 2] * 3

    def create(client: int) -> int:
        shape = pybullet.createCollisionShape(
            pybullet.GEOM_BOX, halfExtents=half, physicsClientId=client
        )
        visual = pybullet.createVisualShape(
            pybullet.GEOM_BOX,
            halfExtents=half,
            rgbaColor=(0.8, 0.3, 0.2, 1.0),
            physicsClientId=client,
        )
        return int(pybullet.createMultiBody(0.0, shape, visual, basePosition=pose.position,
                                            baseOrientation=pose.orientation,
                                            physicsClientId=client))  # fmt: skip

    return session.sim.call(create)


def remove_body(session: SimCellSession, body: int) -> None:
    session.sim.call(lambda client: pybullet.removeBody(body, physicsClientId=client))
