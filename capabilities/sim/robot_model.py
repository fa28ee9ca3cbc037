"""The robot's URDF for pybullet: the UR5 of example-robot-data, plus our gripper.

The model files themselves are found with ``capabilities.robot.robot_model``.

example-robot-data refers to its meshes with ``package://`` URLs, which pybullet cannot
resolve; at load time a copy with absolute mesh paths, without the URDF's ``world`` link (so
that ``base_link`` is the root pybullet places) and with the primitive gripper of
``resources/robots/parallel_gripper.urdf.xml`` fixed to ``tool0``, is written to a cache
directory. The meshes themselves are never copied.

A *light* variant (``light=True``, for the live view's mirror only: ``live_view.py``) draws
each UR5 link with the collision mesh example-robot-data ships beside its visual one (a few
hundred triangles instead of some tens of thousands: pybullet's CPU renderer spent ~28 ms of a
~50 ms frame on them) in a flat UR grey. The STL files carry no usable normals (pybullet draws
them black), so each is converted once with Open3D to a Wavefront OBJ with normals, cached
beside the URDF copy. The physics cell, and so perception, draws the visual meshes:
their COLLADA files are converted once to OBJ files (``collada_obj.py``), drawn the same
white, which pybullet loads 0.6 s faster, and thinned once by quadric decimation to a tenth
of their triangles (96,000 -> 9,600): the robot renders in 9 ms instead of 32 at 320x240
(26 instead of 54 at 640x480), and a 640x480 frame of it differs from the full meshes' in
166 of 307,200 pixels, at the silhouette's edge.
"""

from __future__ import annotations

import hashlib
import os
import re
import tempfile
from collections.abc import Mapping
from pathlib import Path

from capabilities.robot.robot_model import ROBOTS_DIR, find_ur5_urdf, ur5_collision_meshes
from capabilities.sim.collada_obj import obj_of_collada
from capabilities.sim.errors import SimError

__all__ = ["build_robot_urdf", "robot_urdf_path"]

_PACKAGE_PREFIX = "package://example-robot-data/"
# A visual mesh of the UR5 (COLLADA, with its own colours), to be replaced in the light variant.
_VISUAL_MESH = re.compile(r'"[^"]*/meshes/ur5/visual/(\w+)\.dae"\s*/>\s*</geometry>')
_LIGHT_RGBA = "0.72 0.73 0.75 1"  # the UR's grey


def _share_dir(urdf: Path) -> Path:
    """The directory that holds ``example-robot-data/`` (what ``package://`` refers to)."""
    parts = urdf.parts
    index = len(parts) - 1 - parts[::-1].index("example-robot-data")
    return Path(*parts[:index])


def build_robot_urdf(
    urdf: Path,
    gripper_fragment: str,
    light_meshes: Path | None = None,
    visual_objs: Mapping[str, Path] | None = None,
) -> str:
    """The UR5 URDF text with resolved mesh paths, no world link, and the gripper added.

    Args:
        urdf: example-robot-data's UR5 URDF.
        gripper_fragment: the text of ``parallel_gripper.urdf.xml``.
        light_meshes: the folder of the light meshes (``<link>.obj``) to draw the arm's links
            with instead of the visual meshes (see the module's text); None for the visual.
        visual_objs: each visual mesh as an OBJ file, by the COLLADA file's stem
            (``forearm``), drawn white as pybullet draws those (see the module's text).

    Raises:
        SimError: the gripper fragment or the URDF is not what this expects.
    """
    text = urdf.read_text(encoding="utf-8")
    if visual_objs is not None:

        def white_obj(match: re.Match[str]) -> str:
            obj = visual_objs[match.group(1)].as_posix()
            return f'"{obj}"/></geometry><material name="ur5_{match.group(1)}"><color rgba="1 1 1 1"/></material>'

        text, count = _VISUAL_MESH.subn(white_obj, text)
        if count != len(visual_objs):
            raise SimError(f"{urdf}: {count} visual meshes for {len(visual_objs)} OBJ files")
    if light_meshes is not None:
        light = (
            f'"{light_meshes.as_posix()}/\\1.obj"/></geometry>'
            f'<material name="ur5_light_\\1"><color rgba="{_LIGHT_RGBA}"/></material>'
        )
        text, count = _VISUAL_MESH.subn(light, text)
        if count == 0:
            raise SimError(f"{urdf}: no visual mesh under meshes/ur5/visual/ to lighten")
    text = text.replace(_PACKAGE_PREFIX, f"{_share_dir(urdf).as_posix()}/example-robot-data/")
    text = re.sub(r'<link name="world"\s*/>', "", text)
    text = re.sub(r'<joint name="world_joint".*?</joint>', "", text, flags=re.S)
    body = re.search(r"<fragment>(.*)</fragment>", gripper_fragment, flags=re.S)
    if body is None:
        raise SimError("parallel_gripper.urdf.xml has no <fragment> element")
    if "</robot>" not in text:
        raise SimError(f"{urdf}: no </robot> end tag")
    return text.replace("</robot>", body.group(1) + "\n</robot>")


def robot_urdf_path(cache_dir: Path | None = None, light: bool = False) -> Path:
    """Write (once per content) the resolved robot URDF and return its path.

    Args:
        cache_dir: where to write it, default ``costar_sim`` in the temporary directory.
        light: the light variant, for the live view's mirror only (see the module's text).
    """
    fragment = (ROBOTS_DIR / "parallel_gripper.urdf.xml").read_text(encoding="utf-8")
    folder = cache_dir or Path(tempfile.gettempdir()) / "costar_sim"
    folder.mkdir(parents=True, exist_ok=True)
    urdf = find_ur5_urdf()
    if light:
        text = build_robot_urdf(urdf, fragment, _light_meshes(urdf, folder / "ur5_light_meshes"))
    else:
        text = build_robot_urdf(urdf, fragment, visual_objs=_visual_objs(urdf, folder))
    digest = hashlib.sha1(text.encode("utf-8")).hexdigest()[:12]
    path = folder / f"ur5_gripper_{digest}.urdf"
    if not path.is_file():
        # Written atomically: several cells (test workers) may build it at the same time.
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".urdf.tmp")
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
        os.replace(tmp, path)
    return path


_THINNED = 0.1  # the share of a visual mesh's triangles the physics cell draws
_MIN_TRIANGLES = 200


def _visual_objs(urdf: Path, folder: Path) -> dict[str, Path]:
    """Each UR5 visual mesh as a thinned OBJ file (written once per version), by its stem."""
    visual = ur5_collision_meshes(urdf).parent / "visual"
    return {
        dae.stem: _thinned(obj_of_collada(dae, folder / "ur5_visual_meshes"))
        for dae in sorted(visual.glob("*.dae"))
    }


def _thinned(obj: Path) -> Path:
    """``obj`` decimated to ``_THINNED`` of its triangles, beside it (once)."""
    target = obj.with_name(f"{obj.stem}_thinned{round(_THINNED * 100)}.obj")
    if target.is_file():
        return target
    from capabilities.open3d_lib import o3d as open3d  # only once per mesh version

    mesh = open3d.io.read_triangle_mesh(obj)
    count = max(_MIN_TRIANGLES, int(len(mesh.triangles) * _THINNED))
    mesh = mesh.simplify_quadric_decimation(count)
    mesh.compute_vertex_normals()
    mesh.triangle_normals = open3d.utility.Vector3dVector()  # OBJ keeps vertex normals
    # Written under another name, then renamed: test workers may thin at the same time.
    tmp = obj.with_name(f"{target.stem}.{os.getpid()}.tmp.obj")
    open3d.io.write_triangle_mesh(tmp, mesh, write_vertex_normals=True)
    os.replace(tmp, target)
    return target


def _light_meshes(urdf: Path, folder: Path) -> Path:
    """Convert (once) each UR5 collision mesh to an OBJ with normals in ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    for stl in sorted(ur5_collision_meshes(urdf).glob("*.stl")):
        target = folder / f"{stl.stem}.obj"
        if target.is_file():
            continue
        from capabilities.open3d_lib import (
            o3d as open3d,
        )  # only here: the physics cell never needs it

        mesh = open3d.io.read_triangle_mesh(stl)
        if len(mesh.triangles) == 0:
            raise SimError(f"{stl}: no triangles read")
        mesh.compute_vertex_normals()
        mesh.triangle_normals = open3d.utility.Vector3dVector()  # OBJ keeps vertex normals
        # Written under another name, then renamed: two mirrors may convert at the same time.
        tmp = folder / f"{stl.stem}.{os.getpid()}.tmp.obj"
        open3d.io.write_triangle_mesh(tmp, mesh, write_vertex_normals=True)
        os.replace(tmp, target)
    return folder
