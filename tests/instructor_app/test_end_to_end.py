"""End to end: the paper's Figure 3 plan built by hand in the Instructor from an empty document,
through the palette, the canvas, the inspector and the plan panels alone (no plan file is
loaded), saved, closed, reopened and run on the simulated cell until the cup is in the bin.
The user's actions are counted (clicks, key presses, typed texts, lists opened, drags).

The plan to build is resources/examples/cup_to_bin.costar.json: Figure 3 taught with the
shipped Pick and Place subtrees ("Pick cup": look, check, grasp with the cup model's first
grasp; "Place over bin": move there, open) under the selector that falls back to a wait;
its two taught waypoints (a place out of the camera's view, a place over the bin) come in
the way a worker brings them: the waypoints panel imports cup_to_bin.waypoints.json.
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
from instructor_app.inspectors.rows import MODE_UNSET, MODE_VALUE
from instructor_app.main_window import MainWindow
from instructor_app.runtime.session import CellSession
from tests.capabilities.sim.test_cup_to_bin import cup_in_bin
from tests.instructor_app.gui_driver import (
    CountingBot,
    ScriptedDialogs,
    bind_reference,
    click_node,
    drag_object_onto,
    import_waypoints,
    make_window,
    node_named,
    press_run,
    rename,
    search_down_insert,
    set_plan_name,
    set_run_policy,
    set_value,
    show_tab,
)

pytestmark = pytest.mark.sim

EXAMPLES = Path(__file__).resolve().parents[2] / "resources" / "examples"
EXAMPLE = EXAMPLES / "cup_to_bin.costar.json"
WAYPOINTS = EXAMPLES / "cup_to_bin.waypoints.json"
# The one node that only runs when the cup is not seen, and its child.
FALLBACK = ("Force failure", "Wait")
# Counted as CountingBot counts (every click into a field, key, typed text, list opened,
# drag): 31 actions for these 6 nodes (34 before an unset input showed its editor, so a
# value is chosen there without choosing "value" first), against 126 for the 13 nodes of Figure 3 built from
# operations, each named by hand. What made the difference: the shipped Pick and Place
# subtrees (resources/library/pick_place) do the look, the checks, the grasp from the cup's
# model, the move and the release, each one node that takes the object or the place; a
# model dragged from the Objects tab onto a node is "Pick cup" (3 actions with the two tab
# clicks, against 6 by palette and object field); an instance is named after its object or
# waypoint ("Place over bin"), so no node needs renaming. Before: 132 when choosing
# "parameter" needed the name typed; 206 for the plan of 18 nodes that moved above the cup,
# down to it, closed, checked and lifted with waypoints taught relative to the cup. A change
# that makes teaching this plan take more actions fails here.
MOST_ACTIONS = 31

# What the worker does, node by node: (node to click first, or None when the selection
# already is where the new node goes: a leaf selected takes its next sibling, a composite
# its last child), how it comes (a palette search text, or DRAG and an object model dragged
# from the Objects tab onto the selected node), what it inserts (a kind, an operation or a
# library subtree's id), its name (None: the name it comes with), bindings. A binding is
# ("value", value) or ("ref", parameter name).
DRAG = "drag from the Objects tab: "
Step = tuple[str | None, str, str, str | None, list[tuple[str, tuple[Any, ...]]]]
STEPS: list[Step] = [
    (None, "selector", "selector", None, []),
    (None, "sequence", "sequence", None, []),
    (None, DRAG + "cup", "pick_place.pick", None, []),  # "Pick cup"
    (None, "place", "pick_place.place", None, [("PLACE", ("value", "over bin"))]),
    ("Selector", "force failure", "force_failure", None, []),
    (None, "wait", "wait", None, []),  # the Wait node (1 s by default)
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
    for parent, comes, expect, name, bindings in STEPS:
        if parent is not None:
            click_node(qtbot, window, node_named(window, parent))
        if comes.startswith(DRAG):  # the Objects tab, drag the model onto the node, back
            show_tab(qtbot, window, "Objects")
            selected = window.views.canvas.selected_ids()[0]
            node_id = drag_object_onto(qtbot, window, comes.removeprefix(DRAG), selected)
            show_tab(qtbot, window, "Palette")
        else:  # type into the palette's search field, Down to the wanted hit if needed, Enter
            node_id = search_down_insert(qtbot, window, comes, expect)
        assert expect in _what(window.document.node(node_id))
        if name is not None:
            rename(qtbot, window, node_id, name)
        for port, (how, value) in bindings:
            if how == "ref":
                bind_reference(qtbot, window, node_id, port, value)
            else:
                set_value(qtbot, window, node_id, port, _typed(window, node_id, port, value))


def _what(node: NodeSpec) -> tuple[str | None, ...]:
    """Its operation, kind and library subtree's id."""
    return (node.op, node.kind.value, node.subtree.id if node.subtree else None)


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


def test_figure3_built_by_hand_with_grasp_counted_saved_reopened_and_run(
    qtbot: Any, sim_session: CellSession, tmp_path: Path, record_property: Any
) -> None:
    dialogs = ScriptedDialogs()
    window = make_window(qtbot, sim_session, tmp_path, dialogs)
    empty = window.document.serialized()
    hands = CountingBot(qtbot)
    build_figure3(hands, window)
    built = window.document.serialized()
    actions = len(hands.actions) + 1  # and one click on Run
    print(f"Figure 3 by hand: {actions} user actions for {len(STEPS)} nodes")
    record_property("figure3_actions", actions)  # bench/teach.py reports it
    assert actions <= MOST_ACTIONS, hands.actions
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
    """Clicked on the reopened canvas, nodes show their values."""
    inspector = window.views.inspector
    click_node(qtbot, window, node_named(window, "Pick cup"))
    assert inspector.name_field.text() == "Pick cup"
    assert inspector.port_row("OBJECT").editor.combo.currentText() == "cup"
    assert inspector.port_row("LOOK_FROM").mode == MODE_UNSET  # observe, by default
    click_node(qtbot, window, node_named(window, "Place over bin"))
    place = inspector.port_row("PLACE")
    assert place.mode == MODE_VALUE and place.editor.combo.currentText() == "over bin (object)"


def check_run(qtbot: Any, window: MainWindow, session: CellSession, plan: PlanSpec) -> None:
    """Run: every node on the success path ends green, and the cup is in the bin."""
    with qtbot.waitSignal(window.controller.run_finished, timeout=120_000) as blocker:
        press_run(qtbot, window)
    assert blocker.args[0].status is Status.SUCCESS
    canvas = window.views.canvas
    path = [n.id for _, n in plan.walk() if n.name not in FALLBACK]
    assert len(path) == len(STEPS) - len(FALLBACK)
    qtbot.waitUntil(lambda: all(canvas.status_of(i) is Status.SUCCESS for i in path))
    assert canvas.status_of(node_named(window, FALLBACK[1])) is not Status.SUCCESS
    session.cell.sim.wait_sim(1.0)  # let the cup settle
    assert cup_in_bin(session.cell.truth_pose("cup"), session.cell.truth_pose("waste_bin"))
