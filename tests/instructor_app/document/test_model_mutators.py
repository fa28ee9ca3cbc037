"""The model owns its edits: public mutators that emit signals and know nothing of undo."""

from __future__ import annotations

import ast
from pathlib import Path

from pytestqt.qtbot import QtBot

from engine.spec import Binding, NodeKind, NodeSpec
from engine.types import ParamType
from instructor_app.document import PlanModel

DOCUMENT = Path(__file__).resolve().parents[3] / "instructor_app" / "document"


def test_the_model_imports_no_undo_code() -> None:
    tree = ast.parse((DOCUMENT / "model.py").read_text(encoding="utf-8"))
    imported = {
        node.module or "" for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
    } | {
        alias.name
        for node in ast.walk(tree)
        if isinstance(node, ast.Import)
        for alias in node.names
    }
    assert "instructor_app.document.commands" not in imported
    assert "QUndo" not in (DOCUMENT / "model.py").read_text(encoding="utf-8")


def test_mutators_change_the_spec_and_emit(qtbot: QtBot) -> None:
    model = PlanModel()
    root = NodeSpec(NodeKind.SEQUENCE, id="root")
    wait = NodeSpec(NodeKind.WAIT, id="wait")
    with qtbot.waitSignal(model.node_inserted) as inserted:
        model.insert_node(root, None, 0, {})
    assert inserted.args == ["", 0, "root"]
    model.insert_node(wait, "root", 0, {})
    seconds = Binding.fixed(2.0, ParamType.DURATION)
    with qtbot.waitSignal(model.node_changed) as changed:
        model.set_binding("wait", "seconds", seconds)
    assert changed.args == ["wait"] and model.node("wait").params == {"seconds": seconds}
    with qtbot.waitSignal(model.plan_changed):
        model.rename_node("wait", "pause")
    assert model.node("wait").name == "pause"
    node, layout = model.detach_node("wait")
    assert node is wait and layout == {} and model.plan.tree is root and not root.children
    assert not hasattr(model, "undo_stack")
