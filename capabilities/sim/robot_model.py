"""The robot's URDF: the UR5 of example-robot-data with its meshes, plus our gripper.

example-robot-data refers to its meshes with ``package://`` URLs, which pybullet cannot
resolve; at load time a copy with absolute mesh paths, without the URDF's ``world`` link (so
that ``base_link`` is the root pybullet places) and with the primitive gripper of
``resources/robots/parallel_gripper.urdf.xml`` fixed to ``tool0``, is written to a cache
directory. The meshes themselves are never copied.
"""

from __future__ import annotations

import hashlib
import os
import re
import tempfile
from importlib import metadata
from pathlib import Path

from capabilities.sim.errors import SimError
from resources import resource_path

__all__ = ["ROBOTS_DIR", "find_ur5_urdf", "robot_urdf_path"]

ROBOTS_DIR = resource_path("robots")
_UR5_SUFFIX = "example-robot-data/robots/ur_description/urdf/ur5_robot.urdf"
_PACKAGE_PREFIX = "package://example-robot-data/"


def find_ur5_urdf() -> Path:
    """Path of the UR5 URDF installed by the example-robot-data package.

    Raises:
        SimError: the package or its UR5 model is not installed.
    """
    try:
        files = metadata.files("example-robot-data") or []
    except metadata.PackageNotFoundError as exc:
        raise SimError(
            "example-robot-data is not installed (pip install example-robot-data)"
        ) from exc
    for entry in files:
        if str(entry).endswith(_UR5_SUFFIX):
            path = Path(str(entry.locate())).resolve()
            if path.is_file():
                return path
    raise SimError(f"example-robot-data has no {_UR5_SUFFIX}")


def _share_dir(urdf: Path) -> Path:
    """The directory that holds ``example-robot-data/`` (what ``package://`` refers to)."""
    parts = urdf.parts
    index = len(parts) - 1 - parts[::-1].index("example-robot-data")
    return Path(*parts[:index])


def build_robot_urdf(urdf: Path, gripper_fragment: str) -> str:
    """The UR5 URDF text with resolved mesh paths, no world link, and the gripper added."""
    text = urdf.read_text(encoding="utf-8")
    text = text.replace(_PACKAGE_PREFIX, f"{_share_dir(urdf).as_posix()}/example-robot-data/")
    text = re.sub(r'<link name="world"\s*/>', "", text)
    text = re.sub(r'<joint name="world_joint".*?</joint>', "", text, flags=re.S)
    body = re.search(r"<fragment>(.*)</fragment>", gripper_fragment, flags=re.S)
    if body is None:
        raise SimError("parallel_gripper.urdf.xml has no <fragment> element")
    if "</robot>" not in text:
        raise SimError(f"{urdf}: no </robot> end tag")
    return text.replace("</robot>", body.group(1) + "\n</robot>")


def robot_urdf_path(cache_dir: Path | None = None) -> Path:
    """Write (once per content) the resolved robot URDF and return its path."""
    fragment = (ROBOTS_DIR / "parallel_gripper.urdf.xml").read_text(encoding="utf-8")
    text = build_robot_urdf(find_ur5_urdf(), fragment)
    digest = hashlib.sha1(text.encode("utf-8")).hexdigest()[:12]
    folder = cache_dir or Path(tempfile.gettempdir()) / "costar_sim"
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"ur5_gripper_{digest}.urdf"
    if not path.is_file():
        # Written atomically: several cells (test workers) may build it at the same time.
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".urdf.tmp")
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
        os.replace(tmp, path)
    return path
