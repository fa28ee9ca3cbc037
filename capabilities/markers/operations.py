"""Operations of the markers capability.

``detect_markers`` looks once through a camera (on a worker thread: rendering or grabbing a
frame takes tens of milliseconds) and stores what it saw in the cell's world model: marker
poses, and the pose of every object that carries a seen marker. The queries and conditions
then read the world model, so they answer at once.
"""

from __future__ import annotations

from collections.abc import Mapping
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
)
from capabilities.markers.backend import CameraDevice
from capabilities.world_model import Detection, WorldModel
from engine.error_types import ErrorType
from engine.operations import Job, OperationCall, OperationFailed
from engine.types import ObjectModel, ParamType, Pose

if TYPE_CHECKING:
    from capabilities.markers.detection import MarkerObservation

# Detection and calibration (OpenCV, numpy) are imported where an operation runs, so the
# manifests (costar ops, validation, XML) load without them.

__all__ = ["capability"]

CAP = "markers"
# A detection whose pose is ambiguous (a marker seen almost face-on) is kept but trusted less.
MIN_CONFIDENCE = 0.05


CAMERA = camera_port()
OBJECT = object_model("object", doc="the object (by its model name)")


class _Env:
    """The interfaces every markers operation uses, taken from the cell once."""

    def __init__(self, env: CapabilityEnv) -> None:
        self.env = env
        self.world: WorldModel = env.interface("world")
        self.workers = env.interface("workers")
        self.layout = env.interface("scene_layout")
        self.library = env.interface("objects")
        self.looks = ArmLooks(env.cell.interfaces().get("arm"))

    def camera(self, name: str) -> CameraDevice:
        """The cell's camera ``name``."""
        return camera(self.env, name)

    def markers_on_objects(self) -> dict[int, tuple[str, Pose]]:
        """Marker id -> (object model name, marker pose in the object frame)."""
        found: dict[int, tuple[str, Pose]] = {}
        for name in self.library.names():
            for marker in self.library.get(name).markers:
                found[marker.marker_id] = (name, marker.pose)
        return found


def _object_detections(
    seen: Mapping[int, tuple[MarkerObservation, Pose]],
    carriers: Mapping[int, tuple[str, Pose]],
    stamp: float,
    source: str,
) -> list[Detection]:
    """One detection per object: from its most confident visible marker."""
    from capabilities.markers.detection import object_pose_from_marker

    best: dict[str, Detection] = {}
    for marker_id, (observation, world_pose) in seen.items():
        if marker_id not in carriers or observation.confidence < MIN_CONFIDENCE:
            continue
        name, in_object = carriers[marker_id]
        pose = object_pose_from_marker(world_pose, in_object)
        candidate = Detection(
            name, pose, observation.confidence, stamp, source, f"marker {marker_id}"
        )
        if name not in best or candidate.confidence > best[name].confidence:
            best[name] = candidate
    return list(best.values())


class DetectMarkers(StatefulOperation[_Env]):
    """markers.detect_markers: one look, on a worker thread, into the world model."""

    MANIFEST = manifest(
        CAP,
        "detect_markers",
        OperationKind.ACTION,
        "Looks through a camera and remembers every marker and marked object it sees.",
        CAMERA,
        output("count", ParamType.NUMBER, doc="how many markers were seen"),
    )

    def start(self, call: OperationCall) -> Job:
        from capabilities.markers.depth import refine_with_depth
        from capabilities.markers.detection import detect_markers, marker_pose_world

        camera = self._state.camera(call.input(CAMERA))
        env = self._state

        def look() -> dict[str, Any]:
            frame = camera.capture()
            glance = env.looks.glance(camera, frame)
            sizes = env.layout["marker_sizes"]
            observations = detect_markers(frame.rgb, frame.K, sizes)
            if frame.depth is not None:
                observations = [refine_with_depth(o, frame.depth, frame.K) for o in observations]
            if not observations:
                fail_if_occluded(glance, "no markers were seen")
            seen = {
                o.marker_id: (o, marker_pose_world(o, frame.T_world_camera)) for o in observations
            }
            env.world.set_markers({k: pose for k, (_, pose) in seen.items()}, frame.stamp)
            source = f"markers:{camera.name}"
            objects = _object_detections(seen, env.markers_on_objects(), frame.stamp, source)
            env.world.replace(source, objects)
            call.log(
                f"{camera.name} camera: markers {sorted(seen) or 'none'}; "
                f"objects {sorted(d.object_class for d in objects) or 'none'}"
            )
            return {"count": float(len(seen))} if "count" in call.outputs else {}

        job: Job = env.workers.submit(look, f"detect markers ({camera.name} camera)")
        return job


class MarkerPose(StatefulOperation[_Env]):
    """markers.marker_pose: where a marker was last seen."""

    MARKER_ID = number("marker_id", doc="the marker's id")
    MANIFEST = manifest(
        CAP,
        "marker_pose",
        OperationKind.QUERY,
        "The pose of a marker last seen.",
        MARKER_ID,
        output("pose", ParamType.POSE, doc="where it is"),
    )

    def start(self, call: OperationCall) -> Job:
        marker_id = int(call.input(self.MARKER_ID))
        found = self._state.world.marker(marker_id)
        if found is None:
            raise OperationFailed(
                f"marker {marker_id} has not been seen{self._state.looks.hidden()}",
                ErrorType.NOT_FOUND,
            )
        call.write("pose", found[0])
        return Job.done()


def _best(env: _Env, model: Any) -> Detection | None:
    name = model.name if isinstance(model, ObjectModel) else str(model)
    return env.world.best(name)


class ObjectPose(StatefulOperation[_Env]):
    """markers.object_pose: an object's pose from its marker."""

    MANIFEST = manifest(
        CAP,
        "object_pose",
        OperationKind.QUERY,
        "The pose of an object, from its marker.",
        OBJECT,
        output("pose", ParamType.POSE, doc="where the object is"),
    )

    def start(self, call: OperationCall) -> Job:
        detection = _best(self._state, call.input(OBJECT))
        if detection is None:
            raise OperationFailed(
                f"{call.input(OBJECT).name} has not been seen{self._state.looks.hidden()}",
                ErrorType.NOT_FOUND,
            )
        call.write("pose", detection.pose)
        return Job.done()


class ObjectFound(StatefulOperation[_Env]):
    """markers.object_found."""

    MANIFEST = manifest(
        CAP,
        "object_found",
        OperationKind.CONDITION,
        "True when the object's marker was seen.",
        OBJECT,
    )

    def start(self, call: OperationCall) -> Job:
        if _best(self._state, call.input(OBJECT)) is not None:
            return Job.answer(True)
        return Job.answer(False, f"{call.input(OBJECT).name} not seen{self._state.looks.hidden()}")


class CalibrateCamera(StatefulOperation[_Env]):
    """Finds a fixed camera's pose from the markers of known pose (on the table, on fixtures)."""

    MAX_ERROR_PX = number(
        "max_error_px", 1.5, unit="px", doc="refuse a calibration worse than this"
    )
    MANIFEST = manifest(
        CAP,
        "calibrate_camera",
        OperationKind.ACTION,
        "Finds a fixed camera's pose from the markers of known pose (table, fixtures).",
        CAMERA,
        MAX_ERROR_PX,
    )

    def start(self, call: OperationCall) -> Job:
        from capabilities.markers.calibration import calibrate_extrinsics
        from capabilities.markers.detection import detect_markers

        camera = self._state.camera(call.input(CAMERA))
        if camera.on_wrist:
            raise OperationFailed(
                "the wrist camera is calibrated by hand-eye calibration, not here"
            )
        env = self._state
        max_rms = call.input(self.MAX_ERROR_PX)

        def calibrate() -> dict[str, Any]:
            frame = camera.capture()
            known: Mapping[int, Pose] = env.layout["fixed_markers"]
            observations = detect_markers(frame.rgb, frame.K, env.layout["marker_sizes"])
            pose, report = calibrate_extrinsics([observations], known, frame.K)
            if report.rms_px > max_rms:
                raise OperationFailed(
                    f"calibration error {report.rms_px:.2f} px is above {max_rms:g} px"
                )
            camera.set_extrinsics(pose)
            call.log(
                f"{camera.name} camera calibrated from markers {sorted(report.inliers)}: "
                f"{report.rms_px:.3f} px"
            )
            return {}

        job: Job = env.workers.submit(calibrate, f"calibrate the {camera.name} camera")
        return job


def capability() -> Capability:
    """The markers capability; its per-cell state is the interfaces its operations use."""
    cap = Capability(
        CAP,
        "Finds ArUco markers in camera images; object poses and camera calibration from them.",
        requires=("world", "workers", "scene_layout", "objects", "rgbd:shoulder"),
        setup=_Env,  # the per-cell state: the interfaces every markers operation uses
    )
    cap.add(DetectMarkers, MarkerPose, ObjectPose, ObjectFound, CalibrateCamera)
    return cap
