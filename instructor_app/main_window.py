"""MainWindow: wires the document, the canvas, the panels and the run together.

It implements none of their logic: the canvas edits and shows the plan, the panels their
part, the RunController runs it, CellControl switches and resets the cell, PlanFiles does
new, open, save and recovery, and window_layout places the docks. What is here: menus, the
toolbar, and the signal wiring, which lives in :meth:`_wire_views` and :meth:`_wire_run` so
that an API change of a panel is adjusted in one place.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from PySide6.QtGui import QAction, QCloseEvent, QKeySequence, QUndoGroup
from PySide6.QtWidgets import (
    QLabel,
    QMainWindow,
    QStackedWidget,
    QWidget,
)

from engine.executor import ExecutorState
from engine.library import library_folder
from engine.spec import NodeKind
from instructor_app.canvas.actions import MenuEntry
from instructor_app.cell_control import CellControl
from instructor_app.dialogs import APP_TITLE, DISCARD, Dialogs
from instructor_app.document.autosave import DEFAULT_INTERVAL_MS, Autosaver
from instructor_app.document.editing import PlanDocument
from instructor_app.document.model import DocumentError
from instructor_app.document.tree_ops import can_have_child
from instructor_app.inspectors.offers import nodes_before_insert, prebound
from instructor_app.library_wiring import LibraryController
from instructor_app.node_factory import make_node, manifest_or_none
from instructor_app.panels.cell_views import CellViews
from instructor_app.panels.operator import OperatorPanel
from instructor_app.panels.scene_teach import SceneTeachLink
from instructor_app.panels.start_page import StartPage, find_examples
from instructor_app.plan_files import PlanFiles
from instructor_app.runtime.blackboard_edits import BlackboardEdits
from instructor_app.runtime.controller import RunController
from instructor_app.runtime.debug_view import DebugActions
from instructor_app.runtime.robot_status import CellClearButton, RobotStatusLabel
from instructor_app.runtime.run_view import (
    FailureButton,
    RunActions,
    RunningNodesPanel,
    RunPresenter,
)
from instructor_app.runtime.session import CellSession
from instructor_app.settings import (
    EXAMPLES_DIR,
    AppSettings,
    RecentFilesMenu,
    app_version,
)
from instructor_app.timeline_wiring import TimelineController
from instructor_app.views import Views, make_views
from instructor_app.window_layout import arrange_cell_views, place_docks
from instructor_app.xml_files import export_plan_xml, import_plan_xml

__all__ = ["APP_TITLE", "DISCARD", "Dialogs", "MainWindow", "Views", "make_views"]


class MainWindow(QMainWindow):
    """The Instructor's window.

    Args:
        session: the cell in use and its registry (opened by the caller).
        settings: recent files and window layout (default: the user's settings).
        dialogs: questions and messages (tests pass scripted ones).
        recovery_folder: where autosave writes (default: AppDataLocation/recovery).
        autosave_interval_ms: how often a dirty plan is autosaved.
        rate_hz: the executor's tick rate.
    """

    def __init__(
        self,
        session: CellSession,
        settings: AppSettings | None = None,
        dialogs: Dialogs | None = None,
        recovery_folder: Path | None = None,
        autosave_interval_ms: int = DEFAULT_INTERVAL_MS,
        rate_hz: float = 20.0,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self.setObjectName("MainWindow")
        self.session = session
        self.settings = settings if settings is not None else AppSettings()
        self._dialogs = dialogs if dialogs is not None else Dialogs()
        self.document = PlanDocument(self)
        self.autosaver = Autosaver(self.document, recovery_folder, autosave_interval_ms, self)
        self.controller = RunController(self.document, session, rate_hz=rate_hz, parent=self)
        self.controller.runs_setting = self.settings.runs_folder()  # Run > Runs Folder…
        self.views: Views = make_views(self.document, session, self, self.autosaver.folder.parent)
        self.run_actions = RunActions(self.controller, self)
        self.debug_actions = DebugActions(
            self.controller,
            self.views.canvas,
            self.show_message,
            self,
            self.settings,
            lambda title, label, text: self._dialogs.ask_text(self, title, label, text),
        )
        self.running_panel = RunningNodesPanel(self._node_path, self)
        self.operator_panel = OperatorPanel(self)
        self.failure_button = FailureButton(self)
        self.selection: list[str] = []
        self.cell_views = CellViews(self.document, session, self._selected_node, parent=self)
        self.library = LibraryController(
            self.document,
            self.views,
            lambda: self.session.registry,
            self._insertion_point,
            library_folder(setting=self.settings.library_folder()),
            self,
        )
        self.library.message.connect(self.show_message)
        self.cells = CellControl(
            session,
            self.controller,
            self.document,
            self.views,
            self.run_actions,
            self.dialogs,
            self.show_message,
            self,
        )
        self.cell_combo = self.cells.combo
        self.files = PlanFiles(
            self.document,
            self.autosaver,
            self.dialogs,
            self.settings,
            self.show_message,
            self.show_canvas,
            self,
        )
        self._build_layout()
        self.timeline = TimelineController(
            self.views.timeline,
            self.document,
            self.views,
            self.cell_views.scene3d,
            self,
            lambda: self.controller.last_record,
            self,
            self.controller.runs_folder,
        )
        self.actions_by_name: dict[str, QAction] = {}
        self._build_menus()
        self._wire_views()
        self._wire_run()
        self._restore_window()
        self.files.update_title()

    # ------------------------------------------------------------------ layout

    def _build_layout(self) -> None:
        # The start page until there is a plan to show (new, open, a first node, recovery).
        self.start_page = StartPage(find_examples(EXAMPLES_DIR), self.settings.recent_files)
        self.start_page.new_requested.connect(self.new_plan)
        self.start_page.open_requested.connect(lambda path: self.open_plan(path or None))
        self.central = QStackedWidget(self)
        self.central.addWidget(self.start_page)
        self.central.addWidget(self.views.canvas)
        self.setCentralWidget(self.central)
        self.docks = place_docks(
            self, self.views, self.cell_views, self.operator_panel, self.running_panel
        )
        self.robot_status = RobotStatusLabel(self.session, parent=self)
        self.problems_label = QLabel("")
        # permanent: a temporary status message would hide a normal status-bar widget
        self.robot_clear = CellClearButton(self.session, self.robot_status, self)
        self.statusBar().addPermanentWidget(self.robot_clear)
        self.statusBar().addPermanentWidget(self.robot_status)
        self.robot_status.setVisible(self.robot_status.present)
        self.robot_status.presence_changed.connect(self.robot_status.setVisible)
        self.statusBar().addPermanentWidget(self.failure_button)
        self.statusBar().addPermanentWidget(self.problems_label)

    def arrange_cell_views(self) -> None:
        """Place the cameras and the 3D scene for the window's width (see
        window_layout.arrange_cell_views). Called when no saved layout is restored, and
        after a resize for a picture.
        """
        arrange_cell_views(self, self.docks)

    def _action(self, name: str, text: str, slot: Any, shortcut: str = "") -> QAction:
        action = QAction(text, self)
        action.setObjectName(name)
        if shortcut:
            action.setShortcut(QKeySequence(shortcut))
        action.triggered.connect(slot)
        self.actions_by_name[name] = action
        return action

    def _build_menus(self) -> None:
        bar = self.menuBar()
        files = bar.addMenu("&File")
        files.addAction(self._action("new", "&New", self.new_plan, "Ctrl+N"))
        files.addAction(self._action("open", "&Open…", lambda: self.open_plan(), "Ctrl+O"))
        files.addAction(self._action("start_page", "Start &Page", self.show_start_page))
        self.recent_menu = RecentFilesMenu(self.settings, self.open_plan, self)
        files.addMenu(self.recent_menu)
        files.addSeparator()
        files.addAction(self._action("save", "&Save", self.files.save_plan, "Ctrl+S"))
        files.addAction(
            self._action("save_as", "Save &As…", self.files.save_plan_as, "Ctrl+Shift+S")
        )
        files.addSeparator()
        files.addAction(
            self._action(
                "export_xml",
                "&Export BehaviorTree.CPP XML…",
                lambda: export_plan_xml(self),
            )
        )
        files.addAction(
            self._action(
                "import_xml",
                "&Import BehaviorTree.CPP XML…",
                lambda: import_plan_xml(self),
            )
        )
        files.addSeparator()
        files.addAction(
            self._action("open_record", "Open &Run Record…", lambda: self.timeline.open_record())
        )
        files.addSeparator()
        files.addAction(self._action("quit", "&Quit", self.close, "Ctrl+Q"))
        self._build_edit_menus()
        reset = self.actions_by_name["reset_cell"] = self.cells.reset_action
        run_menu = bar.addMenu("&Run")
        run_menu.addActions(self.run_actions.all())
        run_menu.addSeparator()
        run_menu.addAction(reset)
        run_menu.addSeparator()
        groot2 = self._action("groot2", "Publish Runs for &Groot2", self._set_groot2)
        groot2.setCheckable(True)
        groot2.setChecked(self.settings.groot2_publish())
        groot2.setToolTip("Serve each run to Groot2's monitor, as BehaviorTree.CPP does")
        run_menu.addAction(groot2)
        run_menu.addAction(self._action("groot2_port", "Groot2 &Port…", self._ask_groot2_port))
        run_menu.addAction(self._action("runs_folder", "Runs &Folder…", self._ask_runs_folder))
        self._apply_groot2()
        self.debug_actions.fill_menu(bar.addMenu("&Debug"))
        self.library.fill_menu(bar.addMenu("&Library"))
        help_menu = bar.addMenu("&Help")
        help_menu.addAction(self._action("about", f"&About {APP_TITLE}", self._about))
        toolbar = self.addToolBar("Run")
        toolbar.setObjectName("run_toolbar")
        toolbar.addActions(self.run_actions.all())
        toolbar.addSeparator()
        toolbar.addAction(reset)
        toolbar.addWidget(self.cells.label)
        toolbar.addWidget(self.cells.combo)

    def _apply_groot2(self) -> None:
        publish = self.settings.groot2_publish()
        self.controller.set_groot2_port(self.settings.groot2_port() if publish else None)

    def _set_groot2(self, publish: bool) -> None:
        """Run > Publish Runs for Groot2: from the next run on (off: at once)."""
        self.settings.set_groot2_publish(publish)
        self._apply_groot2()
        port = self.settings.groot2_port()
        self.show_message(
            f"Runs are published for Groot2 on 127.0.0.1:{port} from the next run"
            if publish
            else "Runs are no longer published for Groot2"
        )

    def _ask_groot2_port(self) -> None:
        port = self.dialogs.ask_groot2_port(self, self.settings.groot2_port())
        if port is not None:
            self.settings.set_groot2_port(port)
            self._apply_groot2()

    def _ask_runs_folder(self) -> None:
        """Run > Runs Folder…: where the next runs' records go (and Last run looks)."""
        folder = self.dialogs.ask_runs_folder(self, str(self.controller.runs_folder()))
        if folder is None:
            return
        self.settings.set_runs_folder(folder)
        self.controller.runs_setting = folder
        now = self.controller.runs_folder()
        self.show_message(
            f"Run records go to {now}"
            + (" ($COSTAR_RUNS overrides the setting)" if folder and now != Path(folder) else "")
        )

    def _build_edit_menus(self) -> None:
        edit = self.menuBar().addMenu("&Edit")
        # The plan's edits; while a run is paused, its named parameters' (BlackboardEdits).
        self.undo_group = QUndoGroup(self)
        self.undo_group.addStack(self.document.undo_stack)
        self.undo_group.setActiveStack(self.document.undo_stack)
        undo, redo = (
            self.undo_group.createUndoAction(self, "&Undo"),
            self.undo_group.createRedoAction(self, "&Redo"),
        )
        undo.setShortcuts(QKeySequence.keyBindings(QKeySequence.StandardKey.Undo))
        redo.setShortcuts([QKeySequence("Ctrl+Shift+Z"), QKeySequence("Ctrl+Y")])
        self.actions_by_name.update(undo=undo, redo=redo)
        edit.addActions([undo, redo])
        edit.addSeparator()
        for name in ("cut", "copy", "paste", "duplicate", "delete"):
            self._add_canvas_action(edit, name)
        view = self.menuBar().addMenu("&View")
        for dock in self.docks.values():
            view.addAction(dock.toggleViewAction())
        view.addSeparator()
        for name in ("auto_layout", "toggle_collapse", "move_left", "move_right"):
            self._add_canvas_action(view, name)
        view.addAction(self._action("fit", "&Fit to Window", self.views.canvas.fit_all, "Ctrl+0"))

    def _add_canvas_action(self, menu: Any, name: str) -> None:
        action = self.views.canvas_actions[name]
        self.actions_by_name[name] = action
        menu.addAction(action)

    # ------------------------------------------------------------------ wiring

    def _wire_views(self) -> None:
        views, document = self.views, self.document
        views.canvas.selection_changed.connect(self._on_selection)
        views.canvas.message.connect(self.show_message)
        views.waypoints.message.connect(self.show_message)
        views.teacher.message.connect(self.show_message)
        views.objects.message.connect(self.show_message)
        self.cell_views.message.connect(self.show_message)
        # Drag the tool gizmo in the 3D scene, preview waypoints as a ghost arm there.
        self.scene_link = SceneTeachLink(
            self.cell_views.scene3d, views.teacher, views.waypoints, self
        )
        self.session.cell_changed.connect(lambda _name: self._attach_operator())
        self.operator_panel.prompt_shown.connect(lambda _text: self.raise_dock("operator"))
        self._attach_operator()
        views.palette.item_activated.connect(self.add_palette_item)
        views.validation.node_selected.connect(self.select_node)
        views.validation.summary_changed.connect(self._on_summary)
        views.validation.summary_changed.connect(
            lambda *_: views.inspector.set_problems(views.validation.problems())
        )
        self.running_panel.node_selected.connect(self.select_node)
        self.failure_button.node_selected.connect(self.select_node)
        self.cells.wire()
        document.dirty_changed.connect(lambda _: self.files.update_title())
        document.path_changed.connect(lambda _: self.files.update_title())
        document.plan_reset.connect(self._on_plan_reset)
        document.plan_changed.connect(self._leave_start_page_when_a_plan_shows)
        views.validation.revalidate()  # its first summary came before these connections

    def _wire_run(self) -> None:
        controller, views = self.controller, self.views
        controller.statuses_changed.connect(views.canvas.set_statuses)
        controller.nodes_halted.connect(views.canvas.set_halted)
        controller.failures_described.connect(views.canvas.set_failure_tips)
        views.canvas.commands.run_entries = self._run_entries
        controller.inner_statuses_changed.connect(views.inside.set_statuses)
        self.blackboard_edits = BlackboardEdits(
            controller, views.blackboard, self.undo_group, self.document.undo_stack, self
        )
        controller.log_message.connect(views.log.append)
        controller.running_nodes_changed.connect(self.running_panel.set_nodes)
        controller.hold_changed.connect(self.running_panel.set_held)
        controller.failure_changed.connect(self.failure_button.show_failure)
        controller.run_state_changed.connect(self.cells.follow_run_state)
        controller.run_starting.connect(views.teacher.leave_freedrive)
        controller.run_starting.connect(lambda: views.timeline.set_timeline(None))  # live again
        controller.run_state_changed.connect(
            lambda state: views.teacher.set_run_active(
                state not in (ExecutorState.READY, ExecutorState.FINISHED)
            )
        )
        self.run_presenter = RunPresenter(
            controller,
            views.canvas,
            views.blackboard,
            views.log,
            self.show_message,
            self,
        )
        self.run_presenter.problems_shown.connect(lambda: self.docks["validation"].raise_())
        self.timeline.message.connect(self.show_message)

    # ------------------------------------------------------------------ editing

    def _attach_operator(self) -> None:
        """The operator panel answers the prompts of the cell in use (its "operator")."""
        cell = self.session.cell
        self.operator_panel.set_console(cell.interfaces().get("operator") if cell else None)

    def _selected_node(self) -> str | None:
        return self.selection[0] if len(self.selection) == 1 else None

    def raise_dock(self, name: str) -> None:
        self.docks[name].show()
        self.docks[name].raise_()

    def show_message(self, text: str, timeout_ms: int = 8000) -> None:
        self.statusBar().showMessage(text, timeout_ms)

    def select_node(self, node_id: str) -> None:
        """Select a node on the canvas and bring it into view."""
        if node_id and self.document.plan.find(node_id) is not None:
            self.views.canvas.select(node_id)
            self.views.canvas.center_on(node_id)

    def add_palette_item(self, item: Any) -> str | None:
        """Add the palette item's node where the selection says; returns the new node's id,
        or None with a status-bar message.

        With a node selected that can take a child, the new node becomes its last child;
        with a leaf (or a full decorator) selected, it goes right after it, as a sibling.
        Nothing selected: under the root (as the root when the plan is empty). The new
        node is selected, so that consecutive inserts with a leaf line up one after the
        other, and the view scrolls to it. A required input of the new node is bound to the
        output of its type that a node before it writes, when exactly one does (one step).
        """
        if not item.available:
            self.show_message(f"{item.label} cannot be used on this cell: {item.reason}")
            return None
        if item.kind is NodeKind.SUBTREE:  # a library subtree: an instance, its subtree embedded
            return self.library.insert(item.op)
        registry = self.session.registry
        manifest = manifest_or_none(registry, item.op)
        node = make_node(item, manifest)
        try:
            parent_id, index = self._insertion_point()
            # a required input takes the one output of its type written before it, if one
            before = nodes_before_insert(self.document.plan, parent_id, index)
            node = prebound(node, manifest, self.document.plan, registry, before)
            new_id = self.document.add_node(node, parent_id, index)
        except DocumentError as exc:
            self.show_message(f"Cannot add {node.label} here: {exc}")
            return None
        canvas = self.views.canvas
        canvas.select(new_id)
        canvas.ensure_visible(new_id)
        return new_id

    def _insertion_point(self) -> tuple[str | None, int | None]:
        """(parent id, index) for a new node from the selection (see add_palette_item)."""
        plan = self.document.plan
        if plan.tree is None:
            return None, None
        selected = self.selection[0] if self.selection else plan.tree.id
        if can_have_child(self.document.node(selected)):
            return selected, None
        parent_id, index, _ = self.document.locate(selected)
        if parent_id is None:
            raise DocumentError(f"{self._node_label(selected)!r} is the root and takes no child")
        if not can_have_child(self.document.node(parent_id)):
            raise DocumentError(f"{self._node_label(parent_id)!r} cannot take another child")
        return parent_id, index + 1

    def _on_selection(self, node_ids: list[str]) -> None:
        self.selection = list(node_ids)
        self.views.inspector.show_node(node_ids[0] if len(node_ids) == 1 else None)

    def _on_summary(self, errors: int, warnings: int) -> None:
        parts = [f"{errors} error{'s' * (errors != 1)}"] if errors else []
        parts += [f"{warnings} warning{'s' * (warnings != 1)}"] if warnings else []
        if not parts and self.document.plan.tree is None:
            self.problems_label.setText("Empty plan: add a node from the palette")
            return
        self.problems_label.setText(", ".join(parts) or "No problems")

    # ------------------------------------------------------------------ start page

    @property
    def start_page_shown(self) -> bool:
        return self.central.currentWidget() is self.start_page

    def show_start_page(self) -> None:
        self.start_page.refresh()
        self.central.setCurrentWidget(self.start_page)

    def show_canvas(self) -> None:
        if not self.start_page_shown:
            return
        self.central.setCurrentWidget(self.views.canvas)
        self.views.canvas.fit_all()

    def _leave_start_page_when_a_plan_shows(self) -> None:
        if self.document.plan.tree is not None or self.document.path is not None:
            self.show_canvas()

    def _on_plan_reset(self) -> None:
        self._leave_start_page_when_a_plan_shows()
        self.selection = []
        self.views.inspector.show_node(None)
        self.views.canvas.clear_statuses()
        self.failure_button.show_failure("", "")

    def _node_label(self, node_id: str) -> str:
        node = self.document.plan.find(node_id)
        return node.label if node is not None else node_id

    def _node_path(self, node_id: str) -> str:
        return self.document.plan.path_of(node_id)

    # ------------------------------------------------------------------ cell and files
    # The window's public commands; CellControl and PlanFiles implement them.

    @property
    def dialogs(self) -> Dialogs:
        return self._dialogs

    @dialogs.setter
    def dialogs(self, dialogs: Dialogs) -> None:
        """Replace the dialogs (a test does), also in CellControl and PlanFiles."""
        self._dialogs = self.cells.dialogs = self.files.dialogs = dialogs

    def switch_cell(self, name: str) -> None:
        self.cells.switch_cell(name)

    def reset_cell(self) -> None:
        self.cells.reset_cell()

    def maybe_save(self) -> bool:
        return self.files.maybe_save()

    def new_plan(self) -> None:
        self.files.new_plan()

    def open_plan(self, path: str | Path | None = None) -> bool:
        if not self.files.open_plan(path):
            return False
        self.cells.use_plan_scene()
        return True

    def offer_recoveries(self) -> bool:
        if not self.files.offer_recoveries():
            return False
        self.cells.use_plan_scene()
        return True

    def _run_entries(self, node_id: str) -> list[MenuEntry]:
        """The run commands of a node's context menu: resume from it after a run ended;
        its breakpoint, skip and forced result.
        """
        entries = self.debug_actions.node_entries(node_id)
        if self.controller.state != ExecutorState.FINISHED:
            return entries

        def resume() -> None:
            self.controller.resume_from(node_id)  # a refused plan shows its problems

        return [("Resume from this node", resume), *entries]

    def _about(self) -> None:
        self.dialogs.about(
            self,
            f"<b>{APP_TITLE}</b> {app_version()}<p>Teach a robot a task by composing a behavior tree "
            "(after CoSTAR, Guerin et al., ICRA 2015).</p>",
        )

    # ------------------------------------------------------------------ window

    def _restore_window(self) -> None:
        geometry, state = self.settings.window_geometry(), self.settings.window_state()
        if geometry is not None:
            self.restoreGeometry(geometry)
        else:
            self.resize(1400, 900)
        if state is not None:
            self.restoreState(state)
        else:
            self.arrange_cell_views()

    def shutdown(self, keep_recovery: bool = False) -> None:
        """Stop the run, the robot's teaching commands, background drawing and autosave;
        with ``keep_recovery`` unsaved work stays in its recovery file (a signal ends the
        program: nobody was asked to save).
        """
        self.controller.shutdown()
        self.cell_views.stop()
        self.views.teacher.shutdown()
        self.views.objects.shutdown()
        self.library.shutdown()
        if keep_recovery and self.document.dirty:
            self.autosaver.write_now()
        else:
            self.autosaver.stop()

    def closeEvent(self, event: QCloseEvent) -> None:
        if not self.maybe_save():
            event.ignore()
            return
        self.shutdown()
        self.settings.save_window(self.saveGeometry(), self.saveState())
        event.accept()
