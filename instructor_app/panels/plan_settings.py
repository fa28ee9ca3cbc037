"""The plan's own settings: its name and its run policy (the paper's root "evaluated until it
returns SUCCESS" is the policy "until success"), and after how many identical failures in a
row such a plan gives up.

Each finished edit is one document command (``rename_plan``, ``set_run_policy``,
``set_give_up_after``, ``set_reset_cell``); the panel follows the document (undo, open, new)
without echoing edits back.
"""

from __future__ import annotations

from PySide6.QtWidgets import QCheckBox, QComboBox, QFormLayout, QLineEdit, QSpinBox, QWidget

from engine.spec import RunPolicy
from instructor_app.document import PlanDocument

__all__ = ["PlanSettingsPanel", "POLICY_TEXT"]

POLICY_TEXT: dict[RunPolicy, str] = {
    RunPolicy.ONCE: "once",
    RunPolicy.UNTIL_SUCCESS: "until success",
    RunPolicy.FOREVER: "forever",
}


class PlanSettingsPanel(QWidget):
    """Edits the plan's name, run policy, limit of identical failures and cell reset.

    Args:
        document: the plan being edited.
    """

    def __init__(self, document: PlanDocument, parent: QWidget | None = None) -> None:
        super().__init__(parent)
        self.document = document
        self.name_field = QLineEdit()
        self.name_field.setPlaceholderText("plan name")
        self.name_field.editingFinished.connect(self._name_finished)
        self.policy_combo = QComboBox()
        for policy, text in POLICY_TEXT.items():
            # The value, not the enum: Qt hands a str subclass back as a plain str.
            self.policy_combo.addItem(text, policy.value)
        self.policy_combo.setToolTip(
            "once: run the tree once; until success: start again after a failure; "
            "forever: start again after every run"
        )
        self.policy_combo.activated.connect(self._policy_chosen)
        self.give_up_spin = QSpinBox()
        self.give_up_spin.setRange(0, 1_000_000)
        self.give_up_spin.setSpecialValueText("never")  # 0
        self.give_up_spin.setSuffix(" identical failures in a row")
        self.give_up_spin.setKeyboardTracking(False)  # one edit when typing is done
        self.give_up_spin.setToolTip(
            "A plan that runs until success stops after this many failures in a row that "
            "started at the same node with the same error and message (never: it keeps "
            "trying)"
        )
        self.give_up_spin.valueChanged.connect(self._give_up_changed)
        self.reset_box = QCheckBox("Reset the cell before each run")
        self.reset_box.setToolTip("Robot and objects go back to the scene's start before a run")
        self.reset_box.clicked.connect(lambda: self._reset_clicked(self.reset_box.isChecked()))
        form = QFormLayout(self)
        form.setContentsMargins(4, 4, 4, 4)
        form.addRow("Name", self.name_field)
        form.addRow("Run", self.policy_combo)
        form.addRow("Give up after", self.give_up_spin)
        form.addRow("", self.reset_box)
        document.plan_changed.connect(self._refresh)
        document.plan_reset.connect(self._refresh)
        self._refresh()

    def _name_finished(self) -> None:
        name = self.name_field.text().strip()
        if name and name != self.document.plan.name:
            self.document.rename_plan(name)

    def _policy_chosen(self, index: int) -> None:
        policy = RunPolicy(self.policy_combo.itemData(index))
        if policy is not RunPolicy(self.document.plan.run_policy):
            self.document.set_run_policy(policy)

    def _give_up_changed(self, limit: int) -> None:
        if limit != self.document.plan.give_up_after:
            self.document.set_give_up_after(limit)

    def _reset_clicked(self, checked: bool) -> None:
        if checked != self.document.plan.reset_cell:
            self.document.set_reset_cell(checked)

    def _refresh(self) -> None:
        plan = self.document.plan
        if self.name_field.text() != plan.name and not self.name_field.hasFocus():
            self.name_field.setText(plan.name)
        index = self.policy_combo.findData(RunPolicy(plan.run_policy).value)
        if index != self.policy_combo.currentIndex():
            self.policy_combo.setCurrentIndex(index)
        if self.give_up_spin.value() != plan.give_up_after:
            self.give_up_spin.setValue(plan.give_up_after)  # the same value: no new edit
        self.give_up_spin.setEnabled(RunPolicy(plan.run_policy) is RunPolicy.UNTIL_SUCCESS)
        if self.reset_box.isChecked() != plan.reset_cell:
            self.reset_box.setChecked(plan.reset_cell)
