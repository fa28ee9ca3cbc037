"""Opening the camera source a cell file names: recorded frames, a frame stream, a RealSense.

(The simulated cell renders its own cameras: ``capabilities.sim.session``.)
"""

from __future__ import annotations

from pathlib import Path

from capabilities.camera_source import CameraSource
from capabilities.errors import CapabilityError

__all__ = ["open_source"]


def open_source(name: str, kind: str, where: str, base: Path | None = None) -> CameraSource:
    """The camera source a cell file names (not "sim": the simulated cell makes its own).

    Args:
        name: the camera's name in the cell.
        kind: "recorded" (``where`` is the recording folder), "stream" (``where`` is the frame
            server's "host:port") or "realsense" (``where`` is the device's serial number, ""
            for the only one connected).
        where: the recording folder, the server's address or the serial number (see kind).
        base: the cell file's folder (a relative recording folder is relative to it).

    Raises:
        CapabilityError: the source cannot be opened (the message says which and why).
    """
    if kind == "recorded":
        from capabilities.recorded_frames import RecordedCamera

        folder = Path(where)
        if not folder.is_absolute() and base is not None:
            folder = base / folder
        return RecordedCamera(folder, name)
    if kind == "stream":
        from capabilities.stream_camera import StreamCamera

        return StreamCamera(name, where)
    if kind == "realsense":
        from capabilities.realsense import RealSenseCamera

        return RealSenseCamera(name, where)
    raise CapabilityError(
        f"camera {name}: source {kind!r} cannot be opened here (sources: recorded, stream, realsense)"
    )
