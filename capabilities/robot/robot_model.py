"""The robot's model files: the UR5 of example-robot-data and our own parts in resources.

The simulated cell loads them into pybullet (``capabilities.sim.robot_model`` writes the
URDF it can read); the Instructor's 3D view draws the arm with the collision meshes.
"""

from __future__ import annotations

from importlib import metadata
from pathlib import Path

from capabilities.robot.errors import RobotCellError
from resources import resource_path

__all__ = ["ROBOTS_DIR", "find_ur5_urdf", "ur5_collision_meshes"]

ROBOTS_DIR = resource_path("robots")
_UR5_SUFFIX = "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"


def find_ur5_urdf() -> Path:
    """Path of the UR5 URDF installed by the example-robot-data package.

    Raises:
        RobotCellError: the package or its UR5 model is not installed.
    """
    try:
        files = metadata.files("example-robot-data") or []
    except metadata.PackageNotFoundError as exc:
        raise RobotCellError(
            "example-robot-data is not installed (pip install example-robot-data)"
        ) from exc
    for entry in files:
        if str(entry).endswith(_UR5_SUFFIX):
            path = Path(str(entry.locate())).resolve()
            if path.is_file():
                return path
    raise RobotCellError(f"example-robot-data has no {_UR5_SUFFIX}")


def ur5_collision_meshes(urdf: Path | None = None) -> Path:
    """The folder of the UR5's collision meshes (one STL per link: ``base.stl``, ...).

    Args:
        urdf: example-robot-data's UR5 URDF; default :func:`find_ur5_urdf`.
    """
    return (urdf or find_ur5_urdf()).parents[1] / "meshes" / "ur5" / "collision"
