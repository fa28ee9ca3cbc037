"""The cell's visible state as a few hundred bytes, taken on the physics thread and laid onto a
mirror of the cell in another pybullet client (the live view's renderer, ``live_view.py``).

A snapshot holds what a camera can see move: every joint of the robot (arm and fingers), the
suction tool's base pose (in the holster or on the flange: its attachment shows through its
pose) and the base pose of every scene object by name. Objects added to the scene after the
mirror was built (a bin the simulated worker hands over) carry their model the first time
they are sent; objects gone from the scene are removed from the mirror. The mirror never
steps its physics: it only teleports bodies to where the cell has them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from capabilities.bullet import pybullet as p
from capabilities.object_library import ObjectModelSpec
from capabilities.sim.objects import spawn_object
from capabilities.sim.scene import SceneState
from capabilities.sim.world import World
from engine.types import Pose

__all__ = ["CellSnapshot", "apply_snapshot", "take_snapshot"]

BasePose = tuple[tuple[float, float, float], tuple[float, float, float, float]]


@dataclass(frozen=True)
class CellSnapshot:
    """What the cameras can see move, at one simulated time.

    Attributes:
        stamp: simulated time of the state (s).
        robot_joints: the position of every joint of the robot body, by joint index.
        tool: base pose of the suction tool (centre-of-mass frame, as pybullet keeps it).
        objects: scene object name -> base pose.
        new_models: models (and whether the body is fixed) of objects the mirror may not
            have yet, by object name.
    """

    stamp: float
    robot_joints: tuple[float, ...]
    tool: BasePose
    objects: dict[str, BasePose]
    new_models: dict[str, tuple[ObjectModelSpec, bool]] = field(default_factory=dict)


def _base_pose(client: int, body: int) -> BasePose:
    position, orientation = p.getBasePositionAndOrientation(body, physicsClientId=client)
    return tuple(position), tuple(orientation)


def take_snapshot(
    client: int, world: World, scene: SceneState, stamp: float, known: set[str]
) -> CellSnapshot:
    """Read the visible state (physics thread only; some tens of microseconds).

    Args:
        client: the cell's pybullet client.
        world: the cell's fixed bodies.
        scene: the loaded scene (its ``objects`` are the bodies present now).
        stamp: the simulated time to stamp the snapshot with.
        known: names of the objects the mirror has (models are sent for the others);
            updated in place with the names sent.
    """
    count = p.getNumJoints(world.robot, physicsClientId=client)
    states = p.getJointStates(world.robot, range(count), physicsClientId=client)
    objects = {name: _base_pose(client, obj.body_id) for name, obj in scene.objects.items()}
    new = {
        n: (scene.objects[n].model, _is_fixed(client, scene, n)) for n in objects if n not in known
    }
    known.intersection_update(objects)
    known.update(objects)
    return CellSnapshot(
        stamp=stamp,
        robot_joints=tuple(float(s[0]) for s in states),
        tool=_base_pose(client, world.suction_tool),
        objects=objects,
        new_models=new,
    )


def _is_fixed(client: int, scene: SceneState, name: str) -> bool:
    mass = p.getDynamicsInfo(scene.objects[name].body_id, -1, physicsClientId=client)[0]
    return float(mass) == 0.0


def apply_snapshot(client: int, world: World, scene: SceneState, snapshot: CellSnapshot) -> None:
    """Put the mirror's bodies where the snapshot has them (the mirror's own thread).

    Objects the snapshot lacks are removed; objects it adds are spawned from their model.
    """
    for name in [n for n in scene.objects if n not in snapshot.objects]:
        scene.remove(client, name)
    for name, (model, fixed) in snapshot.new_models.items():
        if name not in scene.objects:
            position, orientation = snapshot.objects[name]
            scene.objects[name] = spawn_object(
                client, model, Pose(position, orientation), scene.textures, fixed
            )
    for index, value in enumerate(snapshot.robot_joints):
        p.resetJointState(world.robot, index, value, physicsClientId=client)
    p.resetBasePositionAndOrientation(world.suction_tool, *snapshot.tool, physicsClientId=client)
    for name, (position, orientation) in snapshot.objects.items():
        if name in scene.objects:
            p.resetBasePositionAndOrientation(
                scene.objects[name].body_id, position, orientation, physicsClientId=client
            )
