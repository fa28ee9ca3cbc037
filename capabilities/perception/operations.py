"""Operations of the perception capability (paper IV-B's Perceptor).

``detect_objects`` looks once through a camera and, on a worker thread, recognises the
library's objects on the table (:class:`Recognizer`), gives them identities that persist
between looks (:class:`SurfaceTracker`) and stores them in the cell's world model under the
source ``perception:<camera>``. The conditions and queries read the world model and answer
at once.

The recogniser (its sampled models) and the trackers are shared by every operation of one
capability instance and one cell: they are kept per object library and per world model.
"""

from __future__ import annotations

import math
import threading
import weakref
from typing import TYPE_CHECKING, Any

from capabilities.arm_looks import ArmLooks, fail_if_occluded
from capabilities.base import Capability, CapabilityEnv
from capabilities.kit import (
    OperationKind,
    StatefulOperation,
    camera,
    camera_port,
    manifest,
    number,
    object_model,
    output,
    pose,
)
from capabilities.perception.config import SETTINGS, RecognitionConfig
from capabilities.perception.errors import PerceptionError
from capabilities.world_model import Detection, WorldModel
from engine.error_types import ErrorType
from engine.operations import Job, OperationCall, OperationFailed
from engine.types import ObjectModel, ParamType, Pose

__all__ = ["SOURCE_PREFIX", "capability"]

if TYPE_CHECKING:  # recognition (numpy, Open3D, OpenCV) loads when a cell first recognises
    from capabilities.perception.recognizer import Recognizer
    from capabilities.perception.tracker import SurfaceTracker

CAP = "perception"
SOURCE_PREFIX = "perception:"


class _Shared:
    """What the operations of one capability instance share: recognisers by object library,
    trackers by (world model, camera). Weak keys: a closed cell takes its state with it.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._recognizers: weakref.WeakKeyDictionary[Any, Recognizer] = weakref.WeakKeyDictionary()
        self._trackers: weakref.WeakKeyDictionary[Any, dict[str, SurfaceTracker]] = (
            weakref.WeakKeyDictionary()
        )

    def recognizer(self, library: Any, config: RecognitionConfig) -> Recognizer:
        from capabilities.perception.recognizer import Recognizer

        with self._lock:
            found = self._recognizers.get(library)
            if found is None or found.config != config:
                found = self._recognizers[library] = Recognizer(library, config)
            return found

    def tracker(self, world: Any, camera: str, library: Any) -> SurfaceTracker:
        from capabilities.perception.tracker import SurfaceTracker

        with self._lock:
            per_camera = self._trackers.setdefault(world, {})
            if camera not in per_camera:
                symmetries = {name: library.get(name).symmetry for name in library.names()}
                per_camera[camera] = SurfaceTracker(symmetries=symmetries)
            return per_camera[camera]


class _Env:
    """The interfaces every perception operation uses, taken from the cell once."""

    def __init__(self, env: CapabilityEnv, shared: _Shared) -> None:
        self.env = env
        self.shared = shared
        self.world: WorldModel = env.interface("world")
        self.workers = env.interface("workers")
        self.library = env.interface("objects")
        self.config = RecognitionConfig.from_settings(env.settings)
        self.looks = ArmLooks(
            env.cell.interfaces().get("arm"),
            (self.config.workspace_min, self.config.workspace_max),
        )

    def camera(self, name: str) -> Any:
        """The cell's camera ``name``."""
        return camera(self.env, name)

    def seen(self, model: Any) -> list[Detection]:
        """Current perception detections of a class, best first."""
        name = model.name if isinstance(model, ObjectModel) else str(model)
        return [d for d in self.world.detections(name) if d.source.startswith(SOURCE_PREFIX)]


CAMERA = camera_port()
OBJECT = object_model("object", doc="the object class (a model name)")


class DetectObjects(StatefulOperation[_Env]):
    """perception.detect_objects: one look, recognised on a worker thread."""

    MANIFEST = manifest(
        CAP,
        "detect_objects",
        OperationKind.ACTION,
        "Looks through a camera and recognises the known objects on the table "
        "(point cloud matched to the object models).",
        CAMERA,
        output("count", ParamType.NUMBER, doc="how many objects were recognised"),
    )

    def start(self, call: OperationCall) -> Job:
        env = self._state
        camera = env.camera(call.input(CAMERA))
        recognizer = env.shared.recognizer(env.library, env.config)
        tracker = env.shared.tracker(env.world, camera.name, env.library)
        source = f"{SOURCE_PREFIX}{camera.name}"

        def look() -> dict[str, Any]:
            frame = camera.capture()
            glance = env.looks.glance(camera, frame)
            try:
                found = recognizer.recognize(frame)
            except PerceptionError as exc:
                env.world.replace(source, [])
                fail_if_occluded(glance, str(exc))
                raise OperationFailed(f"{camera.name} camera: {exc}") from exc
            if not found:
                fail_if_occluded(glance, "no objects were recognised")
            tracked = tracker.update(found, frame.stamp)
            detections = [
                Detection(r.object_class, r.pose, r.confidence, frame.stamp, source, instance)
                for instance, r in tracked
            ]
            env.world.replace(source, detections)
            names = sorted(instance for instance, _ in tracked)
            call.log(
                f"{camera.name} camera: {', '.join(names) or 'no objects'} "
                f"({1000 * recognizer.last_seconds:.0f} ms)"
            )
            return {"count": float(len(detections))}

        job: Job = env.workers.submit(look, f"detect objects ({camera.name} camera)")
        return job


class ObjectFound(StatefulOperation[_Env]):
    """perception.object_found."""

    MANIFEST = manifest(
        CAP,
        "object_found",
        OperationKind.CONDITION,
        "True when the last look recognised an object of this class.",
        OBJECT,
    )

    def start(self, call: OperationCall) -> Job:
        if self._state.seen(call.input(OBJECT)):
            return Job.answer(True)
        return Job.answer(
            False, f"{_name(call.input(OBJECT))} not seen{self._state.looks.hidden()}"
        )


class ObjectPose(StatefulOperation[_Env]):
    """perception.object_pose: the most confident detection's pose."""

    MANIFEST = manifest(
        CAP,
        "object_pose",
        OperationKind.QUERY,
        "The pose of the most confidently recognised object of a class.",
        OBJECT,
        output("pose", ParamType.POSE, doc="where the object is"),
    )

    def start(self, call: OperationCall) -> Job:
        seen = self._state.seen(call.input(OBJECT))
        if not seen:
            raise OperationFailed(
                f"{_name(call.input(OBJECT))} has not been seen{self._state.looks.hidden()}",
                ErrorType.NOT_FOUND,
            )
        call.write("pose", seen[0].pose)
        return Job.done()


class ObjectsOfClass(StatefulOperation[_Env]):
    """perception.objects_of_class: how many, and their poses."""

    MANIFEST = manifest(
        CAP,
        "objects_of_class",
        OperationKind.QUERY,
        "How many objects of a class the last look recognised, and their poses.",
        OBJECT,
        output("count", ParamType.NUMBER, doc="how many"),
        output("poses", ParamType.ANY, doc="their poses, most confident first"),
    )

    def start(self, call: OperationCall) -> Job:
        seen = self._state.seen(call.input(OBJECT))
        call.write("count", float(len(seen)))
        call.write("poses", [d.pose for d in seen])
        return Job.done()


class PlateType(StatefulOperation[_Env]):
    """perception.plate_type: the plate model nearest a pose."""

    NEAR = pose("near", Pose(), doc="the plate nearest this pose (default: nearest the robot base)")
    WITHIN = number("within", 2.0, unit="m", doc="fail when the nearest plate is farther than this")
    MANIFEST = manifest(
        CAP,
        "plate_type",
        OperationKind.QUERY,
        "Which plate (by its holes) lies nearest to a pose.",
        NEAR,
        WITHIN,
        output("model", ParamType.OBJECT, doc="the plate's model"),
        output("pose", ParamType.POSE, doc="where the plate is"),
    )

    def start(self, call: OperationCall) -> Job:
        near = call.input(self.NEAR)
        within = call.input(self.WITHIN)
        plates = [
            d
            for name in self._state.library.names()
            if self._state.library.get(name).extra.get("holes")
            for d in self._state.seen(name)
        ]
        ranked = sorted(plates, key=lambda d: math.dist(d.pose.position, near.position))
        if not ranked or math.dist(ranked[0].pose.position, near.position) > within:
            raise OperationFailed(
                f"no plate seen within {within:g} m of {near.position}", ErrorType.NOT_FOUND
            )
        call.write("model", ObjectModel(ranked[0].object_class))
        call.write("pose", ranked[0].pose)
        return Job.done()


def _name(model: Any) -> str:
    return model.name if isinstance(model, ObjectModel) else str(model)


def capability() -> Capability:
    """The perception capability; its per-cell state is the interfaces and the recognisers."""
    cap = Capability(
        CAP,
        "Recognises the library's objects on the table in RGB-D point clouds; plate types.",
        requires=("world", "workers", "objects", "rgbd:shoulder"),
        settings=SETTINGS,
        setup=lambda env: _Env(env, _Shared()),
    )
    cap.add(DetectObjects, ObjectFound, ObjectPose, ObjectsOfClass, PlateType)
    return cap
