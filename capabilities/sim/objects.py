"""Spawning the object library's models in pybullet (the library itself is cell-neutral:
:mod:`capabilities.object_library`).
"""

from __future__ import annotations

from dataclasses import dataclass

from capabilities.bullet import pybullet as p
from capabilities.object_library import (
    BoxPart,
    CollisionSpec,
    MarkerSpec,
    ObjectLibrary,
    ObjectLibraryError,
    ObjectModelSpec,
    Symmetry,
    default_library_path,
    parse_model,
)
from capabilities.sim.errors import SimError
from capabilities.sim.markers_texture import MarkerTextures, plane_side
from engine.types import Pose

__all__ = [
    "BoxPart",
    "CollisionSpec",
    "MarkerSpec",
    "ObjectLibrary",
    "ObjectLibraryError",
    "ObjectModelSpec",
    "SceneError",
    "SpawnedObject",
    "Symmetry",
    "default_library_path",
    "object_frame_pose",
    "parse_model",
    "set_object_frame_pose",
    "spawn_object",
    "wake",
]


class SceneError(SimError):
    """Something is wrong with a scene or a simulated camera."""


# --------------------------------------------------------------------------- spawning


@dataclass(frozen=True)
class SpawnedObject:
    """A model instance in a pybullet client: its body (markers are drawn on its base)."""

    body_id: int
    model: ObjectModelSpec

    def carries(self, marker_id: int) -> bool:
        return any(m.marker_id == marker_id for m in self.model.markers)


def _collision_shape(client: int, model: ObjectModelSpec) -> int:
    c = model.collision
    if c.kind == "cylinder":
        return p.createCollisionShape(
            p.GEOM_CYLINDER,
            radius=c.radius,
            height=c.height,
            collisionFramePosition=[0, 0, c.height / 2],
            physicsClientId=client,
        )
    if c.kind == "convex_hull":
        return p.createCollisionShape(
            p.GEOM_MESH, fileName=str(model.mesh_file), physicsClientId=client
        )
    return p.createCollisionShapeArray(
        shapeTypes=[p.GEOM_BOX] * len(c.boxes),
        halfExtents=[[s / 2 for s in b.size] for b in c.boxes],
        collisionFramePositions=[list(b.position) for b in c.boxes],
        physicsClientId=client,
    )


def _visual_shapes(client: int, model: ObjectModelSpec, textures: MarkerTextures) -> int:
    """The base's visual shapes: the mesh, then one textured plane per marker.

    The planes are shapes of the base, not links of their own: a link on a fixed joint costs
    the physics as much as a moving part (a resting kit bin stepped 2.4 times slower with its
    six marker links), and TinyRenderer textures each shape of a base on its own.
    """
    markers = model.markers
    plane = str(textures.plane_file())
    return p.createVisualShapeArray(
        shapeTypes=[p.GEOM_MESH] * (1 + len(markers)),
        fileNames=[str(model.mesh_file)] + [plane] * len(markers),
        meshScales=[[1.0, 1.0, 1.0]]
        + [[plane_side(m.size), plane_side(m.size), 1.0] for m in markers],
        rgbaColors=[list(model.color)] + [[1.0, 1.0, 1.0, 1.0]] * len(markers),
        visualFramePositions=[[0.0, 0.0, 0.0]] + [list(m.pose.position) for m in markers],
        visualFrameOrientations=[[0.0, 0.0, 0.0, 1.0]]
        + [list(m.pose.orientation) for m in markers],
        physicsClientId=client,
    )


def spawn_object(
    client: int,
    model: ObjectModelSpec,
    pose: Pose,
    textures: MarkerTextures,
    fixed: bool = False,
) -> SpawnedObject:
    """Create a body for ``model`` with its object frame at ``pose`` (world).

    The body's base carries the collision shape, the mesh and a textured plane per marker,
    placed at the marker pose of model.json.

    Args:
        client: pybullet client id.
        model: the model to spawn.
        pose: object frame (bottom centre) in the world.
        textures: the marker texture cache.
        fixed: a static body (mass 0), e.g. a fixture.
    """
    body = p.createMultiBody(
        baseMass=0.0 if fixed else model.mass,
        baseCollisionShapeIndex=_collision_shape(client, model),
        baseVisualShapeIndex=_visual_shapes(client, model, textures),
        basePosition=list(pose.position),
        baseOrientation=list(pose.orientation),
        baseInertialFramePosition=list(model.center_of_mass),
        physicsClientId=client,
    )
    p.changeDynamics(
        body,
        -1,
        lateralFriction=model.friction,
        rollingFriction=1e-4,
        spinningFriction=1e-3,
        # A body at rest sleeps until something touches it: resting objects are most of a
        # cell's contacts, and stepping them cost 20-35 us a step each (a kitting scene
        # stepped 170 us a step awake, 60 asleep). Teleports and tools wake them.
        activationState=p.ACTIVATION_STATE_ENABLE_SLEEPING,
        physicsClientId=client,
    )
    for index, marker in enumerate(model.markers):
        textures.apply(client, body, -1, marker.marker_id, shape_index=1 + index)
    return SpawnedObject(body, model)


def object_frame_pose(client: int, body_id: int, model: ObjectModelSpec) -> Pose:
    """The pose of the object frame (bottom centre) of a spawned body: ground truth.

    pybullet reports the base's centre of mass frame; the object frame is offset from it by
    the model's ``center_of_mass``.
    """
    pos, orn = p.getBasePositionAndOrientation(body_id, physicsClientId=client)
    com = Pose(model.center_of_mass)
    return Pose(pos, orn).compose(com.inverse())


def set_object_frame_pose(client: int, body_id: int, model: ObjectModelSpec, pose: Pose) -> None:
    """Teleport a spawned body so that its object frame is at ``pose`` (velocity zeroed)."""
    com = pose.compose(Pose(model.center_of_mass))
    p.resetBasePositionAndOrientation(
        body_id, list(com.position), list(com.orientation), physicsClientId=client
    )
    p.resetBaseVelocity(body_id, [0, 0, 0], [0, 0, 0], physicsClientId=client)
    wake(client, body_id)


def wake(client: int, body_id: int) -> None:
    """Wake a body that sleeps at rest (after a teleport, or when what it rests on moves or
    goes): a sleeping body is not stepped until something active touches it.
    """
    p.changeDynamics(
        body_id, -1, activationState=p.ACTIVATION_STATE_WAKE_UP, physicsClientId=client
    )
