"""RGB-D frames over a loopback socket: the emulated cell's cameras seen from another process.

The UR emulator renders its simulated cell's cameras in its own process and serves them on
``FRAME_PORT`` (not a UR port: the emulator stands for the whole cell, cameras included). A
client sends a camera's name on a line; the server answers one JSON line (``{"ok": true,
"width", "height", "K", "T_world_camera", "stamp"}`` or ``{"ok": false, "error"}``), then the
colour (height x width x 3 bytes) and the depth (height x width little-endian float32 metres,
NaN: no reading). :class:`StreamCamera` is the camera source of such a stream.
"""

from __future__ import annotations

import json
import socket
import threading
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from capabilities.camera_source import CameraSource, RGBDFrame
from capabilities.errors import CapabilityError
from engine.json_reader import JsonReader, errors_as, parse_json
from engine.types import ParamType, Pose

__all__ = ["FRAME_PORT", "StreamCamera", "StreamCameraError", "serve_frames"]

FRAME_PORT = 30500
_MAX_PIXELS = 4096 * 4096


class StreamCameraError(CapabilityError):
    """The frame server is not there, or sent something that is not a frame."""


def _read(sock: socket.socket, size: int) -> bytes:
    chunks, left = [], size
    while left:
        chunk = sock.recv(min(left, 1 << 20))
        if not chunk:
            raise OSError("the frame server closed the connection")
        chunks.append(chunk)
        left -= len(chunk)
    return b"".join(chunks)


def _read_line(sock: socket.socket) -> bytes:
    line = b""
    while not line.endswith(b"\n"):
        line += _read(sock, 1)
    return line


class StreamCamera:
    """A camera source whose frames come from a frame server (``host:port``).

    Args:
        name: the camera's name (asked of the server and used in this cell).
        address: "host:port" (port default ``FRAME_PORT``).
    """

    def __init__(self, name: str, address: str) -> None:
        host, _, port = address.partition(":")
        self.name = name
        self.on_wrist = False  # frames carry their pose: the server knows where the wrist is
        self._address = (host, int(port) if port else FRAME_PORT)
        self._lock = threading.Lock()
        self._socket: socket.socket | None = None
        self._calibrated: Pose | None = None
        self._last: RGBDFrame | None = None

    @property
    def intrinsics(self) -> np.ndarray:
        return (self._last or self.capture()).K

    def extrinsics(self) -> Pose:
        if self._calibrated is not None:
            return self._calibrated
        return (self._last or self.capture()).T_world_camera

    def set_extrinsics(self, pose: Pose) -> None:
        self._calibrated = pose

    def capture(self, max_width: int | None = None) -> RGBDFrame:
        """The camera's next frame (blocks the calling worker thread)."""
        with self._lock:
            try:
                frame = self._fetch()
            except OSError as exc:
                if self._socket is not None:
                    self._socket.close()
                    self._socket = None
                raise StreamCameraError(
                    f"camera {self.name}: no frame from {self._address[0]}:{self._address[1]}: "
                    f"{exc}"
                ) from exc
        self._last = frame
        return frame.at_most(max_width)

    def _fetch(self) -> RGBDFrame:
        if self._socket is None:
            self._socket = socket.create_connection(self._address, timeout=10.0)
        sock = self._socket
        sock.sendall(self.name.encode("utf-8") + b"\n")
        where = f"{self._address[0]}:{self._address[1]}"
        with errors_as(StreamCameraError):
            r = JsonReader(parse_json(_read_line(sock).decode("utf-8"), where, "frame"), where)
            if not r.flag("ok"):
                raise StreamCameraError(f"camera {self.name}: {r.text('error', '?')}")
            width, height = r.integer("width", lo=1), r.integer("height", lo=1)
            if width * height > _MAX_PIXELS:
                r.fail("a frame of at most 4096 x 4096 pixels", key="width")
            k = np.array([r.at("K").at(i).as_vector(3) for i in range(3)])
            pose = r.typed("T_world_camera", ParamType.POSE)
            stamp = r.number("stamp")
        rgb = np.frombuffer(_read(sock, width * height * 3), np.uint8).reshape(height, width, 3)
        depth = np.frombuffer(_read(sock, width * height * 4), "<f4").reshape(height, width)
        return RGBDFrame(
            rgb.copy(), depth.astype(np.float32), k, self._calibrated or pose, stamp, self.name
        )


def frame_header(frame: RGBDFrame) -> dict[str, Any]:
    height, width = frame.depth.shape
    pose = frame.T_world_camera
    return {
        "ok": True,
        "width": width,
        "height": height,
        "K": np.asarray(frame.K).tolist(),
        "T_world_camera": {"position": list(pose.position), "orientation": list(pose.orientation)},
        "stamp": float(frame.stamp),
    }


def serve_frames(
    cameras: Mapping[str, CameraSource],
) -> Callable[[socket.socket, Any, threading.Event], None]:
    """A client handler (for the emulator's servers) that answers frames of ``cameras``."""

    def handle(conn: socket.socket, _ctl: Any, stop: threading.Event) -> None:
        while not stop.is_set():
            name = _read_line(conn).decode("utf-8", "replace").strip()
            camera = cameras.get(name)
            if camera is None:
                error = {"ok": False, "error": f"no camera {name!r} (cameras: {sorted(cameras)})"}
                conn.sendall(json.dumps(error).encode() + b"\n")
                continue
            frame = camera.capture()
            rgb = np.ascontiguousarray(frame.rgb[..., :3], dtype=np.uint8)
            depth = np.ascontiguousarray(frame.depth, dtype="<f4")
            conn.sendall(json.dumps(frame_header(frame)).encode() + b"\n")
            conn.sendall(rgb.tobytes())
            conn.sendall(depth.tobytes())

    return handle
