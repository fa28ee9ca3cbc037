"""The "Save as subtree" dialog: name, folder, description, open parameters and outputs.

Every parameter of the selected nodes is listed with its current value; ticking "open" makes
it an input of the subtree (named in the second column, described in the third), the others
stay fixed inside. Every name the selected nodes write is listed too; ticking it declares it
an output. Names the nodes read from outside become inputs by themselves.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from PySide6.QtCore import Qt
from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QLabel,
    QLineEdit,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from engine.operations import Direction, PortSpec
from engine.spec import NodeSpec
from engine.subtree_ops import OpenPort, PortsOf
from instructor_app.canvas.style import binding_text

__all__ = ["SubtreeChoices", "SaveSubtreeDialog"]


@dataclass
class SubtreeChoices:
    """What the user chose in the dialog."""

    name: str
    folder: str = ""
    description: str = ""
    open_ports: list[OpenPort] = field(default_factory=list)
    outputs: dict[str, str] = field(default_factory=dict)


def _item(text: str, checkable: bool = False, editable: bool = False) -> QTableWidgetItem:
    item = QTableWidgetItem(text)
    flags = Qt.ItemFlag.ItemIsEnabled | Qt.ItemFlag.ItemIsSelectable
    if checkable:
        flags |= Qt.ItemFlag.ItemIsUserCheckable
        item.setCheckState(Qt.CheckState.Unchecked)
    if editable:
        flags |= Qt.ItemFlag.ItemIsEditable
    item.setFlags(flags)
    return item


class SaveSubtreeDialog(QDialog):
    """Choose how a selection becomes a library subtree.

    Args:
        root: the selected node (its nodes below are saved with it).
        ports_of: the ports of a node.
        parent: the window.
    """

    def __init__(self, root: NodeSpec, ports_of: PortsOf, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Save as subtree")
        self.name_field = QLineEdit(root.name or root.label, self)
        self.folder_field = QLineEdit(self)
        self.folder_field.setPlaceholderText("folder in the library, e.g. kitting")
        self.description_field = QLineEdit(self)
        self.params_table = QTableWidget(0, 4, self)
        self.params_table.setHorizontalHeaderLabels(
            ["Node / parameter", "Value", "Input name", "Description"]
        )
        self.outputs_table = QTableWidget(0, 2, self)
        self.outputs_table.setHorizontalHeaderLabels(["Written name (output)", "Description"])
        self._params: list[tuple[NodeSpec, PortSpec]] = []
        self._fill(root, ports_of)
        for table in (self.params_table, self.outputs_table):
            table.resizeColumnsToContents()
            table.horizontalHeader().setStretchLastSection(True)
        form = QFormLayout()
        form.addRow("Name", self.name_field)
        form.addRow("Folder", self.folder_field)
        form.addRow("Description", self.description_field)
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Save | QDialogButtonBox.StandardButton.Cancel, self
        )
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(QLabel("Tick the parameters that stay open (the subtree's inputs):"))
        layout.addWidget(self.params_table)
        layout.addWidget(QLabel("Tick the names the subtree passes out (its outputs):"))
        layout.addWidget(self.outputs_table)
        layout.addWidget(buttons)
        self.resize(720, 560)

    def _fill(self, root: NodeSpec, ports_of: PortsOf) -> None:
        written: list[str] = []
        for _, node in root.walk():
            for port in ports_of(node):
                binding = node.params.get(port.name)
                if port.direction is Direction.OUT:
                    if binding is not None and binding.ref and binding.ref not in written:
                        written.append(binding.ref)
                    continue
                if binding is not None and binding.is_ref:
                    continue  # a reference: read from outside (an input) or from inside
                self._add_param(node, port, binding_text(binding) if binding else "(default)")
        for name in written:
            row = self.outputs_table.rowCount()
            self.outputs_table.insertRow(row)
            self.outputs_table.setItem(row, 0, _item(name, checkable=True))
            self.outputs_table.setItem(row, 1, _item("", editable=True))

    def _add_param(self, node: NodeSpec, port: PortSpec, value: str) -> None:
        row = self.params_table.rowCount()
        self.params_table.insertRow(row)
        self.params_table.setItem(row, 0, _item(f"{node.label} / {port.name}", checkable=True))
        self.params_table.setItem(row, 1, _item(value))
        self.params_table.setItem(row, 2, _item(port.name.upper(), editable=True))
        self.params_table.setItem(row, 3, _item(port.doc, editable=True))
        self._params.append((node, port))

    # ------------------------------------------------------------------ choices

    def parameter_rows(self) -> list[str]:
        """The first column of every parameter row ("node / port")."""
        return [self._text(self.params_table, r, 0) for r in range(self.params_table.rowCount())]

    def output_rows(self) -> list[str]:
        return [self._text(self.outputs_table, r, 0) for r in range(self.outputs_table.rowCount())]

    def set_open(self, row: int, name: str, doc: str = "") -> None:
        """Tick parameter row ``row`` as an input called ``name`` (what a click and typing do)."""
        table = self.params_table
        self._cell(table, row, 0).setCheckState(Qt.CheckState.Checked)
        self._cell(table, row, 2).setText(name)
        if doc:
            self._cell(table, row, 3).setText(doc)

    def set_output(self, row: int, doc: str = "") -> None:
        self._cell(self.outputs_table, row, 0).setCheckState(Qt.CheckState.Checked)
        self._cell(self.outputs_table, row, 1).setText(doc)

    def choices(self) -> SubtreeChoices:
        """What the dialog says now."""
        open_ports = [
            OpenPort(
                node.id,
                port.name,
                self._text(self.params_table, row, 2).strip(),
                self._text(self.params_table, row, 3).strip(),
            )
            for row, (node, port) in enumerate(self._params)
            if self._checked(self.params_table, row)
        ]
        outputs = {
            self._text(self.outputs_table, row, 0): self._text(self.outputs_table, row, 1)
            for row in range(self.outputs_table.rowCount())
            if self._checked(self.outputs_table, row)
        }
        return SubtreeChoices(
            self.name_field.text().strip(),
            self.folder_field.text().strip(),
            self.description_field.text().strip(),
            open_ports,
            outputs,
        )

    @staticmethod
    def _cell(table: QTableWidget, row: int, column: int) -> QTableWidgetItem:
        item = table.item(row, column)
        assert item is not None
        return item

    def _text(self, table: QTableWidget, row: int, column: int) -> str:
        return self._cell(table, row, column).text()

    def _checked(self, table: QTableWidget, row: int) -> bool:
        return self._cell(table, row, 0).checkState() == Qt.CheckState.Checked
