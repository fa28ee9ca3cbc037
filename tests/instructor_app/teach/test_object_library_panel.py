"""The Objects panel: every model with a thumbnail (drawn off the GUI thread, cached on disk),
its symmetry, markers and grasps; Add model… from a mesh through its dialog, written whole
into the user's library folder and read back like any model.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QDialogButtonBox

from capabilities.object_import import NewModel
from capabilities.object_library import ObjectLibrary, default_library_path
from instructor_app.panels.object_library import ObjectLibraryPanel
from instructor_app.panels.object_model_dialog import AddModelDialog
from instructor_app.panels.object_thumbnails import ThumbnailCache, render_mesh
from tests.instructor_app.gui_driver import choose

SHIPPED = ObjectLibrary().names()


@pytest.fixture
def folders(tmp_path: Path) -> tuple[Path, Path]:
    return tmp_path / "my objects", tmp_path / "thumbnails"


def make_panel(qtbot: Any, folders: tuple[Path, Path], **kw: Any) -> ObjectLibraryPanel:
    panel = ObjectLibraryPanel(folders[0], ThumbnailCache(folders[1], 64), **kw)
    qtbot.addWidget(panel)
    panel.show()
    return panel


def box_mesh_file(folder: Path, size_mm: tuple[float, float, float]) -> Path:
    """An STL box in millimetres, its corner at the origin (as CAD exports often are)."""
    from capabilities.open3d_lib import o3d

    box = o3d.geometry.TriangleMesh.create_box(*size_mm)
    box.compute_triangle_normals()
    path = folder / "Bracket A.stl"
    folder.mkdir(parents=True, exist_ok=True)
    assert o3d.io.write_triangle_mesh(str(path), box)
    return path


def test_every_model_has_a_thumbnail_and_its_facts(qtbot: Any, folders: tuple[Path, Path]) -> None:
    panel = make_panel(qtbot, folders)
    assert panel.names() == SHIPPED
    qtbot.waitUntil(lambda: all(panel.has_thumbnail(n) for n in SHIPPED), timeout=30_000)
    assert panel.thumbnails.drawn == len(SHIPPED)
    panel.select("cup")
    text = panel.details.text()
    assert (
        "any turn about z" in text
        and "Markers: 1, 2" in text
        and "80 &times; 80 &times; 100 mm" in text
    )
    panel.select("plate_4_holes")
    assert "every 90° about z (order 4)" in panel.details.text()
    again = make_panel(qtbot, folders)  # the pictures come from the cache now
    qtbot.waitUntil(lambda: all(again.has_thumbnail(n) for n in SHIPPED), timeout=10_000)
    assert again.thumbnails.drawn == 0
    panel.shutdown()
    again.shutdown()


def test_the_picture_shows_the_mesh_in_its_colour() -> None:
    cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])  # fmt: skip
    picture = render_mesh(cube, faces, (1.0, 0.0, 0.0, 1.0), 48)
    assert picture.shape == (48, 48, 4)
    inside = picture[picture[..., 3] == 255]
    assert 0.3 < len(inside) / 48**2 < 0.9  # drawn, with a transparent margin
    assert np.all(inside[:, 1:3] == 0) and inside[:, 0].max() > 200  # red, shaded
    assert picture[0, 0, 3] == 0


def test_grasps_show_when_the_model_has_them(qtbot: Any, folders: tuple[Path, Path]) -> None:
    user = folders[0]
    shutil.copytree(default_library_path() / "cup", user / "held_cup")
    data = json.loads((user / "held_cup" / "model.json").read_text())
    down = {"position": [0.0, 0.0, 0.06], "orientation": [1.0, 0.0, 0.0, 0.0]}
    above = {"position": [0.0, 0.0, 0.16], "orientation": [1.0, 0.0, 0.0, 0.0]}
    data.update(
        name="held_cup",
        grasps=[{"name": "side", "tool": "gripper", "pose": down, "approach": above}],
    )
    (user / "held_cup" / "model.json").write_text(json.dumps(data))
    panel = make_panel(qtbot, folders)
    panel.select("held_cup")
    assert "held_cup</b> (your library)" in panel.details.text()
    assert "side (gripper): at (0, 0, 60) mm, from (0, 0, 160) mm" in panel.details.text()
    panel.select("cup")  # the shipped cup's grasps, as the library parses them
    assert "top (gripper): at (0, 0, 60) mm, from (0, 0, 220) mm" in panel.details.text()
    panel.select("kit_bin")
    assert "Grasps: none taught" in panel.details.text()
    panel.shutdown()


def fill_dialog(qtbot: Any, dialog: AddModelDialog, name: str) -> None:
    dialog.name_edit.selectAll()
    qtbot.keyClicks(dialog.name_edit, name)
    choose(qtbot, dialog.symmetry_combo, "discrete")
    dialog.order_spin.setValue(2)
    choose(qtbot, dialog.units_combo, "mm")
    dialog.mass_spin.setValue(0.25)


def test_add_a_model_from_a_mesh_through_the_dialog(
    qtbot: Any, folders: tuple[Path, Path], tmp_path: Path
) -> None:
    mesh = box_mesh_file(tmp_path / "cad", (120.0, 60.0, 30.0))

    def details(parent: Any, chosen: Path, taken: list[str]) -> NewModel | None:
        dialog = AddModelDialog(chosen, taken, parent)
        qtbot.addWidget(dialog)
        assert dialog.name_edit.text() == "bracket_a"  # suggested from the file's name
        fill_dialog(qtbot, dialog, "cup")  # taken: OK is off and the dialog says why
        ok = dialog.buttons.button(QDialogButtonBox.StandardButton.Ok)
        assert not ok.isEnabled() and "already a model 'cup'" in dialog.problem_label.text()
        fill_dialog(qtbot, dialog, "bracket_a")
        assert ok.isEnabled()
        return dialog.model()

    panel = make_panel(qtbot, folders, ask_mesh=lambda parent: str(mesh), ask_details=details)
    messages: list[str] = []
    panel.message.connect(messages.append)
    with qtbot.waitSignal(panel.models_changed):
        qtbot.mouseClick(panel.add_button, Qt.MouseButton.LeftButton)
    assert (
        panel.names() == [*SHIPPED, "bracket_a"]
        and panel.list.currentItem().text() == "bracket_a (yours)"
    )
    spec = ObjectLibrary(folders[0]).get("bracket_a")  # read back by the library itself
    assert spec.dimensions == pytest.approx((0.12, 0.06, 0.03))
    assert (spec.symmetry.kind, spec.symmetry.order, spec.mass) == ("discrete", 2, 0.25)
    assert spec.mesh_file.name == "bracket_a.obj"
    verts = np.loadtxt(
        [ln[2:] for ln in spec.mesh_file.read_text().splitlines() if ln.startswith("v ")]
    )
    assert verts.min(axis=0) == pytest.approx((-0.06, -0.03, 0.0))  # bottom centre, metres
    assert sorted(p.name for p in folders[0].iterdir()) == ["bracket_a"]  # no temporary left
    assert "every 180° about z" in panel.details.text()
    qtbot.waitUntil(lambda: panel.has_thumbnail("bracket_a"), timeout=10_000)
    assert messages[-1].startswith("Added the model 'bracket_a'")
    panel.shutdown()


def test_what_cannot_be_added_is_said_and_nothing_is_written(
    qtbot: Any, folders: tuple[Path, Path], tmp_path: Path
) -> None:
    panel = make_panel(qtbot, folders)
    messages: list[str] = []
    panel.message.connect(messages.append)
    text = tmp_path / "notes.txt"
    text.write_text("not a mesh")
    broken = tmp_path / "broken.obj"
    broken.write_text("v 0 0 0\nf 1 1 1\n")
    tries = [(text, "notes"), (broken, "broken"), (broken, "Bad Name")]
    for mesh, name in tries:  # each is read and refused on the panel's worker thread
        with qtbot.waitSignal(panel.message, timeout=20_000):
            assert panel.add_from_mesh(mesh, NewModel(name))
    assert panel.add_from_mesh(broken, NewModel("cup")) is False  # refused at once
    assert "notes.txt: not a mesh file" in messages[0]
    assert "broken.obj: no usable triangle mesh" in messages[1]
    assert "'Bad Name' is not a model name" in messages[2]
    assert "already a model" in messages[3]
    assert panel.add_button.isEnabled()
    assert not folders[0].exists() or not list(folders[0].iterdir())
    panel.shutdown()
