"""The inspector: the parameter area of the paper's Figure 5 (3) for the selected node.

It shows the node's name (editable), what it is and its doc, then the settings of a logic
node kind (engine.kinds.KIND_PORTS) or of an operation (from its manifest), one row type.
Below them, the Advanced section holds the node's pre- and post-conditions (BehaviorTree.CPP's
``_skipIf`` ...: engine.conditions), one script field each; it opens by itself for a node
that has any. Every finished edit is exactly one document command; edits that change nothing push none.
The panel follows the document: a change of the shown node refreshes the rows in place.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from PySide6.QtCore import QStringListModel, Qt
from PySide6.QtWidgets import (
    QFormLayout,
    QLabel,
    QLineEdit,
    QScrollArea,
    QSizePolicy,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from engine.conditions import Condition
from engine.instances import instance_manifest
from engine.kinds import KIND_DOC, KIND_PORTS
from engine.operations import Direction, OperationSource, PortSpec
from engine.spec import Binding, NodeKind, NodeSpec
from engine.types import Waypoint
from engine.units import display_unit
from engine.validation import ERROR, Problem
from instructor_app.dialogs import Dialogs
from instructor_app.document import DocumentError, PlanDocument
from instructor_app.inspectors.base import EditorContext
from instructor_app.inspectors.factory import type_names
from instructor_app.inspectors.offers import nodes_before, offered_outputs
from instructor_app.inspectors.rows import MODE_REFERENCE, PortRow
from instructor_app.inspectors.teach_buttons import (
    TeachButtons,
    change_text,
    is_teachable,
    move_target,
    other_users,
    taught_value,
)
from instructor_app.node_factory import manifest_or_none, readable
from instructor_app.runtime.waypoint_teach import TeachError

__all__ = ["InspectorPanel", "CONDITION_TIPS"]

# What each condition does, for its field's tooltip (BehaviorTree.CPP's attribute first).
CONDITION_TIPS: dict[Condition, str] = {
    Condition.FAILURE_IF: "checked when the node is about to start: true makes it fail "
    "without running",
    Condition.SUCCESS_IF: "checked when the node is about to start: true makes it succeed "
    "without running",
    Condition.SKIP_IF: "checked when the node is about to start: true skips it (SKIPPED), "
    "its parent goes on",
    Condition.WHILE: "false when the node is about to start skips it; false while it runs "
    "halts it and skips it",
    Condition.ON_SUCCESS: "runs after the node succeeded",
    Condition.ON_FAILURE: "runs after the node failed",
    Condition.POST: "runs after the node succeeded or failed (not when halted)",
    Condition.ON_HALTED: "runs when the node is halted while it runs",
}


class InspectorPanel(QWidget):
    """Edits the parameters of one node of a document.

    Args:
        document: the plan being edited.
        registry: the cell's operations (manifests for the port rows).
    """

    def __init__(
        self, document: PlanDocument, registry: OperationSource, parent: QWidget | None = None
    ) -> None:
        super().__init__(parent)
        self.document = document
        self._registry = registry
        self._node_id: str | None = None
        self._shown_op: str | None = None
        self._object_names: list[str] = []
        self._names = QStringListModel(self)
        self._port_rows: dict[str, PortRow] = {}
        self._last_context = EditorContext()
        self._problems: list[Problem] = []
        self._field_labels: dict[str, QLabel] = {}
        self._teacher: Any = None  # RobotTeacher: Teach and Move here under Pose/Waypoint ports
        self.teach_buttons: dict[str, TeachButtons] = {}
        # Questions (None: the window's, or plain message boxes); a test sets scripted ones.
        self.dialogs: Dialogs | None = None
        self._build()
        document.node_changed.connect(self._node_changed)
        document.node_removed.connect(self._node_removed)
        document.plan_reset.connect(self._plan_reset)
        document.plan_changed.connect(self._plan_changed)
        self.show_node(None)

    def _build(self) -> None:
        self.name_field = QLineEdit()
        self.name_field.setPlaceholderText("name")
        self.name_field.editingFinished.connect(self._rename)
        self.kind_label = QLabel()
        self.doc_label = QLabel()
        self.doc_label.setWordWrap(True)
        self.doc_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self._form_holder = QWidget()
        holder_layout = QVBoxLayout(self._form_holder)
        holder_layout.setContentsMargins(0, 0, 0, 0)
        form_widget = QWidget()
        self.form = QFormLayout(form_widget)
        # Labels above their fields when the dock is narrow, never cut off; rows keep their
        # natural height and the space left stays below them.
        self.form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)
        self.form.setFieldGrowthPolicy(QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
        self.form.setContentsMargins(2, 2, 2, 2)  # the fields, not margins, get the width
        holder_layout.addWidget(form_widget)
        self._build_advanced(holder_layout)
        holder_layout.addStretch(1)
        # The parameter area takes every pixel the panel has below the name and the doc line.
        self.parameter_area = QScrollArea()
        self.parameter_area.setWidgetResizable(True)
        self.parameter_area.setWidget(self._form_holder)
        self.parameter_area.setSizePolicy(
            QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding
        )
        layout = QVBoxLayout(self)
        layout.setContentsMargins(4, 4, 4, 4)
        for widget in (self.name_field, self.kind_label, self.doc_label):
            layout.addWidget(widget, 0)
        layout.addWidget(self.parameter_area, 1)

    def _build_advanced(self, holder: QVBoxLayout) -> None:
        """The Advanced section: a toggle, then one script field per condition."""
        self.advanced_toggle = QToolButton()
        self.advanced_toggle.setText("Advanced: pre- and post-conditions")
        self.advanced_toggle.setCheckable(True)
        self.advanced_toggle.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextBesideIcon)
        self.advanced_toggle.setArrowType(Qt.ArrowType.RightArrow)
        self.advanced_toggle.toggled.connect(self._show_advanced)
        self.advanced = QWidget()
        form = QFormLayout(self.advanced)
        form.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)
        form.setFieldGrowthPolicy(QFormLayout.FieldGrowthPolicy.AllNonFixedFieldsGrow)
        form.setContentsMargins(2, 2, 2, 2)
        self.condition_fields: dict[Condition, QLineEdit] = {}
        self._condition_labels: dict[str, QLabel] = {}
        for condition in Condition:
            field = QLineEdit()
            field.setPlaceholderText("a script, e.g. count >= 3")
            field.setObjectName(f"condition_{condition.value}")
            field.editingFinished.connect(lambda c=condition: self._set_condition(c))
            tip = f"{condition.attribute}: {CONDITION_TIPS[condition]}"
            label = QLabel(condition.value.replace("_", " "))
            label.setToolTip(tip)
            label.setProperty("tip", tip)
            field.setToolTip(tip)
            self.condition_fields[condition] = field
            self._condition_labels[condition.value] = label
            form.addRow(label, field)
        self.advanced.setVisible(False)
        holder.addWidget(self.advanced_toggle)
        holder.addWidget(self.advanced)

    def _show_advanced(self, shown: bool) -> None:
        self.advanced.setVisible(shown)
        arrow = Qt.ArrowType.DownArrow if shown else Qt.ArrowType.RightArrow
        self.advanced_toggle.setArrowType(arrow)

    # ------------------------------------------------------------------ public

    def show_node(self, node_id: str | None) -> None:
        """Show a node's parameters (None: nothing selected)."""
        node = self._find(node_id)
        self._node_id = node.id if node is not None else None
        self._rebuild(node)

    def shown_node_id(self) -> str | None:
        return self._node_id

    def set_registry(self, registry: OperationSource) -> None:
        """Use another cell's operations; the shown node is laid out again."""
        self._registry = registry
        self.show_node(self._node_id)

    def set_teacher(self, teacher: Any) -> None:
        """The robot that Teach reads and Move here drives (None: no such buttons)."""
        self._teacher = teacher
        self.show_node(self._node_id)

    def set_object_names(self, names: Sequence[str]) -> None:
        """Names the ObjectModel fields offer (e.g. ``ObjectLibrary().names()``)."""
        self._object_names = list(names)
        self._update_context()

    def parameter_names(self) -> list[str]:
        """Names the plan's outputs write and the plan declares, sorted (for completion)."""
        names = {decl.name for decl in self.document.plan.parameters}
        for _, node in self.document.plan.walk():
            manifest = manifest_or_none(self._registry, node.op)
            for port, binding in node.params.items():
                spec = manifest.port(port) if manifest is not None else None
                if binding.ref and spec is not None and spec.direction is Direction.OUT:
                    names.add(binding.ref)
        return sorted(names)

    def completion_model(self) -> QStringListModel:
        """The model behind the parameter-name completion of every name field."""
        return self._names

    def set_problems(self, problems: Sequence[Problem]) -> None:
        """Mark the fields of the shown node that validation complains about
        (connect ``ValidationPanel.problems_changed`` here).
        """
        self._problems = list(problems)
        self._mark_problems()

    def field_problem(self, name: str) -> str:
        """The problem text shown next to a port or setting ("" when none)."""
        label = self._field_labels.get(name)
        return label.toolTip() if label is not None and label.property("problem") else ""

    def port_row(self, port: str) -> PortRow:
        return self._port_rows[port]

    # ------------------------------------------------------------------ layout

    def _find(self, node_id: str | None) -> NodeSpec | None:
        if node_id is None:
            return None
        try:
            return self.document.node(node_id)
        except DocumentError:
            return None

    def _context(self) -> EditorContext:
        objects = list(dict.fromkeys([*self._object_names, *self.document.plan.objects]))
        return EditorContext(tuple(objects), tuple(self.document.plan.waypoints))

    def _clear_form(self) -> None:
        while self.form.rowCount():
            self.form.removeRow(0)
        self._port_rows.clear()
        self._field_labels.clear()
        self.teach_buttons.clear()

    def _add_row(self, name: str, text: str, tip: str, row: QWidget) -> None:
        label = QLabel(text)
        label.setToolTip(tip)
        label.setProperty("tip", tip)
        row.setToolTip(tip)
        self._field_labels[name] = label
        self.form.addRow(label, row)

    def _mark_problems(self) -> None:
        found: dict[str, list[Problem]] = {}
        for problem in self._problems:
            if problem.node_id == self._node_id and problem.field:
                found.setdefault(problem.field, []).append(problem)
        for name, label in self._field_labels.items():
            problems = found.get(name, [])
            text = label.text().removeprefix("⚠ ")
            label.setText(("⚠ " if problems else "") + text)
            label.setProperty("problem", bool(problems))
            colour = "#c0392b" if any(p.severity == ERROR for p in problems) else "#b8860b"
            label.setStyleSheet(f"color: {colour}" if problems else "")
            messages = "\n".join(p.message for p in problems)
            label.setToolTip(messages or str(label.property("tip")))

    def _rebuild(self, node: NodeSpec | None) -> None:
        self._clear_form()
        self._field_labels.update(self._condition_labels)
        self._shown_op = node.op if node is not None else None
        self.name_field.setEnabled(node is not None)
        self.name_field.setText(node.name if node is not None else "")
        self.advanced_toggle.setVisible(node is not None)
        self.advanced_toggle.setChecked(node is not None and bool(node.conditions))
        for field in self.condition_fields.values():
            field.setText("")
        if node is None:
            self.kind_label.setText("Select a node to see its parameters.")
            self.doc_label.setText("")
            return
        self._names.setStringList(self.parameter_names())
        if node.kind is NodeKind.OPERATION:
            self._layout_operation(node)
        elif node.kind is NodeKind.SUBTREE:
            self._layout_instance(node)
        else:
            self.kind_label.setText(f"<b>{readable(node.kind.value)}</b>")
            self.doc_label.setText(KIND_DOC.get(node.kind, ""))
            self._add_port_rows(KIND_PORTS.get(node.kind, ()))
            for row in self._port_rows.values():  # logic-node ports take fixed values only
                row.mode_combo.removeItem(MODE_REFERENCE)
        self._refresh(node)
        self._mark_problems()

    def _layout_operation(self, node: NodeSpec) -> None:
        manifest = manifest_or_none(self._registry, node.op)
        if manifest is None:
            self.kind_label.setText(f"<b>{node.op or 'no operation'}</b>")
            self.doc_label.setText(
                "This cell has no such operation; its settings are kept as they are."
            )
            return
        self.kind_label.setText(f"<b>{manifest.id}</b> ({manifest.kind.value})")
        self.doc_label.setText(manifest.doc)
        self._add_port_rows(manifest.ports)

    def _layout_instance(self, node: NodeSpec) -> None:
        """An instance's binding form: its subtree's inputs and outputs are its ports."""
        subtree = self.document.plan.subtree(node.subtree) if node.subtree else None
        if subtree is None:
            self.kind_label.setText("<b>Subtree missing</b>")
            self.doc_label.setText("This plan does not hold the subtree this instance runs.")
            return
        self.kind_label.setText(f"<b>Subtree {subtree.name}</b> (version {subtree.version})")
        self.doc_label.setText(subtree.description)
        self._add_port_rows(instance_manifest(subtree).ports)

    def _add_port_rows(self, ports: tuple[PortSpec, ...]) -> None:
        """One row per port, of an operation or of a logic node kind: one row type for both."""
        context = self._last_context = self._context()
        for port in ports:
            row = PortRow(port, self._names, context)
            row.binding_committed.connect(lambda b, name=port.name: self._set_param(name, b))
            self._port_rows[port.name] = row
            unit = display_unit(port.unit).suffix if port.unit else ""
            arrow = "→ " if port.direction is Direction.OUT else ""
            text = f"{arrow}{port.name}" + (f" [{unit}]" if unit else "")
            tip = f"{port.doc}\n{type_names(port.types)}" + (f", in {unit}" if unit else "")
            self._add_row(port.name, text, tip, row)
            if self._teacher is not None and is_teachable(port):
                self._add_teach_buttons(port)
        self._update_offers()

    def _update_offers(self) -> None:
        """Offer each input first the outputs of its types written before the shown node."""
        node = self._find(self._node_id)
        if node is None or node.kind not in (NodeKind.OPERATION, NodeKind.SUBTREE):
            return
        plan = self.document.plan
        before = nodes_before(plan, node.id)
        for row in self._port_rows.values():
            if row.port.direction is Direction.IN:
                types = tuple(row.port.types)
                row.set_offers(offered_outputs(plan, self._registry, before, types, node))

    def _refresh(self, node: NodeSpec) -> None:
        """Show the node's current values in the existing rows."""
        if self.name_field.text() != node.name and not self.name_field.hasFocus():
            self.name_field.setText(node.name)
        for port, row in self._port_rows.items():
            row.load(node.params.get(port))
        for condition, field in self.condition_fields.items():
            text = node.conditions.get(condition, "")
            if field.text() != text and not field.hasFocus():
                field.setText(text)
        for buttons in self.teach_buttons.values():
            buttons.update_enabled()

    def _update_context(self) -> None:
        context = self._context()
        if context == self._last_context:
            return
        self._last_context = context
        for row in self._port_rows.values():
            row.set_context(context)

    def _add_teach_buttons(self, port: PortSpec) -> None:
        def target() -> tuple[Any, Any] | None:
            node = self._find(self._node_id)
            params = node.params if node is not None else {}
            return move_target(params.get(port.name), params.get("reference"))

        def by_name() -> bool:
            node = self._find(self._node_id)
            binding = node.params.get(port.name) if node is not None else None
            return binding is not None and binding.is_ref

        buttons = TeachButtons(self._teacher, lambda: self.teach(port.name), target, by_name)
        self.teach_buttons[port.name] = buttons
        self.form.addRow("", buttons)

    def teach(self, port: str) -> bool:
        """Fill ``port`` of the shown node from where the robot is now (one undo step). A
        waypoint other nodes use too is taught again only if the user agrees; what changed
        (old and new pose) goes to the status bar.
        """
        node = self._find(self._node_id)
        row = self._port_rows.get(port)
        if node is None or row is None or self._teacher is None:
            return False
        old = node.params.get(port)
        old_value = old.value if old is not None and not old.is_ref else None
        if isinstance(old_value, Waypoint):
            users = other_users(self.document.plan, old_value.name, node.id)
            if users and not self._question_dialogs().ask_overwrite_waypoint(
                self, old_value.name, users
            ):
                self._teacher.message.emit(f"Teach cancelled: {old_value.name!r} is unchanged.")
                return False
        names = [w.name for w in self.document.plan.waypoints]
        interfaces = {name: self._teacher.interface(name) for name in ("arm", "world")}
        try:
            waypoint, binding = taught_value(
                interfaces, row.port, old, node.name, names, row.value_type
            )
        except TeachError as exc:
            self._teacher.message.emit(f"Cannot teach {port}: {exc}.")
            return False
        if waypoint is None:
            self.document.set_param(node.id, port, binding)
            what = f"{port} of {node.name or node.id}"
        else:
            old_name = old_value.name if isinstance(old_value, Waypoint) else waypoint.name
            self.document.replace_waypoint(
                old_name, waypoint, f"Teach {waypoint.name!r}", bind=(node.id, port)
            )
            what = f"the waypoint {waypoint.name!r}"
        self._teacher.message.emit(change_text(what, old_value, binding.value))
        return True

    def _question_dialogs(self) -> Dialogs:
        """This panel's dialogs, else the main window's, else plain message boxes."""
        if self.dialogs is not None:
            return self.dialogs
        found = getattr(self.window(), "dialogs", None)
        return found if isinstance(found, Dialogs) else Dialogs()

    # ------------------------------------------------------------------ document -> view

    def _node_changed(self, node_id: str) -> None:
        if node_id != self._node_id:
            return
        node = self._find(node_id)
        if node is None or node.op != self._shown_op:
            self.show_node(node_id)
        else:
            self._refresh(node)

    def _node_removed(self, _parent: str, _index: int, ids: list[str]) -> None:
        if self._node_id in ids:
            self.show_node(None)

    def _plan_reset(self) -> None:
        self.show_node(self._node_id)

    def _plan_changed(self) -> None:
        names = self.parameter_names()
        if names != self._names.stringList():
            self._names.setStringList(names)
        self._update_context()
        self._update_offers()

    # ------------------------------------------------------------------ view -> document

    def _rename(self) -> None:
        if self._node_id is not None:
            self.document.rename(self._node_id, self.name_field.text().strip())

    def _set_condition(self, condition: Condition) -> None:
        node = self._find(self._node_id)
        if node is not None:
            self.document.set_condition(node.id, condition, self.condition_fields[condition].text())

    def _set_param(self, port: str, binding: Binding | None) -> None:
        node = self._find(self._node_id)
        if node is None or node.params.get(port) == binding:
            return
        self.document.set_param(node.id, port, binding)
