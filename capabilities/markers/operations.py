"""Operations of the markers capability.

``detect_markers`` looks once through a camera (on a worker thread: rendering or grabbing a
frame takes tens of milliseconds) and stores what it saw in the cell's world model: marker
poses, and the pose of every object that carries a seen marker. The queries and conditions
then read the world model, so they answer at once.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from capabilities.base import Capability, CapabilityEnv
from capabilities.kit import CAMERAS, camera, manifest, stateful
from capabilities.markers.backend import CameraDevice
from capabilities.world_model import Detection, WorldModel
from engine.error_types import ErrorType
from engine.operations import (
    Direction,
    Job,
    OperationCall,
    OperationFailed,
    OperationKind,
    PortSpec,
)
from engine.types import ObjectModel, ParamType, Pose

if TYPE_CHECKING:
    from capabilities.markers.detection import MarkerObservation

# Detection and calibration (OpenCV, numpy) are imported where an operation runs, so the
# manifests (costar ops, validation, XML) load without them.

__all__ = ["capability"]

CAP = "markers"
# A detection whose pose is ambiguous (a marker seen almost face-on) is kept but trusted less.
MIN_CONFIDENCE = 0.05


def _camera_port(default: str = "shoulder") -> PortSpec:
    return PortSpec(
        "camera", (ParamType.TEXT,), default=default, doc="which camera looks", choices=CAMERAS
    )


def _object_port() -> PortSpec:
    return PortSpec("object", (ParamType.OBJECT,), doc="the object (by its model name)")


class _Env:
    """The interfaces every markers operation uses, taken from the cell once."""

    def __init__(self, env: CapabilityEnv) -> None:
        self.env = env
        self.world: WorldModel = env.interface("world")
        self.workers = env.interface("workers")
        self.layout = env.interface("scene_layout")
        self.library = env.interface("objects")

    def camera(self, name: str) -> CameraDevice:
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


class DetectMarkers:
    def __init__(self, env: _Env) -> None:
        self._env = env

    def start(self, call: OperationCall) -> Job:
        from capabilities.markers.depth import refine_with_depth
        from capabilities.markers.detection import detect_markers, marker_pose_world

        camera = self._env.camera(call.input("camera"))
        env = self._env

        def look() -> dict[str, Any]:
            frame = camera.capture()
            sizes = env.layout["marker_sizes"]
            observations = detect_markers(frame.rgb, frame.K, sizes)
            if frame.depth is not None:
                observations = [refine_with_depth(o, frame.depth, frame.K) for o in observations]
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


class MarkerPose:
    def __init__(self, env: _Env) -> None:
        self._env = env

    def start(self, call: OperationCall) -> Job:
        marker_id = int(call.input("marker_id"))
        found = self._env.world.marker(marker_id)
        if found is None:
            raise OperationFailed(f"marker {marker_id} has not been seen", ErrorType.NOT_FOUND)
        call.write("pose", found[0])
        return Job.done()


def _best(env: _Env, model: Any) -> Detection | None:
    name = model.name if isinstance(model, ObjectModel) else str(model)
    return env.world.best(name)


class ObjectPose:
    def __init__(self, env: _Env) -> None:
        self._env = env

    def start(self, call: OperationCall) -> Job:
        detection = _best(self._env, call.input("object"))
        if detection is None:
            raise OperationFailed(
                f"{call.input('object').name} has not been seen", ErrorType.NOT_FOUND
            )
        call.write("pose", detection.pose)
        return Job.done()


class ObjectFound:
    def __init__(self, env: _Env) -> None:
        self._env = env

    def start(self, call: OperationCall) -> Job:
        return Job.answer(_best(self._env, call.input("object")) is not None)


class CalibrateCamera:
    """Finds a fixed camera's pose from the markers of known pose (on the table, on fixtures)."""

    def __init__(self, env: _Env) -> None:
        self._env = env

    def start(self, call: OperationCall) -> Job:
        from capabilities.markers.calibration import calibrate_extrinsics
        from capabilities.markers.detection import detect_markers

        camera = self._env.camera(call.input("camera"))
        if camera.on_wrist:
            raise OperationFailed(
                "the wrist camera is calibrated by hand-eye calibration, not here"
            )
        env = self._env
        max_rms = call.input("max_error_px")

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
    cap = Capability(
        CAP,
        "Finds ArUco markers in camera images; object poses and camera calibration from them.",
        requires=("world", "workers", "scene_layout", "objects", "rgbd:shoulder"),
        setup=_Env,  # the per-cell state: the interfaces every markers operation uses
    )

    cap.add(
        manifest(
            CAP,
            "detect_markers",
            OperationKind.ACTION,
            "Looks through a camera and remembers every marker and marked object it sees.",
            _camera_port(),
            PortSpec("count", (ParamType.NUMBER,), Direction.OUT, doc="how many markers were seen"),
        ),
        stateful(DetectMarkers),
    )
    cap.add(
        manifest(
            CAP,
            "marker_pose",
            OperationKind.QUERY,
            "The pose of a marker last seen.",
            PortSpec("marker_id", (ParamType.NUMBER,), doc="the marker's id"),
            PortSpec("pose", (ParamType.POSE,), Direction.OUT, doc="where it is"),
        ),
        stateful(MarkerPose),
    )
    cap.add(
        manifest(
            CAP,
            "object_pose",
            OperationKind.QUERY,
            "The pose of an object, from its marker.",
            _object_port(),
            PortSpec("pose", (ParamType.POSE,), Direction.OUT, doc="where the object is"),
        ),
        stateful(ObjectPose),
    )
    cap.add(
        manifest(
            CAP,
            "object_found",
            OperationKind.CONDITION,
            "True when the object's marker was seen.",
            _object_port(),
        ),
        stateful(ObjectFound),
    )
    cap.add(
        manifest(
            CAP,
            "calibrate_camera",
            OperationKind.ACTION,
            "Finds a fixed camera's pose from the markers of known pose (table, fixtures).",
            _camera_port(),
            PortSpec(
                "max_error_px",
                (ParamType.NUMBER,),
                default=1.5,
                unit="px",
                doc="refuse a calibration worse than this",
            ),
        ),
        stateful(CalibrateCamera),
    )
    return cap
