"""Configuration of the simulated cell: where things stand, home joints, tool offsets.

Loaded from versioned JSON (``resources/cells/sim_default.json``). The world frame has z up;
the UR base frame (what the robot's controller calls "base") stands at ``robot_base`` and
the table top is at ``table_top_z``.
"""

from __future__ import annotations

import dataclasses
import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from capabilities.sim.cameras import SHOULDER_EYE, SHOULDER_TARGET, WRIST_MOUNT, look_at
from capabilities.sim.errors import SimError
from engine.types import ParamType, Pose, ValueError_, decode_value

__all__ = ["CameraSettings", "CellConfig", "TableConfig", "DEFAULT_CONFIG_PATH", "FORMAT_VERSION"]

FORMAT_VERSION = 1
DEFAULT_CONFIG_PATH = (
    Path(__file__).resolve().parents[2] / "resources" / "cells" / "sim_default.json"
)
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
    """

    pose: Pose
    on_wrist: bool = False
    size: tuple[int, int] = (640, 480)
    fov_y_deg: float = 45.0
    near: float = 0.1
    far: float = 3.0


def _default_cameras() -> dict[str, CameraSettings]:
    return {
        # On a stand behind the robot base, off to its left, aimed at the middle of the table;
        # 640x480 because a 4 cm marker at 1.5 m is too small to read at 320x240.
        "shoulder": CameraSettings(look_at(SHOULDER_EYE, SHOULDER_TARGET)),
        "wrist": CameraSettings(WRIST_MOUNT, True, (320, 240), near=0.05, far=2.0),
    }


@dataclass(frozen=True)
class CellConfig:
    """Everything the simulated cell needs to build its world.

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
    source: str = field(default="", compare=False)

    @classmethod
    def load(cls, path: str | Path = DEFAULT_CONFIG_PATH) -> CellConfig:
        """Read a cell configuration file.

        Raises:
            SimError: the file is missing, not JSON, or a field is off (names the JSON path).
        """
        path = Path(path)
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
            return dataclasses.replace(cls.from_json(data), source=str(path))
        except OSError as exc:
            raise SimError(f"{path}: cannot read cell config: {exc}") from exc
        except json.JSONDecodeError as exc:
            raise SimError(f"{path}: not valid JSON: {exc}") from exc
        except (ValueError_, ValueError, TypeError) as exc:
            raise SimError(f"{path}: {exc}") from exc

    @classmethod
    def from_json(cls, data: Any) -> CellConfig:
        """Build from the JSON form; raises ValueError_ naming the path of a bad field."""
        if not isinstance(data, dict):
            raise ValueError_("$", "an object", data)
        if data.get("format_version") != FORMAT_VERSION:
            raise ValueError_("$.format_version", str(FORMAT_VERSION), data.get("format_version"))
        default = cls()
        offsets = data.get("tcp_offsets", {})
        if not isinstance(offsets, dict):
            raise ValueError_("$.tcp_offsets", "an object of poses", offsets)
        table = data.get("table", {})
        return cls(
            robot_base=_pose(data, "robot_base", default.robot_base),
            home_joints=_numbers(data, "home_joints", default.home_joints, 6),
            tcp_offsets={
                **default.tcp_offsets,
                **{
                    k: decode_value(ParamType.POSE, v, f"$.tcp_offsets.{k}")
                    for k, v in offsets.items()
                },
            },
            holster_pose=_pose(data, "holster_pose", default.holster_pose),
            handle_grasp=_pose(data, "handle_grasp", default.handle_grasp),
            table=TableConfig(
                size=_numbers(table, "size", default.table.size, 3, "$.table"),  # type: ignore[arg-type]
                center=_numbers(table, "center", default.table.center, 2, "$.table"),  # type: ignore[arg-type]
                top_z=_numbers(table, "top_z", (default.table.top_z,), 1, "$.table")[0],
            ),
            stand_size=_numbers(data, "stand_size", default.stand_size, 2),  # type: ignore[arg-type]
            cameras=_cameras(data.get("cameras"), default.cameras),
            capabilities=_capabilities(data.get("capabilities", {})),
        )

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
                }
                for name, c in self.cameras.items()
            },
            "capabilities": self.capabilities,
        }


def _capabilities(block: Any) -> dict[str, Any]:
    if not isinstance(block, dict):
        raise ValueError_("$.capabilities", "an object of capability settings", block)
    return block


def _pose(data: dict[str, Any], key: str, default: Pose) -> Pose:
    if key not in data:
        return default
    return decode_value(ParamType.POSE, data[key], f"$.{key}")  # type: ignore[no-any-return]


def _numbers(
    data: Any, key: str, default: tuple[float, ...], n: int, prefix: str = "$"
) -> tuple[float, ...]:
    if not isinstance(data, dict):
        raise ValueError_(prefix, "an object", data)
    if key not in data:
        return tuple(default)
    value = data[key]
    if n == 1:
        value = [value]
    if (
        not isinstance(value, list)
        or len(value) != n
        or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        or not all(math.isfinite(v) for v in value)
    ):
        raise ValueError_(f"{prefix}.{key}", f"{n} finite number(s)", data[key])
    return tuple(float(v) for v in value)


def _cameras(data: Any, default: dict[str, CameraSettings]) -> dict[str, CameraSettings]:
    """The ``cameras`` block: missing cameras and fields keep their defaults."""
    if data is None:
        return dict(default)
    if not isinstance(data, dict):
        raise ValueError_("$.cameras", "an object of cameras by name", data)
    cameras = dict(default)
    for name, entry in data.items():
        path = f"$.cameras.{name}"
        if not isinstance(entry, dict):
            raise ValueError_(path, "an object with pose, on_wrist, size, fov_y_deg", entry)
        base = cameras.get(name, CameraSettings(Pose()))
        on_wrist = entry.get("on_wrist", base.on_wrist)
        if not isinstance(on_wrist, bool):
            raise ValueError_(f"{path}.on_wrist", "true or false", on_wrist)
        size = _numbers(entry, "size", base.size, 2, path)
        if not all(v >= 16 and v == int(v) for v in size):
            raise ValueError_(f"{path}.size", "two whole numbers of pixels, at least 16", size)
        fov, near, far = (
            _numbers(entry, key, (getattr(base, key),), 1, path)[0]
            for key in ("fov_y_deg", "near", "far")
        )
        if not (1.0 <= fov <= 170.0 and 0.0 < near < far):
            raise ValueError_(path, "a field of view of 1-170 deg and 0 < near < far", entry)
        cameras[name] = CameraSettings(
            decode_value(ParamType.POSE, entry["pose"], f"{path}.pose") if "pose" in entry else base.pose,
            on_wrist, (int(size[0]), int(size[1])), fov, near, far,
        )  # fmt: skip
    return cameras
