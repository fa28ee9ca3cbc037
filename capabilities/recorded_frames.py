"""Recorded RGB-D frames: save what any camera source gives, play it back as a camera source.

A recording is a folder::

    recording.json          {"format": "costar-rgbd-recording", "format_version": 1,
                             "camera": "shoulder", "on_wrist": false, "depth_unit": 0.0001,
                             "frames": [{"rgb": "000000.rgb.png", "depth": "000000.depth.png",
                                         "K": [[fx, 0, cx], [0, fy, cy], [0, 0, 1]],
                                         "T_world_camera": {"position", "orientation"},
                                         "stamp": 12.5}, ...]}
    000000.rgb.png          8-bit colour
    000000.depth.png        16-bit depth in ``depth_unit`` metres (0: no reading)

The depth unit of 0.1 mm keeps depth to 6.5 m. ``recording.json`` is rewritten atomically after
each frame, so a recording cut short is still readable up to its last whole frame.
"""

from __future__ import annotations

import itertools
import json
import threading
from pathlib import Path
from typing import Any

import cv2
import numpy as np

from capabilities.camera_source import CameraSource, RGBDFrame
from capabilities.errors import CapabilityError
from engine.json_reader import JsonReader, errors_as, read_json_file
from engine.plan_writer import write_atomic
from engine.types import ParamType, Pose

__all__ = ["FrameRecorder", "RecordedCamera", "RecordingError", "record"]

FORMAT = "costar-rgbd-recording"
FORMAT_VERSION = 1
INDEX = "recording.json"
DEPTH_UNIT = 1e-4  # m per depth count
_FRAME_FIELDS = ("rgb", "depth", "K", "T_world_camera", "stamp")


class RecordingError(CapabilityError):
    """A recording cannot be written or read; the message names the file (and JSON path)."""


def _pose_json(p: Pose) -> dict[str, list[float]]:
    return {"position": list(p.position), "orientation": list(p.orientation)}


class FrameRecorder:
    """Writes frames of one camera into a recording folder (created if missing).

    Args:
        folder: the recording's folder.
        camera: the camera's name.
        on_wrist: whether the camera moves with the arm.
    """

    def __init__(self, folder: str | Path, camera: str, on_wrist: bool = False) -> None:
        self.folder = Path(folder)
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise RecordingError(f"{self.folder}: cannot make the folder: {exc}") from exc
        self._index: dict[str, Any] = {
            "format": FORMAT,
            "format_version": FORMAT_VERSION,
            "camera": camera,
            "on_wrist": on_wrist,
            "depth_unit": DEPTH_UNIT,
            "frames": [],
        }

    def add(self, frame: RGBDFrame) -> None:
        """Save one frame (its images, then the index that names them)."""
        number = len(self._index["frames"])
        rgb_name, depth_name = f"{number:06d}.rgb.png", f"{number:06d}.depth.png"
        depth = np.nan_to_num(np.asarray(frame.depth, dtype=np.float64), nan=0.0)
        counts = np.clip(np.round(depth / DEPTH_UNIT), 0, 65535).astype(np.uint16)
        bgr = cv2.cvtColor(np.ascontiguousarray(frame.rgb[..., :3]), cv2.COLOR_RGB2BGR)
        for name, image in ((rgb_name, bgr), (depth_name, counts)):
            if not cv2.imwrite(str(self.folder / name), image):
                raise RecordingError(f"{self.folder / name}: cannot write the image")
        self._index["frames"].append(
            {
                "rgb": rgb_name,
                "depth": depth_name,
                "K": np.asarray(frame.K, dtype=float).tolist(),
                "T_world_camera": _pose_json(frame.T_world_camera),
                "stamp": float(frame.stamp),
            }
        )
        try:
            write_atomic(self.folder / INDEX, json.dumps(self._index, indent=1).encode("utf-8"))
        except Exception as exc:
            raise RecordingError(f"{self.folder / INDEX}: cannot write: {exc}") from exc


def record(source: CameraSource, folder: str | Path, count: int = 1) -> Path:
    """Capture ``count`` frames from ``source`` into a new recording; returns the folder."""
    recorder = FrameRecorder(folder, source.name, source.on_wrist)
    for _ in range(count):
        recorder.add(source.capture())
    return recorder.folder


class RecordedCamera:
    """A camera source that plays a recording back, frame after frame, then from the start.

    The frames keep the pose they were recorded with until :meth:`set_extrinsics` stores a
    calibration, which then applies to every frame (a fixed camera).

    Args:
        folder: the recording's folder.
        name: the camera's name in this cell (default: the recorded one).

    Raises:
        RecordingError: the folder or its index is missing or malformed.
    """

    def __init__(self, folder: str | Path, name: str | None = None) -> None:
        self.folder = Path(folder)
        index = self.folder / INDEX
        with errors_as(RecordingError):
            r = JsonReader(read_json_file(index, "frame recording"), index)
            r.as_object(("format", "format_version", "camera", "on_wrist", "depth_unit", "frames"))
            if r.text("format") != FORMAT:
                r.fail(f"format {FORMAT!r}", key="format")
            r.check_version((FORMAT_VERSION,))
            self.name = name or r.text("camera", nonempty=True)
            self.on_wrist = r.flag("on_wrist", False)
            self._unit = r.number("depth_unit", DEPTH_UNIT, above=True, lo=0.0)
            self._frames = [self._frame_entry(f) for f in r.items("frames", "frames", False)]
        if not self._frames:
            raise RecordingError(f"{index}: $.frames: expected at least one frame, got none")
        self._order = itertools.cycle(range(len(self._frames)))
        self._lock = threading.Lock()
        self._calibrated: Pose | None = None

    def _frame_entry(self, f: JsonReader) -> dict[str, Any]:
        f.as_object(_FRAME_FIELDS, _FRAME_FIELDS)
        k = f.at("K")
        if len(k.as_list("three rows")) != 3:
            k.fail("a 3x3 matrix (three rows of three numbers)")
        rows = [k.at(i).as_vector(3) for i in range(3)]
        return {
            "rgb": f.text("rgb", nonempty=True),
            "depth": f.text("depth", nonempty=True),
            "K": np.array(rows, dtype=np.float64),
            "pose": f.typed("T_world_camera", ParamType.POSE),
            "stamp": f.number("stamp"),
        }

    @property
    def intrinsics(self) -> np.ndarray:
        return np.array(self._frames[0]["K"])

    def extrinsics(self) -> Pose:
        if self._calibrated is not None:
            return self._calibrated
        pose: Pose = self._frames[0]["pose"]
        return pose

    def set_extrinsics(self, pose: Pose) -> None:
        self._calibrated = pose

    def capture(self, max_width: int | None = None) -> RGBDFrame:
        with self._lock:
            entry = self._frames[next(self._order)]
        bgr = cv2.imread(str(self.folder / entry["rgb"]), cv2.IMREAD_COLOR)
        counts = cv2.imread(str(self.folder / entry["depth"]), cv2.IMREAD_UNCHANGED)
        if bgr is None or counts is None or counts.dtype != np.uint16:
            raise RecordingError(
                f"{self.folder}: frame {entry['rgb']} / {entry['depth']} is missing or is not "
                "an 8-bit colour PNG and a 16-bit depth PNG"
            )
        depth = counts.astype(np.float32) * np.float32(self._unit)
        depth[counts == 0] = np.nan
        return RGBDFrame(
            rgb=cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB),
            depth=depth,
            K=np.array(entry["K"]),
            T_world_camera=self._calibrated or entry["pose"],
            stamp=float(entry["stamp"]),
            camera=self.name,
        ).at_most(max_width)
