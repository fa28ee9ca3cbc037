"""End to end: the paper's Figure 3 plan built in the Instructor from an empty document, through
the palette, the canvas, the inspector and the plan panels alone (no plan file is loaded),
saved, closed, reopened and run on the simulated cell until the cup is in the bin.

The plan to build is resources/examples/cup_to_bin.costar.json; its waypoints come in the way
a worker brings taught waypoints: the waypoints panel imports cup_to_bin.waypoints.json.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from engine.files import load_plan
from engine.spec import Binding, NodeSpec, PlanSpec, RunPolicy
from engine.status import Status
from engine.types import ObjectModel, ParamType
from engine.validation import ERROR, validate_plan
from instructor_app.inspectors.rows import MODE_REFERENCE, MODE_VALUE
from instructor_app.main_window import MainWindow
from instructor_app.runtime.session import CellSession
from tests.capabilities.sim.test_cup_to_bin import cup_in_bin
from tests.instructor_app.gui_driver import (
    ScriptedDialogs,
    bind_reference,
    click_node,
    double_click_palette,
    import_waypoints,
    make_window,
    node_named,
    press_run,
    rename,
    search_insert,
    set_plan_name,
    set_run_policy,
    set_value,
)

pytestmark = pytest.mark.sim

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"
EXAMPLE = EXAMPLES / "cup_to_bin.costar.json"
WAYPOINTS = EXAMPLES / "cup_to_bin.waypoints.json"
# The one node that only runs when the cup is not seen, and its child.
FALLBACK = ("then look again", "WAIT")

# What the worker does, node by node: (parent, palette search text, what it inserts, name,
# bindings). A binding is ("value", value, type) or ("ref", parameter name).
Step = tuple[str | None, str, str, str, list[tuple[str, tuple[Any, ...]]]]
OBSERVE = [("target", ("value", "observe"))]
STEPS: list[Step] = [
    (None, "sequence", "sequence", "cup to bin", []),
    ("cup to bin", "motion.move_to", "motion.move_to", "step out of view", OBSERVE),
    ("cup to bin", "markers.detect_markers", "markers.detect_markers", "detect CUP and BIN",
     [("camera", ("value", "shoulder"))]),
    ("cup to bin", "selector", "selector", "transfer or wait", []),
    ("transfer or wait", "sequence", "sequence", "transfer", []),
    ("transfer", "markers.object_found", "markers.object_found", "CUP found",
     [("object", ("value", "cup"))]),
    ("transfer", "markers.object_pose", "markers.object_pose", "pose of CUP",
     [("object", ("value", "cup")), ("pose", ("ref", "CUP_POSE"))]),
    ("transfer", "markers.object_pose", "markers.object_pose", "pose of BIN",
     [("object", ("value", "waste_bin")), ("pose", ("ref", "BIN_POSE"))]),
    ("transfer", "", "gripper.open", "open gripper", []),
    ("transfer", "motion.move_to", "motion.move_to", "move above CUP_POSE",
     [("reference", ("ref", "CUP_POSE")), ("target", ("value", "above cup"))]),
    ("transfer", "motion.move_to", "motion.move_to", "move to CUP_POSE",
     [("mode", ("value", "linear")), ("reference", ("ref", "CUP_POSE")),
      ("target", ("value", "grasp cup"))]),
    ("transfer", "", "gripper.close", "grasp", []),
    ("transfer", "", "gripper.is_holding", "holding the cup", []),
    ("transfer", "motion.move_to", "motion.move_to", "lift",
     [("mode", ("value", "linear")), ("reference", ("ref", "CUP_POSE")),
      ("target", ("value", "above cup"))]),
    ("transfer", "motion.move_to", "motion.move_to", "move to BIN_POSE",
     [("reference", ("ref", "BIN_POSE")), ("target", ("value", "over bin"))]),
    ("transfer", "", "gripper.open", "release", []),
    ("transfer or wait", "force failure", "force_failure", "then look again", []),
    ("then look again", "", "wait", "WAIT", []),  # the Wait node (1 s by default)
    ("cup to bin", "motion.move_to", "motion.move_to", "back to observe", OBSERVE),
]  # fmt: skip


@pytest.fixture
def sim_session(qapp: Any) -> Iterator[CellSession]:
    session = CellSession("sim", speed=None)  # as fast as the simulation goes
    assert session.open(), "the simulated cell did not open"
    yield session
    session.close()


def build_figure3(qtbot: Any, window: MainWindow) -> None:
    """Everything a worker does to teach the plan, on an empty document."""
    set_plan_name(qtbot, window, "Cup to bin (Figure 3, simulated cell)")
    set_run_policy(qtbot, window, RunPolicy.UNTIL_SUCCESS)
    import_waypoints(qtbot, window, WAYPOINTS)
    for parent, search, expect, name, bindings in STEPS:
        if parent is not None:
            click_node(qtbot, window, node_named(window, parent))
        if search:  # type into the palette's search field, Enter
            node_id = search_insert(qtbot, window, search, expect)
        else:  # find it in the palette's list, double-click it
            node_id = double_click_palette(qtbot, window, expect)
        rename(qtbot, window, node_id, name)
        for port, (how, value) in bindings:
            if how == "ref":
                bind_reference(qtbot, window, node_id, port, value)
            else:
                set_value(qtbot, window, node_id, port, _typed(window, node_id, port, value))


def _typed(window: MainWindow, node_id: str, port: str, value: Any) -> Any:
    """The value as its editor holds it: waypoints by name, object models by name."""
    row = window.views.inspector.port_row(port)
    if row.value_type is ParamType.WAYPOINT:
        return next(w for w in window.document.plan.waypoints if w.name == value)
    if row.value_type is ParamType.OBJECT:
        return ObjectModel(value)
    return value


def shape(node: NodeSpec) -> tuple[Any, ...]:
    """A node and its subtree without ids: kind, op, name, bindings, settings."""
    params = {port: _binding(b) for port, b in sorted(node.params.items())}
    children = tuple(shape(child) for child in node.children)
    return (node.kind, node.op, node.name, params, children)


def _binding(binding: Binding) -> tuple[Any, ...]:
    return (binding.ref,) if binding.is_ref else (binding.type, binding.value)


def test_figure3_built_in_the_gui_saved_reopened_and_run_on_the_sim_cell(
    qtbot: Any, sim_session: CellSession, tmp_path: Path
) -> None:
    dialogs = ScriptedDialogs()
    window = make_window(qtbot, sim_session, tmp_path, dialogs)
    empty = window.document.serialized()
    build_figure3(qtbot, window)
    built = window.document.serialized()
    window.views.validation.revalidate()
    assert window.problems_label.text() == "No problems"

    # Every edit was an undo command: all of them undo back to the empty plan, and redo again.
    stack = window.document.undo_stack
    edits = stack.count()
    for _ in range(edits):
        window.actions_by_name["undo"].trigger()
    assert window.document.serialized() == empty
    for _ in range(edits):
        window.actions_by_name["redo"].trigger()
    assert window.document.serialized() == built
    assert window.views.canvas.node_count() == len(STEPS)  # the canvas followed every step

    dialogs.save_paths = [str(tmp_path / "cup to bin")]
    window.actions_by_name["save"].trigger()
    saved_path = tmp_path / "cup to bin.costar.json"
    assert saved_path.exists() and not window.document.dirty
    assert window.close() and dialogs.asked == []  # nothing unsaved: no question

    # The saved plan is the example: same tree (ids aside), bindings, waypoints and policy.
    registry = sim_session.registry
    saved, example = load_plan(saved_path, registry.aliases()), load_plan(EXAMPLE)
    assert shape(saved.tree) == shape(example.tree)
    assert saved.waypoints == example.waypoints
    assert (saved.name, saved.run_policy) == (example.name, example.run_policy)
    assert not [p for p in validate_plan(saved, registry) if p.severity == ERROR]

    reopened_dialogs = ScriptedDialogs()
    reopened_dialogs.open_paths = [str(saved_path)]
    reopened = make_window(qtbot, sim_session, tmp_path, reopened_dialogs)
    reopened.actions_by_name["open"].trigger()
    assert reopened.document.path == saved_path
    assert reopened.document.serialized() == saved_path.read_text(encoding="utf-8")
    check_inspector_shows_the_bindings(qtbot, reopened)
    check_run(qtbot, reopened, sim_session, reopened.document.plan)


def check_inspector_shows_the_bindings(qtbot: Any, window: MainWindow) -> None:
    """Clicked on the reopened canvas, nodes show their values and parameter names."""
    inspector = window.views.inspector
    click_node(qtbot, window, node_named(window, "move to CUP_POSE"))
    assert inspector.name_field.text() == "move to CUP_POSE"
    target, reference = inspector.port_row("target"), inspector.port_row("reference")
    assert target.mode == MODE_VALUE and target.editor.combo.currentText() == "grasp cup (object)"
    assert reference.mode == MODE_REFERENCE and reference.ref_field.text() == "CUP_POSE"
    assert inspector.port_row("mode").editor.combo.currentText() == "linear"
    click_node(qtbot, window, node_named(window, "pose of BIN"))
    assert inspector.port_row("object").editor.combo.currentText() == "waste_bin"
    assert inspector.port_row("pose").ref_field.text() == "BIN_POSE"


def check_run(qtbot: Any, window: MainWindow, session: CellSession, plan: PlanSpec) -> None:
    """Run: every node on the success path ends green, and the cup is in the bin."""
    with qtbot.waitSignal(window.controller.run_finished, timeout=120_000) as blocker:
        press_run(qtbot, window)
    assert blocker.args[0].status is Status.SUCCESS
    canvas = window.views.canvas
    path = [n.id for _, n in plan.walk() if n.name not in FALLBACK]
    assert len(path) == len(STEPS) - len(FALLBACK)
    qtbot.waitUntil(lambda: all(canvas.status_of(i) is Status.SUCCESS for i in path))
    assert canvas.status_of(node_named(window, "WAIT")) is not Status.SUCCESS
    session.cell.sim.wait_sim(1.0)  # let the cup settle
    assert cup_in_bin(session.cell.truth_pose("cup"), session.cell.truth_pose("waste_bin"))
