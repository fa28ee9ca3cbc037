"""Build a scene of the simulated cell in pybullet: table, fixed markers, objects.

``load_scene(client, scene, seed)`` reads a scene file (see ``scene_spec``), draws the
randomised object poses with ``numpy.random.default_rng(seed)`` (same seed, same scene),
checks that every object is on the table, within the robot's reach and clear of the other
objects, the reserved areas and the fixed markers, and creates the bodies. It runs on the
thread that owns the client (``SimCell.call(lambda c: load_scene(c, ...))``).

The returned ``SceneState`` knows the bodies and the marker layout. Its ``truth_*`` methods
read pybullet's ground truth: for tests and scores only, never for an operation (perception
works on camera images).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from capabilities.bullet import pybullet as p
from capabilities.sim.markers_texture import MarkerTextures
from capabilities.sim.objects import (
    ObjectLibrary,
    ObjectModelSpec,
    SceneError,
    SpawnedObject,
    object_frame_pose,
    spawn_object,
    wake,
)
from capabilities.sim.placement import Placement, sample_placements
from capabilities.sim.scene_spec import SceneSpec, read_scene
from engine.types import Pose
from resources import resource_path

__all__ = [
    "FixedMarker",
    "Placement",
    "SceneState",
    "default_scene_path",
    "load_scene",
    "sample_placements",
    "yaw_pose",
]

MARKER_LIFT = 0.0005  # fixed markers float 0.5 mm above the table so they never z-fight


def default_scene_path(name: str) -> Path:
    """The shipped scene ``scenes/<name>.json``."""
    return resource_path("scenes", f"{name}.json")


def yaw_pose(x: float, y: float, z: float, yaw: float) -> Pose:
    """A pose at (x, y, z) turned by ``yaw`` about world z."""
    return Pose((x, y, z), (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))


@dataclass(frozen=True)
class FixedMarker:
    """A marker fixed on the table: its id, side (m) and world pose (a known calibration pose)."""

    name: str
    marker_id: int
    size: float
    pose: Pose
    body_id: int


@dataclass
class SceneState:
    """The bodies of a loaded scene and what is known about them.

    Operations may use the layout (which models are in the scene, which markers belong to
    which object, the fixed markers' poses: calibration data); the ``truth_*`` methods are
    ground truth for tests and scores only.
    """

    name: str
    seed: int | None
    table_top_z: float
    table_body: int | None
    objects: dict[str, SpawnedObject]
    fixed_markers: dict[int, FixedMarker]
    absent: tuple[str, ...]
    spec: SceneSpec
    library: ObjectLibrary
    textures: MarkerTextures

    def names(self) -> list[str]:
        """Names of the objects present, in scene-file order."""
        return list(self.objects)

    def body_id(self, name: str) -> int:
        """The pybullet body of an object."""
        return self._get(name).body_id

    def model(self, name: str) -> ObjectModelSpec:
        """The model of an object."""
        return self._get(name).model

    def marker_sizes(self) -> dict[int, float]:
        """Side (m) of every marker in the scene (objects' and fixed ones) by id."""
        sizes = {m.marker_id: m.size for m in self.fixed_markers.values()}
        for obj in self.objects.values():
            sizes.update({m.marker_id: m.size for m in obj.model.markers})
        return sizes

    def marker_owner(self, marker_id: int) -> str:
        """``table`` for a fixed marker, else the name of the object carrying the marker."""
        if marker_id in self.fixed_markers:
            return "table"
        for name, obj in self.objects.items():
            if obj.carries(marker_id):
                return name
        raise SceneError(f"scene {self.name!r} has no marker {marker_id}")

    def truth_pose(self, client: int, name: str) -> Pose:
        """GROUND TRUTH, for tests and scores only: an object's frame in the world now."""
        obj = self._get(name)
        return object_frame_pose(client, obj.body_id, obj.model)

    def truth_marker_pose(self, client: int, marker_id: int) -> Pose:
        """GROUND TRUTH, for tests and scores only: a marker's frame in the world now."""
        owner = self.marker_owner(marker_id)
        if owner == "table":
            return self.fixed_markers[marker_id].pose
        obj = self.objects[owner]
        marker = next(m for m in obj.model.markers if m.marker_id == marker_id)
        return object_frame_pose(client, obj.body_id, obj.model).compose(marker.pose)

    def spawn(self, client: int, name: str, model: str, pose: Pose, fixed: bool = False) -> int:
        """Add an object (e.g. a bin a worker hands over); returns its body id."""
        if name in self.objects:
            raise SceneError(f"scene {self.name!r} already has an object {name!r}")
        spawned = spawn_object(client, self.library.get(model), pose, self.textures, fixed)
        self.objects[name] = spawned
        return spawned.body_id

    def remove(self, client: int, name: str) -> None:
        """Take an object out of the world."""
        p.removeBody(self._get(name).body_id, physicsClientId=client)
        del self.objects[name]
        for obj in self.objects.values():  # what rested on it falls
            wake(client, obj.body_id)

    def _get(self, name: str) -> SpawnedObject:
        if name not in self.objects:
            raise SceneError(f"scene {self.name!r} has no object {name!r} (has {self.names()})")
        return self.objects[name]


def _make_table(client: int, spec: SceneSpec, top_z: float) -> int:
    t = spec.table
    half = [t.size[0] / 2, t.size[1] / 2, t.size[2] / 2]
    center = [t.center[0], t.center[1], top_z - half[2]]
    col = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    vis = p.createVisualShape(
        p.GEOM_BOX, halfExtents=half, rgbaColor=list(t.color), physicsClientId=client
    )
    body = p.createMultiBody(0, col, vis, center, physicsClientId=client)
    p.changeDynamics(body, -1, lateralFriction=0.6, physicsClientId=client)
    if t.floor:
        floor_half = [3.0, 3.0, 0.01]
        floor_z = top_z - t.size[2] - 0.01
        fcol = p.createCollisionShape(p.GEOM_BOX, halfExtents=floor_half, physicsClientId=client)
        fvis = p.createVisualShape(
            p.GEOM_BOX,
            halfExtents=floor_half,
            rgbaColor=[0.45, 0.45, 0.47, 1],
            physicsClientId=client,
        )
        p.createMultiBody(0, fcol, fvis, [0, 0, floor_z], physicsClientId=client)
    return body


def _make_markers(
    client: int, spec: SceneSpec, top_z: float, textures: MarkerTextures
) -> dict[int, FixedMarker]:
    out = {}
    for m in spec.markers:
        if m.marker_id in out:
            raise SceneError(f"{spec.source}: marker id {m.marker_id} is used twice")
        pose = yaw_pose(m.position[0], m.position[1], top_z + MARKER_LIFT, m.yaw)
        vis = textures.plane_visual(client, m.size)
        body = p.createMultiBody(
            0, -1, vis, list(pose.position), list(pose.orientation), physicsClientId=client
        )
        textures.apply(client, body, -1, m.marker_id)
        out[m.marker_id] = FixedMarker(m.name, m.marker_id, m.size, pose, body)
    return out


def load_scene(
    client: int,
    scene: Path | str | dict[str, Any] | SceneSpec,
    seed: int | None = 0,
    *,
    library: ObjectLibrary | None = None,
    textures: MarkerTextures | None = None,
    table_top_z: float | None = None,
    make_table: bool = True,
    keep_out: tuple[tuple[float, float, float], ...] = (),
) -> SceneState:
    """Build a scene in a pybullet client.

    Args:
        client: pybullet client id (call on the thread that owns it).
        scene: a scene file path, its parsed JSON, or a SceneSpec.
        seed: the seed of the randomisation (None: fresh entropy, not reproducible).
        library: the object library (default: ``resources/objects``).
        textures: the marker texture cache (default: a new one in the temp directory).
        table_top_z: put the table top here instead of the file's ``top_z``.
        make_table: create the table (and floor); False when the cell made its own.
        keep_out: more circles (x, y, radius) to keep free, e.g. the cell's holster.

    Raises:
        SceneError: the file is malformed, a model is missing, an object does not fit.
    """
    spec = read_scene(scene)
    library = library or ObjectLibrary()
    textures = textures or MarkerTextures()
    top_z = spec.table.top_z if table_top_z is None else table_top_z
    placements = sample_placements(spec, library, seed, keep_out)
    for entry in spec.objects:  # every model must load before any body is made
        library.get(entry.model)
    table = _make_table(client, spec, top_z) if make_table else None
    markers = _make_markers(client, spec, top_z, textures)
    objects: dict[str, SpawnedObject] = {}
    for entry in spec.objects:
        place = placements[entry.name]
        if place is not None:
            pose = yaw_pose(place.x, place.y, top_z, place.yaw)
            objects[entry.name] = spawn_object(
                client, library.get(entry.model), pose, textures, entry.fixed
            )
    absent = tuple(n for n, v in placements.items() if v is None)
    return SceneState(
        name=spec.name,
        seed=seed,
        table_top_z=top_z,
        table_body=table,
        objects=objects,
        fixed_markers=markers,
        absent=absent,
        spec=spec,
        library=library,
        textures=textures,
    )
