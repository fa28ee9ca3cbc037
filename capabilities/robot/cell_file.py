"""The cell file: where things stand, home joints, tool offsets, cameras, and the robot.

One file type describes every cell (``*.cell.json``, schema ``resources/schemas/cell.schema
.json``; the simulated cell's default is ``resources/cells/sim_default.json``). Its ``robot``
block (``cell_robot``) says whether the arm is the simulated one or a UR
controller at a host. The world frame has z up; the UR base frame (what the robot's
controller calls "base") stands at ``robot_base`` (the mounting) and the table top is at
``table_top_z``. Format version 2 added ``robot`` and ``objects``; version 1 files still read.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from capabilities.camera_source import SOURCE_KINDS
from capabilities.robot.camera_mounts import SHOULDER_EYE, SHOULDER_TARGET, WRIST_MOUNT, look_at
from capabilities.robot.cell_robot import RobotSettings, read_robot
from capabilities.robot.errors import RobotCellError
from engine.json_reader import JsonReader, errors_as, read_json_file
from engine.types import ParamType, Pose
from resources import resource_path

__all__ = [
    "CameraSettings",
    "CellConfig",
    "CellConfigError",
    "TableConfig",
    "DEFAULT_CONFIG_PATH",
    "FORMAT_VERSION",
]

FORMAT_VERSION = 2
READABLE_VERSIONS = (1, 2)
DEFAULT_CONFIG_PATH = resource_path("cells", "sim_default.json")


class CellConfigError(RobotCellError):
    """A cell configuration file is missing or off; the message names the file and JSON path.

    It wraps the reader's :class:`engine.json_reader.JsonFileError` (its ``__cause__``).
    """


_DOWN = (1.0, 0.0, 0.0, 0.0)  # tool z axis pointing down: 180 degrees about world x
_BASE = Pose((0.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0))
_HOLSTER = Pose((0.35, -0.45, 0.0))
_HANDLE_GRASP = Pose((0.0, 0.0, 0.145), _DOWN)


@dataclass(frozen=True)
class TableConfig:
    """A box table: ``size`` (x, y, height) m; its top centre at ``center`` (x, y) and ``top_z``."""

    size: tuple[float, float, float] = (0.8, 1.2, 0.75)
    center: tuple[float, float] = (0.55, 0.0)
    top_z: float = 0.0


@dataclass(frozen=True)
class CameraSettings:
    """One RGB-D camera of the cell.

    Attributes:
        pose: the camera's OpenCV frame (x right, y down, z forward): in the world for a fixed
            camera, in the flange (tool0) frame for a wrist camera.
        on_wrist: mounted on the flange, moving with the arm.
        size: (width, height) of the images in pixels.
        fov_y_deg: vertical field of view in degrees.
        near, far: depth range (m); beyond it depth reads NaN.
        source: where the frames come from: "sim" (rendered by the simulated cell),
            "recorded" (a recording folder, ``where``), "stream" (a frame server at ``where``,
            "host:port") or "realsense" (serial ``where``).
        where: the recording folder (relative to the cell file), the frame server's address
            or the RealSense serial.
    """

    pose: Pose
    on_wrist: bool = False
    size: tuple[int, int] = (640, 480)
    fov_y_deg: float = 45.0
    near: float = 0.1
    far: float = 3.0
    source: str = "sim"
    where: str = ""


def _default_cameras() -> dict[str, CameraSettings]:
    return {
        # On a stand behind the robot base, off to its left, aimed at the middle of the table;
        # 640x480 because a 4 cm marker at 1.5 m is too small to read at 320x240.
        "shoulder": CameraSettings(look_at(SHOULDER_EYE, SHOULDER_TARGET)),
        "wrist": CameraSettings(WRIST_MOUNT, True, (320, 240), near=0.05, far=2.0),
    }


@dataclass(frozen=True)
class CellConfig:
    """A cell file, read: where things stand, the tools, the cameras and the robot.

    Attributes:
        robot_base: world pose of the UR base frame. The default puts it at the origin,
            turned 180 degrees about z so that the URDF's ``base_link`` is aligned with the
            world and the arm at its home joints reaches over the table (+x).
        home_joints: the arm's joints at start (rad).
        tcp_offsets: tool pose in the flange (tool0) frame per tool: ``gripper`` (between the
            finger pads) and ``suction`` (the cup tip while the suction tool is held).
        holster_pose: world pose of the holster's frame (on the table top, z up).
        handle_grasp: gripper TCP pose, in the holster frame, that grasps the suction tool's
            handle while it sits in the holster.
        table: the table box.
        stand_size: width and depth (m) of the robot's stand, which reaches from the floor up
            to the robot base.
        cameras: the RGB-D cameras by name ("shoulder", "wrist").
        robot: the ``robot`` block: the simulated arm, or a UR controller at a host.
        objects: the object model library folder ("" for ``resources/objects``); a relative
            path is relative to the cell file.
        capabilities: the raw ``capabilities`` block (capability name -> its settings),
            checked by the capability registry against each capability's declared settings.
        source: the file this configuration was read from ("" when made in code).
    """

    robot_base: Pose = _BASE
    home_joints: tuple[float, ...] = (0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0)
    tcp_offsets: dict[str, Pose] = field(
        default_factory=lambda: {
            "gripper": Pose((0.0, 0.0, 0.145)),
            "suction": Pose((0.0, 0.0, 0.28)),
        }
    )
    holster_pose: Pose = _HOLSTER
    handle_grasp: Pose = _HANDLE_GRASP
    table: TableConfig = TableConfig()
    stand_size: tuple[float, float] = (0.2, 0.2)
    cameras: dict[str, CameraSettings] = field(default_factory=_default_cameras)
    capabilities: dict[str, Any] = field(default_factory=dict)
    robot: RobotSettings = field(default_factory=RobotSettings)
    objects: str = ""
    source: str = field(default="", compare=False)

    @classmethod
    def load(cls, path: str | Path = DEFAULT_CONFIG_PATH) -> CellConfig:
        """Read a cell configuration file.

        Raises:
            CellConfigError: the file is missing, not JSON, or a field is off; the message
                names the file as given and the JSON path.
        """
        with errors_as(CellConfigError):
            return _config(JsonReader(read_json_file(path, "cell configuration"), path))

    @classmethod
    def from_json(cls, data: Any, source: str = "<cell config>") -> CellConfig:
        """Build from the JSON form.

        Raises:
            CellConfigError: a field is off; the message names ``source`` and the JSON path.
        """
        with errors_as(CellConfigError):
            return _config(JsonReader(data, source))

    def to_json(self) -> dict[str, Any]:
        """The JSON form (what ``from_json`` reads)."""

        def pose(p: Pose) -> dict[str, Any]:
            return {"position": list(p.position), "orientation": list(p.orientation)}

        return {
            "format_version": FORMAT_VERSION,
            "robot_base": pose(self.robot_base),
            "home_joints": list(self.home_joints),
            "tcp_offsets": {k: pose(v) for k, v in self.tcp_offsets.items()},
            "holster_pose": pose(self.holster_pose),
            "handle_grasp": pose(self.handle_grasp),
            "table": {
                "size": list(self.table.size),
                "center": list(self.table.center),
                "top_z": self.table.top_z,
            },
            "stand_size": list(self.stand_size),
            "cameras": {
                name: {
                    "pose": pose(c.pose),
                    "on_wrist": c.on_wrist,
                    "size": list(c.size),
                    "fov_y_deg": c.fov_y_deg,
                    "near": c.near,
                    "far": c.far,
                    **({"source": _source_json(c)} if c.source != "sim" else {}),
                }
                for name, c in self.cameras.items()
            },
            "capabilities": self.capabilities,
            "robot": self.robot.to_json(),
            **({"objects": self.objects} if self.objects else {}),
        }

    def folder(self) -> Path | None:
        """The cell file's folder (None for a configuration made in code)."""
        return Path(self.source).parent if self.source else None

    def objects_path(self) -> Path | None:
        """The object library folder the file names (None: the default library)."""
        if not self.objects:
            return None
        path = Path(self.objects)
        return path if path.is_absolute() or not self.source else Path(self.source).parent / path


FIELDS: tuple[str, ...] = ("format_version", "_comment", "robot_base", "home_joints", "tcp_offsets")
FIELDS += ("holster_pose", "handle_grasp", "table", "stand_size", "cameras", "capabilities")
FIELDS += ("robot", "objects")
CAMERA_FIELDS = ("pose", "on_wrist", "size", "fov_y_deg", "near", "far", "source")
_WHERE = {"recorded": "path", "realsense": "serial", "stream": "address"}


def _source_json(c: CameraSettings) -> dict[str, str]:
    return {"kind": c.source, _WHERE[c.source]: c.where}


def _source(entry: JsonReader, base: CameraSettings) -> tuple[str, str]:
    """A camera's ``source``: {"kind": "sim"}, {"kind": "recorded", "path": FOLDER},
    {"kind": "stream", "address": "HOST:PORT"} or {"kind": "realsense", "serial": SERIAL}.
    """
    if not entry.has("source"):
        return base.source, base.where
    block = entry.child("source", ("kind", "path", "serial", "address"), ("kind",))
    kind = block.choice("kind", SOURCE_KINDS)
    if kind == "sim":
        block.as_object(("kind",))
        return kind, ""
    block.as_object(("kind", _WHERE[kind]))
    if kind == "realsense":
        return kind, block.text("serial", "")
    return kind, block.text(_WHERE[kind], nonempty=True)


def _config(r: JsonReader) -> CellConfig:
    r.as_object(FIELDS)
    version = r.check_version(READABLE_VERSIONS)
    if version == 1:
        r.as_object(FIELDS[:-2])  # robot and objects came with version 2
    default = CellConfig()
    table = r.child("table", ("size", "center", "top_z"))
    home = r.vector("home_joints", 6, default.home_joints)
    offsets = {k: v.as_typed(ParamType.POSE) for k, v in r.entries("tcp_offsets", "poses")}
    return CellConfig(
        robot_base=r.pose("robot_base", default.robot_base),
        home_joints=home,
        tcp_offsets={**default.tcp_offsets, **offsets},
        holster_pose=r.pose("holster_pose", default.holster_pose),
        handle_grasp=r.pose("handle_grasp", default.handle_grasp),
        table=TableConfig(
            size=table.vector3("size", default.table.size),
            center=table.vector2("center", default.table.center),
            top_z=table.number("top_z", default.table.top_z),
        ),
        stand_size=r.vector2("stand_size", default.stand_size),
        cameras=_cameras(r, default.cameras),
        # Each capability checks its own block against its settings schema (capabilities.kit).
        capabilities={name: entry.value for name, entry in r.entries("capabilities", "settings")},
        robot=read_robot(r),
        objects=r.text("objects", "", nonempty=False),
        source=r.file,
    )


def _cameras(r: JsonReader, default: dict[str, CameraSettings]) -> dict[str, CameraSettings]:
    """The ``cameras`` block: missing cameras and fields keep their defaults."""
    cameras = dict(default)
    for name, entry in r.entries("cameras", "cameras"):
        entry.as_object(CAMERA_FIELDS)
        base = cameras.get(name, CameraSettings(Pose()))
        width, height = _pixels(entry.at("size")) if entry.has("size") else base.size
        fov = entry.number("fov_y_deg", base.fov_y_deg, lo=1.0, hi=170.0)
        near = entry.number("near", base.near, lo=0.0, above=True)
        far = entry.number("far", base.far, lo=near, above=True)
        cameras[name] = CameraSettings(
            entry.pose("pose", base.pose),
            entry.flag("on_wrist", base.on_wrist),
            (width, height),
            fov,
            near,
            far,
            *_source(entry, base),
        )
    return cameras


def _pixels(r: JsonReader) -> tuple[int, int]:
    if len(r.as_list("two whole numbers of pixels")) != 2:
        r.fail("two whole numbers of pixels")
    return r.at(0).as_integer(16), r.at(1).as_integer(16)
