"""Adding an object model to a library from a mesh file (OBJ, STL, PLY, OFF).

The mesh is read with Open3D, brought to the library's convention (metres; optionally the
object frame moved to the bottom centre of the mesh, z up) and written as the model's own
mesh; ``model.json`` gets the name, description, bounding-box dimensions, a convex-hull
collision, the mass, the symmetry and a colour. The whole model folder is first written
under a temporary name in the library and then renamed, so a library never holds half a
model; the new model is read back through :class:`ObjectLibrary` (the same checks as
every model).
"""

from __future__ import annotations

import json
import re
import shutil
import uuid
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from capabilities.object_library import ObjectLibrary, ObjectLibraryError, ObjectModelSpec
from engine.files import PlanFileError
from engine.plan_writer import write_atomic

__all__ = ["MESH_SUFFIXES", "NewModel", "import_mesh_model", "valid_model_name"]

MESH_SUFFIXES = (".obj", ".stl", ".ply", ".off")
_NAME = re.compile(r"^[a-z0-9][a-z0-9_]{0,47}$")
_UNITS = {"m": 1.0, "mm": 0.001, "cm": 0.01}


@dataclass(frozen=True)
class NewModel:
    """What the worker says about a new model.

    Attributes:
        name: lower-case letters, digits and underscores ("bracket_a"); the folder's name.
        symmetry: ``none``, ``continuous`` or ``discrete``.
        axis: the symmetry axis in the object frame (x, y or z).
        order: for a discrete symmetry, how many equal turns make a full one.
        mass: kg, above 0.
        units: the mesh file's length unit (m, mm or cm).
        origin_at_bottom: move the object frame to the bottom centre of the mesh.
        description: one line for people.
        color: RGBA 0..1.
    """

    name: str
    symmetry: str = "none"
    axis: str = "z"
    order: int = 2
    mass: float = 0.1
    units: str = "m"
    origin_at_bottom: bool = True
    description: str = ""
    color: tuple[float, float, float, float] = (0.6, 0.6, 0.65, 1.0)


def valid_model_name(name: str) -> str:
    """What is wrong with ``name`` as a model folder's name; "" when it can name one."""
    if not _NAME.match(name):
        return (
            f"{name!r} is not a model name: use lower-case letters, digits and underscores, "
            "starting with a letter or digit (at most 48)"
        )
    return ""


def _symmetry_json(model: NewModel) -> dict[str, object]:
    if model.symmetry == "none":
        return {"kind": "none"}
    axis = [1.0 if model.axis == a else 0.0 for a in "xyz"]
    if model.symmetry == "continuous":
        return {"kind": "continuous", "axis": axis}
    return {"kind": "discrete", "axis": axis, "order": int(model.order)}


def _check(model: NewModel, mesh_file: Path, library: Path) -> None:
    problem = valid_model_name(model.name)
    if problem:
        raise ObjectLibraryError(problem)
    if (library / model.name).exists():
        raise ObjectLibraryError(f"{library / model.name}: there is already a model {model.name!r}")
    if mesh_file.suffix.lower() not in MESH_SUFFIXES:
        raise ObjectLibraryError(f"{mesh_file}: not a mesh file ({', '.join(MESH_SUFFIXES)})")
    if model.symmetry not in ("none", "continuous", "discrete") or model.axis not in "xyz":
        raise ObjectLibraryError(f"symmetry {model.symmetry!r} about {model.axis!r} is not known")
    if model.symmetry == "discrete" and model.order < 2:
        raise ObjectLibraryError("a discrete symmetry needs an order of 2 or more")
    if not model.mass > 0 or model.units not in _UNITS:
        raise ObjectLibraryError(f"mass must be above 0 kg and units one of {list(_UNITS)}")


def _read_mesh(mesh_file: Path, model: NewModel) -> tuple[object, np.ndarray, bool]:
    """The mesh in metres in the object frame, its vertices, and whether they changed."""
    from capabilities.open3d_lib import o3d  # only when a model is added (a large import)

    mesh = o3d.io.read_triangle_mesh(str(mesh_file))  # type: ignore[arg-type]  # str works
    vertices = np.asarray(mesh.vertices, dtype=float) * _UNITS[model.units]
    if len(vertices) < 4 or len(np.asarray(mesh.triangles)) < 4:
        raise ObjectLibraryError(f"{mesh_file}: no usable triangle mesh in the file")
    if not np.all(np.isfinite(vertices)):
        raise ObjectLibraryError(f"{mesh_file}: the mesh has vertices that are not numbers")
    changed = model.units != "m"
    if model.origin_at_bottom:
        low, high = vertices.min(axis=0), vertices.max(axis=0)
        shift = np.array([(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, low[2]])
        changed = changed or bool(np.any(np.abs(shift) > 1e-9))
        vertices = vertices - shift
    mesh.vertices = o3d.utility.Vector3dVector(vertices)
    return mesh, vertices, changed


def import_mesh_model(
    library: Path | str, mesh_file: Path | str, model: NewModel
) -> ObjectModelSpec:
    """Add a model to the library folder ``library`` (made if missing) from a mesh file.

    Raises:
        ObjectLibraryError: a bad name or one taken, a file that is no mesh, bad details,
            or a folder that cannot be written; the message names the file.
    """
    library, mesh_file = Path(library), Path(mesh_file)
    _check(model, mesh_file, library)
    mesh, vertices, changed = _read_mesh(mesh_file, model)
    dimensions = vertices.max(axis=0) - vertices.min(axis=0)
    if float(dimensions.min()) <= 0:
        raise ObjectLibraryError(f"{mesh_file}: the mesh is flat (dimensions {dimensions} m)")
    folder = library / f".{model.name}.{uuid.uuid4().hex[:8]}.tmp"
    try:
        folder.mkdir(parents=True)
        if changed or mesh_file.suffix.lower() != ".obj":
            _write_mesh(folder / f"{model.name}.obj", mesh)
        else:  # already as the library wants it: the file itself is copied
            shutil.copyfile(mesh_file, folder / f"{model.name}.obj")
        _write_model(folder, model, dimensions)
        folder.rename(library / model.name)
    except (OSError, PlanFileError) as exc:
        shutil.rmtree(folder, ignore_errors=True)
        raise ObjectLibraryError(f"{library / model.name}: cannot write: {exc}") from exc
    return ObjectLibrary(library).get(model.name)


def _write_mesh(path: Path, mesh: object) -> None:
    from capabilities.open3d_lib import o3d

    if not o3d.io.write_triangle_mesh(str(path), mesh):  # type: ignore[arg-type]  # str works
        raise OSError(f"the mesh could not be written to {path}")


def _write_model(folder: Path, model: NewModel, dimensions: np.ndarray) -> None:
    mesh_name = f"{model.name}.obj"
    data = {
        "format_version": 1,
        "name": model.name,
        "description": model.description,
        "mesh": mesh_name,
        "collision": {"type": "convex_hull"},
        "mass": float(model.mass),
        "dimensions": [round(float(v), 6) for v in dimensions],
        "symmetry": _symmetry_json(model),
        "color": [float(c) for c in model.color],
    }
    text = json.dumps(data, indent=2, ensure_ascii=False) + "\n"
    write_atomic(folder / "model.json", text.encode("utf-8"))
