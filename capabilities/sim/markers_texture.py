"""ArUco marker textures and the thin textured planes that carry them in the simulated cell.

Convention (shared with the marker-detection code): the marker frame has its origin at the
marker centre, z out of the visible face, x toward the texture's right and y toward the
texture's top, which is OpenCV's ArUco convention. The four corners that ``cv2.aruco``
reports (top-left, top-right, bottom-right, bottom-left) are therefore, in the marker frame,
``(-s/2, s/2, 0), (s/2, s/2, 0), (s/2, -s/2, 0), (-s/2, -s/2, 0)`` for a marker of side ``s``.

The side ``s`` counts the black border. The textured plane is larger: a white quiet zone of
``QUIET_ZONE_MODULES`` modules surrounds the marker so that it stays detectable on a dark
object. pybullet reads textures from files only, so the images and the plane mesh are written
once into a cache folder (atomically, so parallel test processes can share it).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import cv2
import numpy as np

from capabilities.bullet import pybullet as p

__all__ = [
    "ARUCO_DICTIONARY",
    "MARKER_MODULES",
    "QUIET_ZONE_MODULES",
    "MarkerTextures",
    "aruco_dictionary",
    "marker_corners_in_marker_frame",
    "marker_image",
    "plane_side",
]

ARUCO_DICTIONARY = cv2.aruco.DICT_4X4_50
"""The ArUco dictionary of every marker in the cell."""

MARKER_MODULES = 6
"""Modules across a DICT_4X4 marker: 4 data bits plus a one-module black border each side."""

QUIET_ZONE_MODULES = 1
"""White modules around the black border on the textured plane."""

_PIXELS_PER_MODULE = 32
_DICTIONARY_SIZE = 50


def aruco_dictionary() -> cv2.aruco.Dictionary:
    """The cell's ArUco dictionary (DICT_4X4_50)."""
    return cv2.aruco.getPredefinedDictionary(ARUCO_DICTIONARY)


def plane_side(marker_side: float) -> float:
    """Side (m) of the textured plane carrying a marker of ``marker_side`` (border included)."""
    return marker_side * (MARKER_MODULES + 2 * QUIET_ZONE_MODULES) / MARKER_MODULES


def marker_corners_in_marker_frame(marker_side: float) -> np.ndarray:
    """The 4x3 corners in cv2.aruco's order (TL, TR, BR, BL) in the marker frame."""
    h = marker_side / 2.0
    return np.array([[-h, h, 0.0], [h, h, 0.0], [h, -h, 0.0], [-h, -h, 0.0]])


def marker_image(marker_id: int, pixels_per_module: int = _PIXELS_PER_MODULE) -> np.ndarray:
    """The greyscale texture of a marker with its white quiet zone (uint8, square).

    Raises:
        ValueError: the id is not in DICT_4X4_50.
    """
    if not 0 <= marker_id < _DICTIONARY_SIZE:
        raise ValueError(f"marker id {marker_id} is not in DICT_4X4_50 (0..{_DICTIONARY_SIZE - 1})")
    inner = cv2.aruco.generateImageMarker(
        aruco_dictionary(), marker_id, MARKER_MODULES * pixels_per_module, borderBits=1
    )
    pad = QUIET_ZONE_MODULES * pixels_per_module
    return np.pad(inner, pad, mode="constant", constant_values=255)


def _write_atomically(path: Path, data: bytes) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as handle:
            handle.write(data)
        os.replace(tmp, path)
    except OSError:
        Path(tmp).unlink(missing_ok=True)
        raise


# A unit square in the xy plane facing +z. OBJ texture coordinates have v up (v=1 is the
# image's top row), and pybullet's renderers follow that, so the image's top lies toward +y
# and its right toward +x: exactly the marker frame above (checked by a rendering test).
_PLANE_OBJ = """# unit textured plane for ArUco markers, facing +z
v -0.5 -0.5 0
v 0.5 -0.5 0
v 0.5 0.5 0
v -0.5 0.5 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
f 1/1/1 2/2/1 3/3/1
f 1/1/1 3/3/1 4/4/1
"""


class MarkerTextures:
    """Marker texture files plus the pybullet texture and shape ids made from them.

    One instance per scene loader; it remembers the ids per physics client so that a marker
    used on several bodies is uploaded once.

    Args:
        cache_dir: where the PNG files and the plane mesh go (default: a folder in the
            system temp directory).
    """

    def __init__(self, cache_dir: Path | None = None) -> None:
        self._dir = cache_dir or Path(tempfile.gettempdir()) / "costar_sim_markers"
        self._textures: dict[tuple[int, int], int] = {}

    @property
    def cache_dir(self) -> Path:
        """The folder holding the generated files."""
        return self._dir

    def texture_file(self, marker_id: int) -> Path:
        """The PNG of a marker, written on first use."""
        path = self._dir / f"aruco_4x4_50_id{marker_id:02d}_q{QUIET_ZONE_MODULES}.png"
        if not path.exists():
            self._dir.mkdir(parents=True, exist_ok=True)
            ok, data = cv2.imencode(".png", marker_image(marker_id))
            if not ok:
                raise OSError(f"could not encode the texture of marker {marker_id}")
            _write_atomically(path, data.tobytes())
        return path

    def plane_file(self) -> Path:
        """The unit plane mesh (OBJ), written on first use."""
        path = self._dir / "marker_plane.obj"
        if not path.exists():
            self._dir.mkdir(parents=True, exist_ok=True)
            _write_atomically(path, _PLANE_OBJ.encode("ascii"))
        return path

    def texture_id(self, client: int, marker_id: int) -> int:
        """The pybullet texture id of a marker in ``client`` (loaded once per client)."""
        key = (client, marker_id)
        if key not in self._textures:
            path = str(self.texture_file(marker_id))
            self._textures[key] = p.loadTexture(path, physicsClientId=client)
        return self._textures[key]

    def plane_visual(
        self, client: int, marker_side: float, offset: tuple[float, float, float] = (0, 0, 0)
    ) -> int:
        """A visual shape: the plane (quiet zone included) of a marker of ``marker_side``.

        Args:
            client: pybullet client id.
            marker_side: marker side in metres, black border included.
            offset: position of the plane centre in the frame of the link that carries it.
        """
        side = plane_side(marker_side)
        return p.createVisualShape(
            p.GEOM_MESH,
            fileName=str(self.plane_file()),
            meshScale=[side, side, 1.0],
            visualFramePosition=list(offset),
            physicsClientId=client,
        )

    def apply(
        self, client: int, body_id: int, link_index: int, marker_id: int, shape_index: int = -1
    ) -> None:
        """Put the texture of ``marker_id`` on a marker plane: the link's only visual shape,
        or its ``shape_index``-th one.
        """
        p.changeVisualShape(
            body_id,
            link_index,
            shapeIndex=shape_index,
            textureUniqueId=self.texture_id(client, marker_id),
            rgbaColor=[1, 1, 1, 1],
            physicsClientId=client,
        )

    def forget_client(self, client: int) -> None:
        """Drop the ids remembered for a client (call after resetSimulation or disconnect)."""
        self._textures = {k: v for k, v in self._textures.items() if k[0] != client}
