"""Operations of the freedrive capability: start and stop hand guiding, record a waypoint."""

from __future__ import annotations

import threading
from collections.abc import Callable

from capabilities.base import Capability, CapabilityEnv
from capabilities.freedrive.backend import FREEDRIVE, FreedriveBackend
from capabilities.kit import manifest
from engine.operations import (
    Direction,
    Job,
    OperationCall,
    OperationFailed,
    OperationKind,
    PortSpec,
)
from engine.types import JointConfig, ParamType, Waypoint, WaypointFrame

__all__ = ["capability"]

CAP = "freedrive"

START = manifest(CAP, "start", OperationKind.ACTION, "Lets the worker guide the arm by hand.")
STOP = manifest(CAP, "stop", OperationKind.ACTION, "Ends hand guiding; the arm holds where it is.")
RECORD_WAYPOINT = manifest(
    CAP,
    "record_waypoint",
    OperationKind.QUERY,
    "Records where the arm is now as a waypoint (typically after guiding it by hand).",
    PortSpec("name", (ParamType.TEXT,), default="waypoint", doc="the waypoint's name"),
    PortSpec(
        "frame",
        (ParamType.TEXT,),
        default="world",
        choices=("world", "joints"),
        doc="world: the tool pose; joints: the joint positions",
    ),
    PortSpec("waypoint", (ParamType.WAYPOINT,), Direction.OUT, doc="the recorded waypoint"),
)


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


class SetFreedrive:
    """freedrive.start / freedrive.stop."""

    def __init__(self, backend: FreedriveBackend, on: bool) -> None:
        self._backend = backend
        self._on = on

    def start(self, call: OperationCall) -> Job:
        describe = "start freedrive" if self._on else "stop freedrive"
        return _off_thread(lambda: self._backend.set_freedrive(self._on), describe)


class RecordWaypoint:
    """freedrive.record_waypoint: the tool pose or joints now, as a named waypoint."""

    def __init__(self, backend: FreedriveBackend) -> None:
        self._backend = backend

    def start(self, call: OperationCall) -> Job:
        name = call.input("name").strip()
        if not name:
            raise OperationFailed("the waypoint needs a name")
        frame = call.input("frame")
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

    def backend(env: CapabilityEnv) -> FreedriveBackend:
        return env.interface(FREEDRIVE)

    cap.add(START, lambda env: SetFreedrive(backend(env), True))
    cap.add(STOP, lambda env: SetFreedrive(backend(env), False))
    cap.add(RECORD_WAYPOINT, lambda env: RecordWaypoint(backend(env)))
    return cap
