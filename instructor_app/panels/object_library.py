"""The Objects panel: the object models the cell knows, with a picture of each, their
symmetry, markers and grasp poses; and Add model… from a mesh file. A model dragged onto a
node of the canvas becomes a Pick of it there (the shipped Pick subtree, "Pick cup").

Models come from the cell's library (the shipped ``resources/objects``) and from the
user's own library folder, where added models go (a model folder written whole, see
:mod:`capabilities.object_import`). Thumbnails are drawn off the GUI thread without OpenGL
and cached on disk (:mod:`instructor_app.panels.object_thumbnails`). A broken model shows
its error instead of a picture; it never stops the others from showing.
"""

from __future__ import annotations

import contextlib
import json
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np
from PySide6.QtCore import QMimeData, QSize, QStandardPaths, Qt, Signal
from PySide6.QtGui import QIcon, QImage, QPixmap
from PySide6.QtWidgets import (
    QDialog,
    QFileDialog,
    QLabel,
    QListWidget,
    QListWidgetItem,
    QPushButton,
    QVBoxLayout,
    QWidget,
)

from capabilities.object_import import MESH_SUFFIXES, NewModel, import_mesh_model
from capabilities.object_library import ObjectLibrary, ObjectLibraryError, ObjectModelSpec
from instructor_app.node_factory import PALETTE_MIME, pick_payload
from instructor_app.panels.object_model_dialog import AddModelDialog
from instructor_app.panels.object_thumbnails import ThumbnailCache

__all__ = ["ObjectLibraryPanel", "describe_model", "user_library_folder"]

MeshAsker = Callable[[QWidget], str]
DetailsAsker = Callable[[QWidget, Path, list[str]], NewModel | None]
_ROLE_NAME = Qt.ItemDataRole.UserRole


def user_library_folder() -> Path:
    """``<AppDataLocation>/objects``: where models the worker adds go."""
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
    return Path(base or Path.home() / ".costar") / "objects"


def _thumbnail_folder() -> Path:
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.CacheLocation)
    return Path(base or Path.home() / ".cache" / "costar") / "thumbnails"


def _ask_mesh(parent: QWidget) -> str:
    patterns = " ".join(f"*{s}" for s in MESH_SUFFIXES)
    return QFileDialog.getOpenFileName(
        parent, "Add a model from a mesh", "", f"Meshes ({patterns})"
    )[0]


def _ask_details(parent: QWidget, mesh: Path, taken: list[str]) -> NewModel | None:
    dialog = AddModelDialog(mesh, taken, parent)
    return dialog.model() if dialog.exec() == QDialog.DialogCode.Accepted else None


def _symmetry_text(spec: ObjectModelSpec) -> str:
    symmetry = spec.symmetry
    axis = "xyz"[int(np.argmax(np.abs(symmetry.axis)))] if symmetry.kind != "none" else ""
    if symmetry.kind == "continuous":
        return f"any turn about {axis}"
    if symmetry.kind == "discrete":
        return f"every {360 / symmetry.order:g}° about {axis} (order {symmetry.order})"
    return "none"


def _mm(position: Any) -> str:
    return "(" + ", ".join(f"{v * 1000:.0f}" for v in position) + ") mm"


def _grasp_lines(spec: ObjectModelSpec) -> list[str]:
    """The model's grasps: name, tool, the holding TCP and its approach (object frame)."""
    return [
        f"{g.name} ({g.tool}): at {_mm(g.pose.position)}, from {_mm(g.approach.position)}"
        for g in spec.grasps
    ]


def describe_model(spec: ObjectModelSpec, user: bool = False) -> str:
    """What the panel says about a model (rich text)."""
    size = " &times; ".join(f"{v * 1000:.0f}" for v in spec.dimensions)
    markers = ", ".join(str(m.marker_id) for m in spec.markers) or "none"
    grasps = _grasp_lines(spec)
    lines = [
        f"<b>{spec.name}</b>" + (" (your library)" if user else ""),
        spec.description,
        f"Size: {size} mm; mass {spec.mass * 1000:.0f} g",
        f"Symmetry: {_symmetry_text(spec)}",
        f"Markers: {markers}",
        "Grasps: " + ("<br>&nbsp;&nbsp;".join(["", *grasps]) if grasps else "none taught"),
    ]
    return "<br>".join(line for line in lines if line)


class _ObjectList(QListWidget):
    """The models; a model drags onto the canvas as a Pick of it (the shipped Pick subtree)."""

    def mimeData(self, items: Iterable[QListWidgetItem]) -> QMimeData:
        mime = QMimeData()
        name = next((i.data(_ROLE_NAME) for i in items if i.flags() & _DRAGGABLE), None)
        if name:
            mime.setData(PALETTE_MIME, json.dumps(pick_payload(name)).encode("utf-8"))
            mime.setText(name)
        return mime

    def mimeTypes(self) -> list[str]:
        return [PALETTE_MIME]


_DRAGGABLE = Qt.ItemFlag.ItemIsDragEnabled


class ObjectLibraryPanel(QWidget):
    """The known object models with thumbnails; Add model… from a mesh.

    Args:
        user_folder: the worker's own library (default: :func:`user_library_folder`).
        thumbnails: the thumbnail cache (default: in the user's cache folder).
        ask_mesh / ask_details: the file dialog and the details dialog (tests replace them).

    Signals:
        message(str): what happened, or why not.
        models_changed(): a model was added (it is selected).
    """

    message = Signal(str)
    models_changed = Signal()
    _drawn = Signal(str, object)  # from the drawing thread: (name, RGBA array or error text)
    _added = Signal(object)  # from the same thread: the new model's spec, or why not

    def __init__(
        self,
        user_folder: Path | None = None,
        thumbnails: ThumbnailCache | None = None,
        parent: QWidget | None = None,
        ask_mesh: MeshAsker = _ask_mesh,
        ask_details: DetailsAsker = _ask_details,
    ) -> None:
        super().__init__(parent)
        self.user_folder = user_folder or user_library_folder()
        self.thumbnails = thumbnails or ThumbnailCache(_thumbnail_folder())
        self.ask_mesh, self.ask_details = ask_mesh, ask_details
        self._shipped = ObjectLibrary()
        self._specs: dict[str, tuple[ObjectModelSpec, bool]] = {}
        self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="costar-thumbnails")
        self.list = _ObjectList()
        self.list.setDragEnabled(True)
        self.list.setDragDropMode(QListWidget.DragDropMode.DragOnly)
        self.list.setIconSize(QSize(self.thumbnails.size, self.thumbnails.size))
        self.list.currentItemChanged.connect(lambda *_: self._show_selected())
        self.details = QLabel()
        self.details.setWordWrap(True)
        self.details.setTextFormat(Qt.TextFormat.RichText)
        self.details.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.add_button = QPushButton("Add model…")
        self.add_button.setToolTip("Add an object model from a mesh file to your library")
        self.add_button.clicked.connect(self._add_asked)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        layout.addWidget(self.list, 1)
        layout.addWidget(self.details)
        layout.addWidget(self.add_button)
        self._drawn.connect(self._set_thumbnail)
        self._added.connect(self._on_added)
        self.refresh()

    # ------------------------------------------------------------------ public

    def set_registry(self, registry: Any) -> None:
        """The cell's own library (its ``objects`` interface) is what it shows first."""
        cell = getattr(registry, "cell", None)
        library = cell.interfaces().get("objects") if cell is not None else None
        self._shipped = library if isinstance(library, ObjectLibrary) else ObjectLibrary()
        self.refresh()

    def names(self) -> list[str]:
        return [self.list.item(i).data(_ROLE_NAME) for i in range(self.list.count())]

    def spec(self, name: str) -> ObjectModelSpec:
        return self._specs[name][0]

    def select(self, name: str) -> None:
        self.list.setCurrentRow(self.names().index(name))

    def refresh(self) -> None:
        """Read both libraries again and (re)draw missing thumbnails off the GUI thread."""
        current = self.list.currentItem()
        chosen = current.data(_ROLE_NAME) if current is not None else None
        self.list.clear()
        self._specs.clear()
        for library, user in ((self._shipped, False), (ObjectLibrary(self.user_folder), True)):
            for name in self._library_names(library):
                self._add_item(library, name, user)
        if chosen in self.names():
            self.select(chosen)

    def add_from_mesh(self, mesh: str | Path, model: NewModel) -> bool:
        """Add a model to the user's library off the GUI thread (reading and writing a mesh
        takes a moment): ``models_changed`` when it is in, a message either way. False (and
        a message) when it is refused at once.
        """
        if model.name in self.names():
            self.message.emit(f"Cannot add {model.name!r}: there is already a model of that name")
            return False
        self.add_button.setEnabled(False)
        self._pool.submit(self._import, Path(mesh), model)
        return True

    def _import(self, mesh: Path, model: NewModel) -> None:
        try:
            outcome: object = import_mesh_model(self.user_folder, mesh, model)
        except ObjectLibraryError as exc:
            outcome = f"Cannot add the model: {exc}"
        except Exception as exc:  # an unreadable mesh must not take the panel down
            outcome = f"Cannot add the model: {type(exc).__name__}: {exc}"
        with contextlib.suppress(RuntimeError):  # the panel is gone
            self._added.emit(outcome)

    def _on_added(self, outcome: object) -> None:
        self.add_button.setEnabled(True)
        if not isinstance(outcome, ObjectModelSpec):
            self.message.emit(str(outcome))
            return
        self.refresh()
        self.select(outcome.name)
        self.message.emit(f"Added the model {outcome.name!r} to {self.user_folder}")
        self.models_changed.emit()

    def has_thumbnail(self, name: str) -> bool:
        """True once the model's row shows its picture."""
        return not self.list.item(self.names().index(name)).icon().isNull()

    def shutdown(self) -> None:
        """Cancel the drawings not begun and wait for the one under way (a moment)."""
        self._pool.shutdown(wait=True, cancel_futures=True)

    # ------------------------------------------------------------------ internals

    @staticmethod
    def _library_names(library: ObjectLibrary) -> list[str]:
        try:
            return library.names()
        except OSError:  # no such folder yet (the user's library before the first model)
            return []

    def _add_item(self, library: ObjectLibrary, name: str, user: bool) -> None:
        item = QListWidgetItem(name + (" (yours)" if user else ""))
        item.setData(_ROLE_NAME, name)
        self.list.addItem(item)
        try:
            spec = library.get(name)
        except ObjectLibraryError as exc:
            item.setToolTip(str(exc))
            item.setText(f"{name}: broken model")
            item.setFlags(item.flags() & ~_DRAGGABLE)
            return
        self._specs[name] = (spec, user)
        item.setToolTip(f"{_symmetry_text(spec)}\nDrag onto the canvas: Pick {name}")
        self._pool.submit(self._draw, spec)

    def _draw(self, spec: ObjectModelSpec) -> None:
        try:
            picture: object = self.thumbnails.get(spec)
        except Exception as exc:  # a mesh that will not draw: say so on its row
            picture = f"no picture: {type(exc).__name__}: {exc}"
        with contextlib.suppress(RuntimeError):  # the panel is gone: nobody to show it to
            self._drawn.emit(spec.name, picture)

    def _set_thumbnail(self, name: str, picture: object) -> None:
        for index in range(self.list.count()):
            item = self.list.item(index)
            if item.data(_ROLE_NAME) != name:
                continue
            if isinstance(picture, np.ndarray):
                height, width = picture.shape[:2]
                image = QImage(
                    picture.tobytes(), width, height, 4 * width, QImage.Format.Format_RGBA8888
                )
                item.setIcon(QIcon(QPixmap.fromImage(image.copy())))
            else:
                item.setToolTip(str(picture))

    def _show_selected(self) -> None:
        item = self.list.currentItem()
        found = self._specs.get(item.data(_ROLE_NAME)) if item is not None else None
        if found is None:
            self.details.setText(item.toolTip() if item is not None else "")
            return
        self.details.setText(describe_model(*found))

    def _add_asked(self) -> None:
        mesh = self.ask_mesh(self)
        if not mesh:
            return
        model = self.ask_details(self, Path(mesh), self.names())
        if model is not None:
            self.add_from_mesh(mesh, model)
