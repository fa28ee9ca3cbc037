"""Builds the cell's fixed world on the physics thread: floor, robot stand, table, robot,
holster and suction tool.

Layout (default config): the world frame's origin is the UR base, on a stand whose top is
flush with the table top (z = 0); the table (0.8 x 1.2 m) spans x 0.15..0.95 in front of the
robot; the floor is 0.75 m below. Scene objects are added later by the scene helper.

The live view's mirror (``live_view.py``) builds a *light* world: the same bodies, but the
robot has its light meshes (``robot_model.py``), and the floor (a finite slab under what the
cameras see instead of pybullet's infinite plane, which cost pybullet's CPU renderer ~20 ms a
frame) and the table's top are not bodies: :func:`light_surfaces` describes them and the
mirror draws them into each picture (``flat_surfaces.py``); the table keeps its four sides.
Only pictures come from it; the cell and perception use the full world.
"""

from __future__ import annotations

from dataclasses import dataclass

from capabilities.bullet import pybullet
from capabilities.robot.cell_file import CellConfig
from capabilities.robot.kinematics import UR5_JOINT_NAMES
from capabilities.robot.robot_model import ROBOTS_DIR
from capabilities.sim.flat_surfaces import FlatSurface
from capabilities.sim.robot_model import robot_urdf_path
from engine.types import Pose

__all__ = ["World", "build_world", "light_surfaces"]

# base_link of the URDF is the UR "base" frame turned 180 degrees about z (and back).
_BASE_LINK_IN_BASE = Pose((0.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0))
_TOOL_IN_HOLSTER = Pose((0.0, 0.0, 0.01))  # the tool's cup tip rests on the 10 mm plate
# The light world's floor: a slab reaching past everything the cameras see of the floor,
# coloured like the mean of the white and blue squares the renderer draws on the plane.
_LIGHT_FLOOR_HALF = (3.0, 3.0)
_LIGHT_FLOOR_RGBA = (0.78, 0.84, 0.95, 1.0)
_TABLE_RGBA = (0.78, 0.7, 0.58, 1.0)


@dataclass(frozen=True)
class World:
    """Body ids and link indices of the fixed world (in the light world ``floor`` is -1 and
    ``table`` draws only the table's sides: see :func:`light_surfaces`).
    """

    robot: int
    arm_joints: tuple[int, ...]
    flange_link: int
    gripper_link: int
    finger_joints: tuple[int, int]
    table: int
    stand: int
    floor: int
    holster: int
    suction_tool: int
    table_top_z: float


def _box(
    client: int,
    half: tuple[float, float, float],
    center: tuple[float, float, float],
    rgba: tuple[float, ...],
) -> int:
    shape = pybullet.createCollisionShape(
        pybullet.GEOM_BOX, halfExtents=half, physicsClientId=client
    )
    visual = pybullet.createVisualShape(
        pybullet.GEOM_BOX, halfExtents=half, rgbaColor=rgba, physicsClientId=client
    )
    return int(
        pybullet.createMultiBody(0.0, shape, visual, basePosition=center, physicsClientId=client)
    )


def _floor(client: int, floor_z: float) -> int:
    plane = pybullet.createCollisionShape(pybullet.GEOM_PLANE, physicsClientId=client)
    return int(
        pybullet.createMultiBody(0.0, plane, basePosition=(0, 0, floor_z), physicsClientId=client)
    )


def _table_sides(client: int, config: CellConfig) -> int:
    """The table's four sides without its top (seen, never touched: no collision shape)."""
    t = config.table
    (x0, x1), (y0, y1) = _table_extent(config)
    z0, z1 = t.top_z - t.size[2], t.top_z
    corners = ((x0, y0), (x1, y0), (x1, y1), (x0, y1))  # counter-clockwise seen from above
    vertices: list[tuple[float, float, float]] = []
    normals: list[tuple[float, float, float]] = []
    indices: list[int] = []
    for (ax, ay), (bx, by) in zip(corners, corners[1:] + corners[:1], strict=True):
        k = len(vertices)  # a side's outward normal: its edge turned clockwise
        length = ((bx - ax) ** 2 + (by - ay) ** 2) ** 0.5
        vertices += [(ax, ay, z0), (bx, by, z0), (bx, by, z1), (ax, ay, z1)]
        normals += [((by - ay) / length, (ax - bx) / length, 0.0)] * 4
        indices += [k, k + 1, k + 2, k, k + 2, k + 3]
    visual = pybullet.createVisualShape(
        pybullet.GEOM_MESH,
        vertices=vertices,
        indices=indices,
        normals=normals,
        rgbaColor=_TABLE_RGBA,
        physicsClientId=client,
    )
    return int(pybullet.createMultiBody(0.0, -1, visual, physicsClientId=client))


def _table_extent(config: CellConfig) -> tuple[tuple[float, float], tuple[float, float]]:
    t = config.table
    return (
        (t.center[0] - t.size[0] / 2, t.center[0] + t.size[0] / 2),
        (t.center[1] - t.size[1] / 2, t.center[1] + t.size[1] / 2),
    )


def light_surfaces(config: CellConfig) -> tuple[FlatSurface, ...]:
    """The light world's surfaces that are drawn, not rendered: the floor (a finite slab's
    top reaching past everything the cameras see of the floor, coloured like the mean of the
    white and blue squares the renderer draws on the plane) and the table's top.
    """
    t = config.table
    floor_x, floor_y = _LIGHT_FLOOR_HALF
    x, y = _table_extent(config)
    return (
        FlatSurface(
            t.top_z - t.size[2], (-floor_x, floor_x), (-floor_y, floor_y), _LIGHT_FLOOR_RGBA
        ),
        FlatSurface(t.top_z, x, y, _TABLE_RGBA),
    )


def _static_world(client: int, config: CellConfig, light: bool) -> tuple[int, int, int]:
    table = config.table
    floor_z = table.top_z - table.size[2]
    floor = -1 if light else _floor(client, floor_z)
    half = (table.size[0] / 2, table.size[1] / 2, table.size[2] / 2)
    table_id = (
        _table_sides(client, config)
        if light
        else _box(
            client, half, (table.center[0], table.center[1], table.top_z - half[2]), _TABLE_RGBA
        )
    )
    base = config.robot_base.position
    stand_h = max(base[2] - floor_z, 0.01)
    stand_half = (config.stand_size[0] / 2, config.stand_size[1] / 2, stand_h / 2)
    stand = _box(client, stand_half, (base[0], base[1], base[2] - stand_h / 2), (0.3, 0.3, 0.33, 1))
    return floor, table_id, stand


def _load_robot(
    client: int, config: CellConfig, light: bool, drawn: bool
) -> tuple[int, dict[str, int]]:
    base_link = config.robot_base.compose(_BASE_LINK_IN_BASE)
    robot = pybullet.loadURDF(
        str(robot_urdf_path(light=light)),
        basePosition=base_link.position,
        baseOrientation=base_link.orientation,
        useFixedBase=True,
        # A world no camera draws needs no meshes to draw: loading them is 0.6 s of 0.7.
        flags=0 if drawn else pybullet.URDF_IGNORE_VISUAL_SHAPES,
        physicsClientId=client,
    )
    joints: dict[str, int] = {}
    for i in range(pybullet.getNumJoints(robot, physicsClientId=client)):
        info = pybullet.getJointInfo(robot, i, physicsClientId=client)
        joints[info[1].decode()] = i
        joints["link:" + info[12].decode()] = i
    return int(robot), joints


def build_world(client: int, config: CellConfig, light: bool = False, drawn: bool = True) -> World:
    """Create every fixed body of the cell (on the physics thread, or in a live view mirror).

    Args:
        client: the pybullet client.
        config: the cell's configuration.
        light: the live view mirror's cheaper-to-draw world (see the module's text).
        drawn: False: no camera renders this world (the UR emulator's arm alone), so the
            robot's visual meshes are not loaded.
    """
    pybullet.setGravity(0, 0, -9.81, physicsClientId=client)
    floor, table, stand = _static_world(client, config, light)
    robot, index = _load_robot(client, config, light, drawn)
    arm = tuple(index[name] for name in UR5_JOINT_NAMES)
    for joint, value in zip(arm, config.home_joints, strict=True):
        pybullet.resetJointState(robot, joint, value, physicsClientId=client)
    holster = config.holster_pose
    holster_id = pybullet.loadURDF(
        str(ROBOTS_DIR / "holster.urdf"),
        basePosition=holster.position,
        baseOrientation=holster.orientation,
        useFixedBase=True,
        physicsClientId=client,
    )
    tool_pose = holster.compose(_TOOL_IN_HOLSTER)
    tool = pybullet.loadURDF(
        str(ROBOTS_DIR / "suction_tool.urdf"),
        basePosition=tool_pose.position,
        baseOrientation=tool_pose.orientation,
        physicsClientId=client,
    )
    return World(
        robot=robot,
        arm_joints=arm,
        flange_link=index["link:tool0"],
        gripper_link=index["link:gripper_body"],
        finger_joints=(index["left_finger_joint"], index["right_finger_joint"]),
        table=table,
        stand=stand,
        floor=floor,
        holster=int(holster_id),
        suction_tool=int(tool),
        table_top_z=config.table.top_z,
    )
