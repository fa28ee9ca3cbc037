"""The 3D scene: the robot in its current joints, the furniture, what the cell recognised,
the latest point cloud, the plan's waypoints and regions, and the cameras' view pyramids.

Drawn with pyqtgraph.opengl; where no OpenGL context can be made (``QT_QPA_PLATFORM=offscreen``,
no GL driver) the panel shows why and everything else of the window works. Nothing here
blocks the GUI thread: joints are a read of the arm's last measured state, recognised objects
come from the world model, the point cloud from the camera panel's latest frame, and the
simulation's ground truth (a labelled toggle, for checking perception by eye) is fetched on a
worker thread.

API for other panels: :meth:`Scene3DPanel.show_ghost`,
:meth:`Scene3DPanel.set_gizmo`, :meth:`Scene3DPanel.set_hand_guiding` and the signals ``gizmo_dragged``, ``gizmo_released``,
``point_picked`` and ``region_drawn``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any

import numpy as np
import pyqtgraph.opengl as gl
from PySide6.QtCore import QPoint, Qt, Signal
from PySide6.QtGui import QPainter, QPixmap
from PySide6.QtWidgets import QCheckBox, QLabel, QPushButton, QToolBar, QVBoxLayout, QWidget

from capabilities.base import Cell
from capabilities.cell_features import ShowsGroundTruth
from capabilities.geometry import pose_to_matrix
from capabilities.motion.symmetry import SymmetryTable
from capabilities.motion.targets import TargetResolver
from capabilities.robot_body import RobotBodyError, robot_base_from_arm
from engine.operations import OperationFailed
from engine.types import Pose, Region, Waypoint, WaypointFrame
from instructor_app.idle_timer import IdlePollTimer
from instructor_app.panels.scene3d_items import (
    RobotItems,
    axes_item,
    box_item,
    frustum_lines,
    mesh_data,
    set_pose,
    sphere_item,
)
from instructor_app.panels.scene3d_labels import Label, LabelsItem
from instructor_app.panels.scene3d_pointing import PointingMixin
from instructor_app.panels.scene3d_view import SceneView, opengl_problem

__all__ = ["Scene3DPanel"]

REFRESH_MS = 33  # while something in view changes
# After IDLE_TICKS refreshes without a change the panel looks for changes only every
# IDLE_REFRESH_MS (the arm's joints are a read of a snapshot, the rest compares values); the
# view is redrawn only when something it shows changed, so an idle cell draws nothing.
IDLE_REFRESH_MS = 250
IDLE_TICKS = 30
JOINT_TOLERANCE = 1e-5  # rad: less is the resting arm's numerical jitter, not a move
REGION_RGBA = (1.0, 0.25, 0.8, 0.25)
DETECTED_RGBA = (0.2, 0.9, 0.35, 1.0)
TRUTH_RGBA = (1.0, 0.6, 0.1, 0.45)
FrameSource = Callable[[str], Any]


class Scene3DPanel(PointingMixin, QWidget):
    """The cell in 3D (see the module doc).

    Signals:
        point_picked(object): (x, y, z) of a clicked surface (point cloud, table, furniture).
        region_drawn(object): an ``engine.types.Region`` drawn in region mode.
        gizmo_dragged(object): the target TCP ``Pose`` while the gizmo is dragged.
        gizmo_released(object): the ``Pose`` where the gizmo's drag ended.
        message(str): for the status bar.
    """

    point_picked = Signal(object)
    region_drawn = Signal(object)
    gizmo_dragged = Signal(object)
    gizmo_released = Signal(object)
    message = Signal(str)

    def __init__(self, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setObjectName("Scene3DPanel")
        layout = QVBoxLayout(self)
        layout.setContentsMargins(2, 2, 2, 2)
        problem = opengl_problem()
        self.available = problem is None
        self.view: SceneView | None = None
        self.problem_label = QLabel(f"The 3D scene needs OpenGL: {problem}." if problem else "")
        if problem is not None:
            self.problem_label.setWordWrap(True)
            self.problem_label.setAlignment(Qt.AlignmentFlag.AlignCenter)
            layout.addWidget(self.problem_label)
            return
        self._cell: Cell | None = None
        self._frames: FrameSource = lambda _name: None
        self._regions: list[tuple[str, Region]] = []
        self._waypoints: list[Waypoint] = []
        self._gizmo: Pose | None = None
        self._draft: tuple[np.ndarray, np.ndarray] | None = None  # region centre, view normal
        self._workers = ThreadPoolExecutor(1, "scene3d-truth")
        self._truth_job: Future[list[tuple[str, Pose]]] | None = None
        self._tick = 0
        self._shown_keys: dict[str, Any] = {}  # what each dynamic part was last drawn from
        self._build(layout)
        self._timer = IdlePollTimer(REFRESH_MS, IDLE_REFRESH_MS, IDLE_TICKS, self)
        self._timer.timeout.connect(self._refresh)

    def _build(self, layout: QVBoxLayout) -> None:
        self.region_button = QPushButton("Draw region")
        self.region_button.setCheckable(True)
        self.region_button.setToolTip(
            "Press on a surface at the region's centre and drag its radius"
        )
        self.cloud_box = QCheckBox("Point cloud")
        self.cloud_box.setChecked(True)
        self.truth_box = QCheckBox("Ground truth (simulation)")
        self.truth_box.setToolTip(
            "Where the simulator really has the objects (orange), to check perception"
        )
        bar = QToolBar()  # a narrow dock folds its buttons into the toolbar's menu
        for widget in (self.region_button, self.cloud_box, self.truth_box):
            bar.addWidget(widget)
        layout.addWidget(bar)
        self.view = view = SceneView()
        # A window of its own in the panel (scene3d_view.py says why)
        self.view_box = QWidget.createWindowContainer(view, self)
        self.view_box.setFocusPolicy(Qt.FocusPolicy.ClickFocus)
        view.setBackgroundColor((32, 32, 36))
        # From behind the robot's left, looking at the table (the robot base is at the origin).
        view.setCameraPosition(
            pos=pg_vector(0.35, 0.0, 0.1), distance=2.0, elevation=32, azimuth=200
        )
        view.gizmo_position = lambda: (
            None if self._gizmo is None else np.array(self._gizmo.position)
        )
        view.clicked.connect(self._on_click)
        view.pressed.connect(self._on_press)
        view.dragged.connect(self._on_drag)
        view.released.connect(self._on_release)
        view.gizmo_moved.connect(self._on_gizmo_moved)
        self.region_button.toggled.connect(lambda on: setattr(view, "capture_drags", on))
        layout.addWidget(self.view_box, 1)
        self._static: list[Any] = []

    # ------------------------------------------------------------------ inputs

    def set_cell(self, cell: Cell | None) -> None:
        """Draw another cell (None: only the grid)."""
        if self.view is None:
            return
        view = self.view
        for item in list(view.items):
            view.removeItem(item)
        self._cell = cell
        self.robot = self.ghost = None
        grid = gl.GLGridItem(size=pg_vector(3, 3, 1), color=(255, 255, 255, 40))
        view.addItem(grid)
        interfaces = cell.interfaces() if cell is not None else {}
        self.table_z = 0.0  # picks fall on the table top when they miss the point cloud
        for name, pose, size in (interfaces.get("scene_layout") or {}).get("fixtures", []):
            box = box_item(size, (0.55, 0.45, 0.35, 1.0))
            set_pose(box, pose_to_matrix(pose))
            view.addItem(box)
            if name == "table":
                self.table_z = pose.position[2] + size[2] / 2
                grid.translate(0.0, 0.0, pose.position[2] - size[2] / 2)  # the floor
        self.arm = interfaces.get("arm")
        try:
            base = robot_base_from_arm(self.arm) if self.arm is not None else None
        except RobotBodyError as exc:  # the 3D scene shows the rest, and says why not the arm
            self.message.emit(f"The 3D scene cannot draw the robot: {exc}")
            self.arm, base = None, None
        if base is not None:
            self.robot = RobotItems(view, base)
            self.ghost = RobotItems(view, base, (0.4, 0.7, 1.0, 0.35))
            self.ghost.set_visible(False)
        self.cameras = {
            k.split(":", 1)[1]: v for k, v in interfaces.items() if k.startswith("rgbd:")
        }
        self.frusta = {
            name: gl.GLLinePlotItem(mode="lines", color=(1, 1, 0.3, 0.8)) for name in self.cameras
        }
        self.cloud = gl.GLScatterPlotItem(size=1.5, pxMode=True)
        self.gizmo_items = (
            axes_item(0.12, 3.0),
            gl.GLMeshItem(
                meshdata=gl.MeshData.sphere(rows=8, cols=12, radius=0.018),
                color=(1, 1, 0, 1),
                shader="shaded",
            ),
        )
        self.labels = LabelsItem()  # every label of the scene, laid out so none overlaps
        for item in (*self.frusta.values(), self.cloud, *self.gizmo_items, self.labels):
            view.addItem(item)
        self._dynamic: dict[str, list[Any]] = {
            "objects": [],
            "truth": [],
            "regions": [],
            "waypoints": [],
            "draft": [],
        }
        self._apply_gizmo(self._gizmo)
        self._show_regions()
        self._show_waypoints()
        self._tick, self._shown_keys = 0, {}
        self._timer.polled(True)  # quick again: all is drawn anew
        self._timer.start()

    def set_frame_source(self, source: FrameSource) -> None:
        """Where the point cloud comes from: camera name -> latest feed frame (or None)."""
        self._frames = source

    def set_regions(self, regions: Iterable[tuple[str, Region]]) -> None:
        """The plan's regions (name, sphere), drawn as translucent spheres."""
        self._regions = list(regions)
        if self.view is not None and self._cell is not None:
            self._show_regions()

    def set_waypoints(self, waypoints: Iterable[Waypoint]) -> None:
        """The plan's waypoints, drawn as small named axes where they are now."""
        self._waypoints = list(waypoints)
        if self.view is not None and self._cell is not None:
            self._show_waypoints()

    def stop(self) -> None:
        """Stop refreshing (before the cell closes)."""
        if self.view is not None:
            self._timer.stop()
            self._workers.shutdown(wait=False, cancel_futures=True)
            self._workers = ThreadPoolExecutor(1, "scene3d-truth")

    def draw_view_into(self, picture: QPixmap, top: QWidget) -> None:
        """Draw the 3D view into ``picture``, a ``grab()`` of ``top`` (a widget's grab leaves
        the view out: it is a native window of its own).
        """
        if self.view is None or not self.view_box.isVisible():
            return
        painter = QPainter(picture)
        painter.drawImage(self.view_box.mapTo(top, QPoint(0, 0)), self.view.grabFramebuffer())
        painter.end()

    # ------------------------------------------------------------------ API for teaching

    def show_ghost(self, joints: Sequence[float] | None) -> None:
        """A translucent arm at these joints (rad), e.g. a waypoint's preview; None hides it."""
        ghost = getattr(self, "ghost", None)
        if ghost is None:
            return
        if joints is not None:
            ghost.set_joints(joints)
        ghost.set_visible(joints is not None)

    def set_gizmo(self, pose: Pose | None) -> None:
        """Show the draggable tool gizmo at a TCP pose (None hides it; the same pose again
        changes nothing, so draws nothing).
        """
        if pose != getattr(self, "_gizmo", None):  # (no attribute: no OpenGL, no view)
            self._apply_gizmo(pose)

    def set_hand_guiding(self, on: bool) -> None:
        """While on (Freedrive on), a plain left drag on the gizmo moves it, as Shift + drag
        does at any time; a drag elsewhere still orbits the view.
        """
        if self.view is not None:
            self.view.hand_guiding = on

    def _apply_gizmo(self, pose: Pose | None) -> None:
        self._gizmo = pose
        items = getattr(self, "gizmo_items", ())
        for item in items:
            item.setVisible(pose is not None)
            if pose is not None:
                set_pose(item, pose_to_matrix(pose))

    def _on_gizmo_moved(self, position: Any, done: Any) -> None:
        if self._gizmo is None:
            return
        x, y, z = (float(v) for v in position)
        pose = Pose((x, y, z), self._gizmo.orientation)
        self.set_gizmo(pose)
        (self.gizmo_released if done else self.gizmo_dragged).emit(pose)

    # ------------------------------------------------------------------ refresh

    @property
    def frames_drawn(self) -> int:
        return self.view.frames_drawn if self.view is not None else 0

    @property
    def refresh_interval_ms(self) -> int:
        """How often the panel looks for changes now (slower once nothing changes)."""
        return self._timer.interval() if self.view is not None else 0

    def _refresh(self) -> None:
        if self.view is None or not self.isVisible():
            return
        self._tick += 1
        slow = self._timer.interval() > REFRESH_MS
        changed = False
        if self.robot is not None and self.arm is not None:
            q = tuple(self.arm.joint_positions())
            shown = self.robot.joints
            if shown is None or len(q) != len(shown) or _moved(q, shown, JOINT_TOLERANCE):
                self.robot.set_joints(q)
                changed = True
        for name, camera in self.cameras.items():
            if getattr(camera, "on_wrist", False) or self._tick == 1:
                changed |= self._show_frustum(name, camera)
        if slow or self._tick % 10 == 1:
            changed |= self._show_objects()
            changed |= self._show_truth()
        if slow or self._tick % 15 == 1:
            changed |= self._show_cloud()
        if changed:
            self.view.update()
        self._timer.polled(changed)

    def _changed(self, part: str, key: Any) -> bool:
        """True (and remembers ``key``) when ``part`` was last drawn from something else."""
        if part in self._shown_keys and _same(self._shown_keys[part], key):
            return False
        self._shown_keys[part] = key
        return True

    def _show_frustum(self, name: str, camera: Any) -> bool:
        latest = self._frames(name)
        K = camera.intrinsics
        size = (
            latest.frame.depth.shape[::-1]
            if latest is not None
            else (int(2 * K[0, 2]), int(2 * K[1, 2] + 2))
        )
        extrinsics = camera.extrinsics()
        matrix = np.round(pose_to_matrix(extrinsics) / JOINT_TOLERANCE)
        if not self._changed(f"frustum:{name}", (tuple(size), matrix)):
            return False
        self.frusta[name].setData(pos=frustum_lines(K, size, extrinsics))
        return True

    def _show_cloud(self) -> bool:
        latest = self._frames("shoulder")
        if not self.cloud_box.isChecked() or latest is None:
            if not self._changed("cloud", None):
                return False
            self.cloud.setVisible(False)
            return True
        if not self._changed("cloud", latest.seq):
            return False
        frame = latest.frame
        stride = max(1, frame.depth.shape[1] // 120)
        # The floor around the table says nothing about the task: only what is on the table.
        keep = frame.point_cloud(stride)[:, 2] > self.table_z - 0.02
        points = frame.point_cloud(stride)[keep]
        colours = frame.point_colors(stride)[keep].astype(np.float32) / 255.0
        self.cloud.setData(
            pos=points, color=np.column_stack((colours, np.full(len(colours), 0.8, np.float32)))
        )
        self.cloud.setVisible(True)
        self._cloud_points = points
        return True

    def _replace(self, group: str, items: list[Any]) -> None:
        assert self.view is not None
        for item in self._dynamic[group]:
            self.view.removeItem(item)
        for item in items:
            self.view.addItem(item)
        self._dynamic[group] = items

    def label_rects(self) -> list[tuple[str, tuple[float, float, float, float]]]:
        """Each label shown and its screen rectangle (x, y, w, h) for the camera now."""
        labels = getattr(self, "labels", None)  # (no attribute: no OpenGL, no view)
        return [(label.text, rect) for label, rect in labels.layout()] if labels else []

    def _object_items(
        self, name: str, pose: Pose, colour: tuple[float, ...], label: str
    ) -> tuple[Any, Label]:
        library = (self._cell.interfaces() if self._cell else {}).get("objects")
        try:
            if library is None:
                raise LookupError("no object library")
            data = mesh_data(str(library.get(name).mesh_file))
        except Exception:  # no library or an unknown class: a ball marks where it was seen
            data = gl.MeshData.sphere(rows=6, cols=8, radius=0.03)
        mesh = gl.GLMeshItem(
            meshdata=data,
            color=colour,
            shader="shaded",
            glOptions="translucent" if colour[3] < 1 else "opaque",
        )
        set_pose(mesh, pose_to_matrix(pose))
        x, y, z = pose.position
        return mesh, Label((x, y, z + 0.12), label)

    def _show_objects(self) -> bool:
        world = (self._cell.interfaces() if self._cell else {}).get("world")
        detections = tuple(world.detections()) if world is not None else ()
        if not self._changed("objects", detections):
            return False
        shown = [
            self._object_items(
                d.object_class, d.pose, DETECTED_RGBA, f"{d.object_class} {d.confidence:.0%}"
            )
            for d in detections
        ]
        self._replace("objects", [mesh for mesh, _ in shown])
        self.labels.set_group("objects", [label for _, label in shown])
        return True

    def _show_truth(self) -> bool:
        """Ground truth (simulation only): fetched on a worker, shown when it arrives."""
        changed = False
        job, self._truth_job = self._truth_job, None
        if (
            job is not None
            and job.done()
            and job.exception() is None
            and self.truth_box.isChecked()
        ):
            truth = job.result()
            if self._changed("truth", tuple(truth)):
                shown = [self._object_items(n, p, TRUTH_RGBA, f"{n} (truth)") for n, p in truth]
                self._replace("truth", [mesh for mesh, _ in shown])
                self.labels.set_group("truth", [label for _, label in shown])
                changed = True
        elif not self.truth_box.isChecked() and self._changed("truth", None):
            self._replace("truth", [])
            self.labels.set_group("truth", [])
            changed = True
        cell = self._cell
        if self.truth_box.isChecked() and isinstance(cell, ShowsGroundTruth):
            names = list(cell.scene.objects)
            self._truth_job = self._workers.submit(lambda: [(n, cell.truth_pose(n)) for n in names])
        return changed

    def _show_regions(self) -> None:
        items: list[Any] = []
        labels: list[Label] = []
        for name, region in self._regions:
            sphere = sphere_item(region.radius, REGION_RGBA)
            sphere.translate(*region.center)
            items.append(sphere)
            x, y, z = region.center
            labels.append(Label((x, y, z + region.radius + 0.02), name, (255, 120, 220, 255)))
        self._replace("regions", items)
        self.labels.set_group("regions", labels)

    def _waypoint_pose(self, waypoint: Waypoint) -> Pose | None:
        """Where a waypoint is now, resolved as motion.move_to resolves it (a relative one
        against the object or marker last seen); None when that cannot be told.
        """
        if waypoint.frame is WaypointFrame.JOINTS:
            fk = getattr(self.arm, "forward_kinematics", None)
            return fk(waypoint.joints.positions) if fk and waypoint.joints else None
        world = (self._cell.interfaces() if self._cell else {}).get("world")
        try:
            resolved = TargetResolver(world, SymmetryTable()).resolve(waypoint, None, Pose())
        except OperationFailed:
            return None
        return resolved.poses[0] if resolved.poses else None

    def _show_waypoints(self) -> None:
        items: list[Any] = []
        labels: list[Label] = []
        for waypoint in self._waypoints:
            pose = self._waypoint_pose(waypoint)
            if pose is None:
                continue
            axes = axes_item()
            set_pose(axes, pose_to_matrix(pose))
            items.append(axes)
            x, y, z = pose.position
            labels.append(Label((x, y, z + 0.03), waypoint.name, (200, 230, 255, 255)))
        self._replace("waypoints", items)
        self.labels.set_group("waypoints", labels)


def _moved(a: Sequence[float], b: Sequence[float], tolerance: float) -> bool:
    return any(abs(x - y) > tolerance for x, y in zip(a, b, strict=True))


def _same(a: Any, b: Any) -> bool:
    """Equality that also compares numpy arrays (inside tuples) element by element."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return (
            isinstance(a, np.ndarray)
            and isinstance(b, np.ndarray)
            and a.shape == b.shape
            and bool(np.array_equal(a, b))
        )
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)


def pg_vector(x: float, y: float, z: float) -> Any:
    from pyqtgraph import Vector

    return Vector(x, y, z)
