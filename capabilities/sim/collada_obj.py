"""The UR5's COLLADA visual meshes as Wavefront OBJ files.

pybullet parses a COLLADA file (the UR5's are 1-2 MB of XML each) every time a world loads
the robot: 0.6 s of a simulated cell's start, paid again by every cell a test, a benchmark
trial or Reset Cell opens. An OBJ of the same triangles and normals loads in a tenth of
that. pybullet's renderer draws the COLLADA meshes white (it takes no colour from them), as
it draws an OBJ given white: the rendered frames, and so what perception sees, stay the same.

Only what example-robot-data's UR5 files use is read: ``<triangles>`` with VERTEX and
NORMAL inputs under nodes placed by a matrix, in metres with z up. Anything else raises
:class:`SimError`.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from capabilities.sim.errors import SimError

__all__ = ["obj_of_collada"]

_NS = {"c": "http://www.collada.org/2005/11/COLLADASchema"}


def obj_of_collada(dae: Path, folder: Path) -> Path:
    """The OBJ of ``dae``'s triangles in ``folder``, written once per version of ``dae``.

    Raises:
        SimError: the file uses COLLADA features this does not read.
    """
    stat = dae.stat()
    target = folder / f"{dae.stem}_{stat.st_size}_{stat.st_mtime_ns}.obj"
    if target.is_file():
        return target
    root = _parse(dae)
    parts = []
    for matrix, geometry_id in _instances(root, dae):
        vertices, normals = _triangles(root, geometry_id, dae)
        parts.append((vertices @ matrix[:3, :3].T + matrix[:3, 3], normals @ matrix[:3, :3].T))
    folder.mkdir(parents=True, exist_ok=True)
    # Written under another name, then renamed: test workers may convert at the same time.
    tmp = target.with_name(f"{target.name}.{os.getpid()}.tmp")
    tmp.write_text(_obj_text(parts), encoding="utf-8")
    os.replace(tmp, target)
    return target


def _parse(dae: Path) -> ET.Element:
    try:
        root = ET.parse(dae).getroot()
    except (OSError, ET.ParseError) as exc:
        raise SimError(f"{dae}: cannot read it as COLLADA: {exc}") from exc
    axis = (root.findtext("c:asset/c:up_axis", default="Y_UP", namespaces=_NS) or "").strip()
    unit = root.find("c:asset/c:unit", _NS)
    scale = float(unit.get("meter", "1")) if unit is not None else 1.0
    if axis != "Z_UP" or scale != 1.0:
        raise SimError(f"{dae}: only Z_UP in metres is read (this is {axis}, {scale} m)")
    return root


def _instances(root: ET.Element, dae: Path) -> list[tuple[np.ndarray, str]]:
    """(node matrix, geometry id) of each geometry the scene places."""
    found = []
    for node in root.iterfind(".//c:library_visual_scenes//c:node", _NS):
        for instance in node.iterfind("c:instance_geometry", _NS):
            nested = node.find("c:node", _NS) is not None
            if nested or node.find("c:translate", _NS) is not None:
                raise SimError(f"{dae}: nested or translated nodes are not read")
            text = node.findtext("c:matrix", default="", namespaces=_NS) or ""
            values = [float(v) for v in text.split()] if text else list(np.eye(4).ravel())
            if len(values) != 16:
                raise SimError(f"{dae}: a node matrix of {len(values)} numbers")
            geometry = instance.get("url", "").lstrip("#")
            found.append((np.array(values).reshape(4, 4), geometry))
    return found


def _triangles(root: ET.Element, geometry_id: str, dae: Path) -> tuple[np.ndarray, np.ndarray]:
    """The geometry's triangles as (3N x 3 positions, 3N x 3 normals), corner by corner."""
    geometry = root.find(f"c:library_geometries/c:geometry[@id='{geometry_id}']", _NS)
    mesh = geometry.find("c:mesh", _NS) if geometry is not None else None
    if mesh is None or mesh.find("c:polylist", _NS) is not None:
        raise SimError(f"{dae}: geometry {geometry_id!r} is not a mesh of triangles")
    sources = {
        source.get("id", ""): np.array(
            (source.findtext("c:float_array", default="", namespaces=_NS) or "").split(), float
        )
        for source in mesh.iterfind("c:source", _NS)
    }
    vertices = mesh.find("c:vertices", _NS)
    position = vertices.find("c:input[@semantic='POSITION']", _NS) if vertices is not None else None
    if position is None:
        raise SimError(f"{dae}: geometry {geometry_id!r} has no vertex positions")
    points = sources[position.get("source", "").lstrip("#")].reshape(-1, 3)
    corners, normals = [], []
    for triangles in mesh.iterfind("c:triangles", _NS):
        inputs = {i.get("semantic"): i for i in triangles.iterfind("c:input", _NS)}
        if set(inputs) != {"VERTEX", "NORMAL"}:
            raise SimError(f"{dae}: triangles with inputs {sorted(map(str, inputs))} not read")
        offset = {name: int(i.get("offset", "0")) for name, i in inputs.items()}
        text = triangles.findtext("c:p", default="", namespaces=_NS) or ""
        indices = np.array(text.split(), int).reshape(-1, 1 + max(offset.values()))
        normal_source = sources[inputs["NORMAL"].get("source", "").lstrip("#")].reshape(-1, 3)
        corners.append(points[indices[:, offset["VERTEX"]]])
        normals.append(normal_source[indices[:, offset["NORMAL"]]])
    if not corners:
        raise SimError(f"{dae}: geometry {geometry_id!r} has no triangles")
    return np.concatenate(corners), np.concatenate(normals)


def _obj_text(parts: list[tuple[np.ndarray, np.ndarray]]) -> str:
    """The triangles (corner by corner: positions and normals) as an OBJ file's text."""
    vertices = np.concatenate([v for v, _ in parts])
    normals = np.concatenate([n for _, n in parts])
    faces = np.arange(1, len(vertices) + 1).reshape(-1, 3)
    lines = [f"v {x:.7g} {y:.7g} {z:.7g}" for x, y, z in vertices]
    lines += [f"vn {x:.6g} {y:.6g} {z:.6g}" for x, y, z in normals]
    lines += [f"f {a}//{a} {b}//{b} {c}//{c}" for a, b, c in faces]
    return "\n".join(lines) + "\n"
