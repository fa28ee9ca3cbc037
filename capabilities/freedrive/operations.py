"""Operations of the freedrive capability: start and stop hand guiding, record a waypoint."""

from __future__ import annotations

import threading
from collections.abc import Callable

from capabilities.base import Capability, CapabilityEnv
from capabilities.freedrive.backend import FREEDRIVE, FreedriveBackend
from capabilities.kit import OperationKind, manifest, output, text
from engine.operations import Job, OperationCall, OperationFailed
from engine.types import JointConfig, ParamType, Waypoint, WaypointFrame

__all__ = ["capability"]

CAP = "freedrive"


def _off_thread(fn: Callable[[], None], describe: str) -> Job:
    """Run a short blocking backend call in its own thread; the Job finishes with it."""
    job = Job()

    def run() -> None:
        try:
            fn()
        except Exception as exc:  # a backend error fails the node, never the engine
            job.fail(f"{describe}: {type(exc).__name__}: {exc}")
        else:
            job.succeed()

    threading.Thread(target=run, name=f"costar-{CAP}", daemon=True).start()
    return job


class _FreedriveOp:
    """An operation on the cell's freedrive backend."""

    def __init__(self, env: CapabilityEnv) -> None:
        self._backend: FreedriveBackend = env.interface(FREEDRIVE)


class Start(_FreedriveOp):
    """freedrive.start."""

    MANIFEST = manifest(
        CAP, "start", OperationKind.ACTION, "Lets the worker guide the arm by hand."
    )

    def start(self, call: OperationCall) -> Job:
        return _off_thread(lambda: self._backend.set_freedrive(True), "start freedrive")


class Stop(_FreedriveOp):
    """freedrive.stop."""

    MANIFEST = manifest(
        CAP, "stop", OperationKind.ACTION, "Ends hand guiding; the arm holds where it is."
    )

    def start(self, call: OperationCall) -> Job:
        return _off_thread(lambda: self._backend.set_freedrive(False), "stop freedrive")


class RecordWaypoint(_FreedriveOp):
    """freedrive.record_waypoint: the tool pose or joints now, as a named waypoint."""

    NAME = text("name", "waypoint", doc="the waypoint's name")
    FRAME = text(
        "frame",
        "world",
        choices=("world", "joints"),
        doc="world: the tool pose; joints: the joint positions",
    )
    MANIFEST = manifest(
        CAP,
        "record_waypoint",
        OperationKind.QUERY,
        "Records where the arm is now as a waypoint (typically after guiding it by hand).",
        NAME,
        FRAME,
        output("waypoint", ParamType.WAYPOINT, doc="the recorded waypoint"),
    )

    def start(self, call: OperationCall) -> Job:
        name = call.input(self.NAME).strip()
        if not name:
            raise OperationFailed("the waypoint needs a name")
        frame = call.input(self.FRAME)
        if frame == "world":
            waypoint = Waypoint(name, WaypointFrame.WORLD, pose=self._backend.tcp_pose())
        else:  # "joints" (the port's choices)
            joints = JointConfig(self._backend.joint_positions())
            waypoint = Waypoint(name, WaypointFrame.JOINTS, joints=joints)
        call.write("waypoint", waypoint)
        return Job.done()


def capability() -> Capability:
    """The freedrive capability (requires ``freedrive``)."""
    cap = Capability(
        CAP, "Hand guiding of the arm and recording where it is.", requires=(FREEDRIVE,)
    )
    cap.add(Start, Stop, RecordWaypoint)
    return cap
