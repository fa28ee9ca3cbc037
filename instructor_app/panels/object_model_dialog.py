"""The small dialog that asks about a new object model: name, symmetry, mass, units."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import (
    QCheckBox,
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QDoubleSpinBox,
    QFormLayout,
    QLabel,
    QLineEdit,
    QSpinBox,
    QWidget,
)

from capabilities.object_import import NewModel, valid_model_name

__all__ = ["AddModelDialog", "suggested_name"]


def suggested_name(mesh_file: Path) -> str:
    """A model name from a file name: "Bracket A.stl" -> "bracket_a"."""
    cleaned = "".join(c if c.isalnum() else "_" for c in mesh_file.stem.lower())
    return "_".join(part for part in cleaned.split("_") if part)[:48]


class AddModelDialog(QDialog):
    """Name, symmetry (none, continuous, discrete with its order) about x, y or z, mass,
    the mesh's units and whether the origin goes to the bottom centre.

    Args:
        mesh_file: the chosen mesh (its name suggests the model's).
        taken: names already in the libraries (refused).
    """

    def __init__(self, mesh_file: Path, taken: list[str], parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Add an object model")
        self._taken = set(taken)
        self.name_edit = QLineEdit(suggested_name(mesh_file))
        self.symmetry_combo = QComboBox()
        self.symmetry_combo.addItems(["none", "continuous", "discrete"])
        self.axis_combo = QComboBox()
        self.axis_combo.addItems(["z", "x", "y"])
        self.order_spin = QSpinBox()
        self.order_spin.setRange(2, 64)
        self.order_spin.setValue(4)
        self.mass_spin = QDoubleSpinBox()
        self.mass_spin.setRange(0.001, 100.0)
        self.mass_spin.setDecimals(3)
        self.mass_spin.setSuffix(" kg")
        self.mass_spin.setValue(0.1)
        self.units_combo = QComboBox()
        self.units_combo.addItems(["m", "mm", "cm"])
        self.bottom_check = QCheckBox("Origin at the bottom centre (z up)")
        self.bottom_check.setChecked(True)
        self.description_edit = QLineEdit()
        self.problem_label = QLabel()
        self.problem_label.setStyleSheet("color: #c0392b")
        self.buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel
        )
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        form = QFormLayout(self)
        form.addRow("Mesh", QLabel(mesh_file.name))
        form.addRow("Name", self.name_edit)
        form.addRow("Symmetry", self.symmetry_combo)
        form.addRow("About axis", self.axis_combo)
        form.addRow("Order", self.order_spin)
        form.addRow("Mass", self.mass_spin)
        form.addRow("Mesh units", self.units_combo)
        form.addRow(self.bottom_check)
        form.addRow("Description", self.description_edit)
        form.addRow(self.problem_label)
        form.addRow(self.buttons)
        self.name_edit.textChanged.connect(lambda _t: self._check())
        self.symmetry_combo.currentTextChanged.connect(lambda _t: self._check())
        self._check()

    def model(self) -> NewModel:
        """What the fields say."""
        return NewModel(
            name=self.name_edit.text().strip(),
            symmetry=self.symmetry_combo.currentText(),
            axis=self.axis_combo.currentText(),
            order=self.order_spin.value(),
            mass=self.mass_spin.value(),
            units=self.units_combo.currentText(),
            origin_at_bottom=self.bottom_check.isChecked(),
            description=self.description_edit.text().strip(),
        )

    def _check(self) -> None:
        name = self.name_edit.text().strip()
        problem = valid_model_name(name)
        if not problem and name in self._taken:
            problem = f"there is already a model {name!r}"
        symmetric = self.symmetry_combo.currentText() != "none"
        self.axis_combo.setEnabled(symmetric)
        self.order_spin.setEnabled(self.symmetry_combo.currentText() == "discrete")
        self.problem_label.setText(problem)
        ok = self.buttons.button(QDialogButtonBox.StandardButton.Ok)
        ok.setEnabled(not problem)
