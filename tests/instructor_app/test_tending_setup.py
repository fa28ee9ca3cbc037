"""Set-up as on site (issue 13 item 6): our wire-bender tending plan built in the Instructor
from the shipped library's subtrees, through the widgets alone, by a worker who never writes
code; its pick and place waypoints taught by moving the tool by hand; the user's actions
counted (the paper: about 30 minutes, no code).

The worker starts on an empty plan on the simulated tending cell and:

- names the plan, ticks "reset the cell before each run", imports the waypoints the
  integrator left (where the arm looks from, the scrap bin, where a broken part's pieces
  fall), inserts "find the rack" (ReRegisterRack) and runs it once so that the rack's marker
  has been seen;
- teaches the pick (over the exit, at the exit) and the place (over the rack, into the rack,
  both relative to the rack) by dragging the tool in the 3D scene (the simulated cell's
  freedrive: the arm follows through IK) and pressing Record;
- builds the rest by typing into the palette's search (subtrees of the library and nodes)
  and filling each node's ports in the inspector (waypoints from lists, parameters by name,
  the occupancy region's centre and radius typed in mm).

The plan built is resources/examples/tending.costar.json where it matters: the same tree
(kinds, operations, subtrees and their versions; node names are the worker's), the same
bindings (taught waypoints within 1 cm and 3 degrees of the shipped ones: a drag by hand
lands within a few millimetres), the same library
subtrees embedded, the same run settings; it validates. The 3D scene's drag is the panel's
public API (``gizmo_dragged`` / ``gizmo_released``, as tests/instructor_app/teach/sim/
test_scene_drag.py drives it): without a display's OpenGL the panel itself cannot show.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from PySide6.QtCore import Qt

from capabilities.sim.transforms import slerp
from engine.files import load_plan
from engine.plan_writer import write_atomic
from engine.spec import Binding, NodeSpec, PlanSpec
from engine.types import ParamType, Pose, Region, Waypoint, encode_value
from engine.validation import ERROR, validate_plan
from instructor_app.inspectors.rows import MODE_UNSET, MODE_VALUE
from instructor_app.main_window import MainWindow
from instructor_app.panels.scene_teach import SceneTeachLink
from instructor_app.runtime.session import CellSession
from tests.instructor_app.gui_driver import (
    CountingBot,
    bind_reference,
    choose,
    choose_index,
    click_node,
    import_waypoints,
    make_window,
    plan_panels,
    run_to_end,
    search_down_insert,
    set_plan_name,
    set_value,
)
from tests.instructor_app.teach.sim.test_scene_drag import SceneStandIn

pytestmark = pytest.mark.sim

LEFT = Qt.MouseButton.LeftButton
SHIPPED = Path(__file__).resolve().parents[2] / "resources" / "examples" / "tending.costar.json"
# Counted as CountingBot counts (a click, a key, a typed text, a list opened, a file chosen, a
# drag of the tool): 336 (396 before an unset input showed its value editor, so a value is
# chosen or typed there without choosing "value" from the mode list first; 677 before a library instance inserted took the bindings the
# plan's other instances give its ports of the same name and type: the second PickAtExit,
# PlaceOnRack, WaitForPart... and PartThenLeftPiece come bound; 683 before choosing "parameter" bound the output of its type
# offered first, so a name already offered needs no typing) for the whole set-up of the 49-node plan, its 4 waypoints taught
# by hand (each: a drag, the frame chosen, the rack typed once, a name, Record), 6 imported,
# and one run to see the rack. Most go to the inspector: the 15 subtree instances and 4
# moves take 34 waypoints, 5 regions (typed in mm) and 6 parameters by name (each: a mode
# and a value from lists), the 4 catches 7 settings, a parallel 1, the occupancy wait 2.
# (666 before PartThenLeftPiece took all three piece spots, to scrap a part it found
# that broke on the lift; 639 for 55 nodes before recovery took a part found at the exit to the rack and then the
# left piece of a scrap it cut short, PartThenLeftPiece, instead of feeling for the part
# by hand-built nodes and leaving it to the next cycle; 614 before a scrap cut short by the next part carried a held piece on into the bin;
# 605 before recovery put a held piece into the scrap bin before it let go and left a
# part felt at the exit to the next cycle's pick; 604 before the robot stepped out of view
# after feeling for a part left at the exit; 600 when the plan waited for the welding arm
# before each pick, by hand-built occupancy waits; 418 for the 28-node plan before a
# collision while recovering was caught, a scrap gave way to the next part and recovery
# cleared a stop and fed a part left at the exit.)
# A change that makes this set-up take more actions fails here.
MOST_ACTIONS = 336
TAUGHT = ("over exit", "at exit", "over rack", "into rack")  # by hand; the rest imported
# How near a pose taught by dragging the tool lands (the hand holds the tool until it is
# within 3 mm and 1 degree; the arm settles a few millimetres further as freedrive lets go):
# the taught waypoints are the shipped ones within this (m, degrees).
HAND, HAND_DEG = 0.01, 3.0
CARRY_Z = 0.3  # the hand carries the tool this high (m) between the exit and the rack

# What the worker does, in order. ("node", key, search text, expect, bindings): click the
# node remembered as ``key`` first (None: insert where the selection puts it: a leaf
# selected takes a next sibling, a composite or decorator a last child), type the search,
# insert the hit ``expect`` (an operation id, a kind or a subtree's name), remember the new
# node as ``key``. A binding is (port, "value" | "ref" | "region", value).
Bindings = list[tuple[str, str, Any]]
Step = tuple[str | None, str, str, str, Bindings]
REGION = Region((0.6, 0.28, 0.235), 0.05)  # where the welding arm swings down
PICK: Bindings = [("ABOVE", "value", "over exit"), ("AT", "value", "at exit")]
PLACE: Bindings = [
    ("RACK", "ref", "RACK_POSE"), ("OVER", "value", "over rack"), ("INTO", "value", "into rack"),
]  # fmt: skip
FIND: Bindings = [("RACK_POSE", "ref", "RACK_POSE")]
SAFE: Bindings = [("SAFE", "value", "observe")]
ARM_WAIT: Bindings = [("period", "value", 0.25), ("region", "region", REGION)]
NEXT_PART: Bindings = [("REGION", "region", REGION), *PICK]  # WaitForPart
PICK_ERRORS: Bindings = [("errors", "value", "failed, grasp_failed, object_lost, timeout"),
                         ("error", "value", "PICK_ERROR")]  # fmt: skip


def _to(waypoint: str, linear: bool = False) -> Bindings:
    return [("target", "value", waypoint), *([("mode", "value", "linear")] if linear else [])]


STEPS: list[Step] = [
    ("every part", "never stop", "force success", "force_success", []),
    (None, "collision", "catch", "catch", [("errors", "value", "protective_stop")]),
    (None, "part", "catch", "catch",
     [("errors", "value", "any"), ("error", "value", "LAST_ERROR")]),
    (None, "one part", "sequence", "sequence", []),
    (None, "in the gripper", "selector", "selector", []),
    (None, "holding", "is holding", "gripper.is_holding", []),
    (None, "pick", "catch", "catch", PICK_ERRORS),
    (None, "pick at exit", "PickAtExit", "subtree", PICK),
    (None, "regrasp or scrap", "selector", "selector", []),
    (None, "regrasp", "Regrasp", "subtree", PICK),
    (None, "scrapped", "force failure", "force_failure", []),
    (None, "scrap it", "sequence", "sequence", []),
    (None, "until the next part", "parallel", "parallel", [("success", "value", "any")]),
    (None, "discard", "DiscardToScrap", "subtree",
     [("ABOVE", "value", "over exit"), ("SCRAP", "value", "over scrap"),
      *((f"PIECE_{i}", "value", f"over piece {i}") for i in range(1, 4))]),
    (None, "arm comes", "occupied", "occupancy.wait_until_occupied",
     [*ARM_WAIT, ("timeout", "value", 600.0)]),
    ("scrap it", "held, scrapped", "force success", "force_success", []),
    (None, "carry it to the bin", "sequence", "sequence", []),
    (None, "a piece held", "is holding", "gripper.is_holding", []),
    (None, "to the bin", "move to", "motion.move_to", _to("over scrap")),
    (None, "into the bin", "gripper open", "gripper.open", []),
    ("one part", "where is the rack", "ReRegisterRack", "subtree", FIND),
    (None, "watching", "parallel", "parallel", []),
    (None, "place and step out", "sequence", "sequence", []),
    (None, "place", "catch", "catch",
     [("errors", "value", "protective_stop"), ("error", "value", "PLACE_ERROR")]),
    (None, "place on rack", "PlaceOnRack", "subtree", PLACE),
    (None, "again", "sequence", "sequence", []),
    (None, "clear the stop", "ClearStopAndBackOff", "subtree", SAFE),
    (None, "find again", "ReRegisterRack", "subtree", FIND),
    (None, "place again", "PlaceOnRack", "subtree", PLACE),
    ("place and step out", "out of view", "move to", "motion.move_to",
     [("target", "value", "observe")]),
    ("watching", "next part", "WaitForPart", "subtree", NEXT_PART),
    ("part", "recover", "sequence", "sequence", []),
    (None, "clear and back off", "ClearStopAndBackOff", "subtree", SAFE),
    (None, "what is held", "force success", "force_success", []),
    (None, "drop it over the bin", "sequence", "sequence", []),
    (None, "something held", "is holding", "gripper.is_holding", []),
    (None, "over the bin", "move to", "motion.move_to", _to("over scrap")),
    (None, "drop it", "gripper open", "gripper.open", []),
    ("what is held", "let go", "gripper open", "gripper.open", []),
    (None, "already, else next", "selector", "selector", []),
    (None, "part then piece", "PartThenLeftPiece", "subtree",
     [*PICK, ("OVER", "value", "over rack"), ("INTO", "value", "into rack"),
      *((f"PIECE_{i}", "value", f"over piece {i}") for i in range(1, 4)),
      ("SCRAP", "value", "over scrap"),
      ("REGION", "region", REGION), ("RACK_POSE", "ref", "RACK_POSE")]),
    ("already, else next", "the next one", "sequence", "sequence", []),
    (None, "step back", "move to", "motion.move_to", _to("observe")),
    (None, "then the next part", "WaitForPart", "subtree", NEXT_PART),
    ("collision", "clear it", "ClearStopAndBackOff", "subtree", SAFE),
]  # fmt: skip


@pytest.fixture
def tending_session(qapp: Any) -> Iterator[CellSession]:
    session = CellSession("sim", scene="tending", speed=None)  # as fast as the simulation goes
    assert session.open(), "the simulated tending cell did not open"
    yield session
    session.close()


def _insert(hands: Any, window: MainWindow, search: str, expect: str) -> str:
    """Search-to-insert; a subtree is asked for by its name (the hit is a library subtree)."""
    if expect == "subtree":
        node_id = search_down_insert(hands, window, search, "subtree")
        node = window.document.node(node_id)
        subtree = window.document.plan.subtree(node.subtree) if node.subtree else None
        assert subtree is not None and search in (subtree.name, subtree.id), node
        return node_id
    return search_down_insert(hands, window, search, expect)


def _bind(hands: Any, window: MainWindow, node_id: str, bindings: Bindings) -> None:
    for port, how, value in bindings:
        if how == "ref":
            bind_reference(hands, window, node_id, port, value)
        elif how == "region":
            _type_region(hands, window, node_id, port, value)
        else:
            row = window.views.inspector.port_row(port)
            if row.value_type is ParamType.WAYPOINT:
                value = next(w for w in window.document.plan.waypoints if w.name == value)
            set_value(hands, window, node_id, port, value)


def _type_region(hands: Any, window: MainWindow, node_id: str, port: str, region: Region) -> None:
    """Choose "value", then type the centre's x, y, z and the radius in mm, each with Enter."""
    window.views.canvas.select(node_id)
    binding = window.document.node(node_id).params.get(port)
    if binding is not None and binding.value == region:
        return  # bound so at insertion, as the plan's other instances are
    row = window.views.inspector.port_row(port)
    if row.mode != MODE_UNSET:  # unset, its editor shows: the centre typed there binds it
        choose_index(hands, row.mode_combo, MODE_VALUE)
    editor = row.editor
    for spin, metres in zip(
        (*editor.center_spins, editor.radius_spin), (*region.center, region.radius), strict=True
    ):
        spin.selectAll()
        hands.keyClicks(spin, f"{metres * 1000:.0f}")
        hands.keyClick(spin, Qt.Key.Key_Return)
    assert editor.value() == region, editor.value()


def _teach_by_drag(
    hands: CountingBot, window: MainWindow, scene: SceneStandIn, link: SceneTeachLink, to: Pose
) -> None:
    """Drag the tool in the 3D scene to ``to`` and let go (one action: the drag): up, across
    and down again, as a hand carries it over the cell; the arm follows the hand (the
    simulated cell's freedrive) and comes to rest where it let go.
    """
    hands.count("drag the tool")
    arm = window.session.cell.interfaces()["arm"]
    start = arm.tcp_pose()
    high = max(start.position[2], to.position[2], CARRY_Z)
    legs = [(start.position[0], start.position[1], high), (to.position[0], to.position[1], high)]
    corners = [start.position, *legs, to.position]
    spots = [
        tuple(a + (b - a) * k / 8 for a, b in zip(p0, p1, strict=True))
        for p0, p1 in itertools.pairwise(corners)
        if math.dist(p0, p1) > 1e-6
        for k in range(1, 9)
    ]
    path = [
        Pose(spot, slerp(start.orientation, to.orientation, i / len(spots)))  # type: ignore[arg-type]
        for i, spot in enumerate(spots, 1)
    ]
    for k, at in enumerate(path, 1):  # the hand does not outrun the arm, holds at the end
        scene.gizmo_dragged.emit(at)
        last = k == len(path)
        hands.waitUntil(
            lambda at=at, last=last: _near(
                arm.tcp_pose(), at, 0.003 if last else 0.02, 1.0 if last else 180.0
            ),
            timeout=30_000,
        )
    with hands.waitSignal(window.views.teacher.finished, timeout=60_000):
        scene.gizmo_released.emit(to)
    assert not link.dragging
    assert math.dist(arm.tcp_pose().position, to.position) < HAND, arm.tcp_pose()


def _angle_deg(a: Pose, b: Pose) -> float:
    dot = abs(sum(x * y for x, y in zip(a.orientation, b.orientation, strict=True)))
    return math.degrees(2 * math.acos(min(dot, 1.0)))


def _near(pose: Pose, to: Pose, metres: float, degrees: float) -> bool:
    return math.dist(pose.position, to.position) < metres and _angle_deg(pose, to) < degrees


def _record(hands: CountingBot, window: MainWindow, name: str, reference: str) -> Waypoint:
    """Record the tool's pose now: in the world, or relative to ``reference``."""
    panel = window.views.waypoints
    choose(hands, panel.frame_combo, "object" if reference else "world")
    if reference and panel.object_field.text() != reference:  # it keeps the last one
        panel.object_field.selectAll()
        hands.keyClicks(panel.object_field, reference)
    hands.keyClicks(panel.name_field, name)
    hands.mouseClick(panel.record_button, LEFT)
    return next(w for w in window.document.plan.waypoints if w.name == name)


def _target(shipped: PlanSpec, name: str, window: MainWindow) -> Pose:
    """Where a shipped waypoint puts the tool now (relative ones: against the rack seen)."""
    waypoint = next(w for w in shipped.waypoints if w.name == name)
    assert waypoint.pose is not None
    if not waypoint.reference:
        return waypoint.pose
    rack = window.views.teacher.interface("world").best(waypoint.reference)
    assert rack is not None, "the rack was not seen"
    return rack.pose.compose(waypoint.pose)


def shape(node: NodeSpec) -> tuple[Any, ...]:
    """A node and its subtree without ids and names: kind, op, subtree, bindings."""
    params = {port: _binding(b) for port, b in sorted(node.params.items())}
    subtree = (node.subtree.id, node.subtree.version) if node.subtree else None
    return (node.kind, node.op, subtree, params, tuple(shape(c) for c in node.children))


def _binding(binding: Binding) -> tuple[Any, ...]:
    if binding.is_ref:
        return ("ref", binding.ref)
    value = binding.value
    if isinstance(value, Waypoint):  # compared by name here, by value in _same_waypoint
        return ("waypoint", value.name)
    return (binding.type, encode_value(value) if binding.type else value)


def _same_waypoint(ours: Waypoint, shipped: Waypoint) -> None:
    assert (ours.frame, ours.reference) == (shipped.frame, shipped.reference), ours
    assert ours.pose is not None and shipped.pose is not None
    assert math.dist(ours.pose.position, shipped.pose.position) < HAND, (ours, shipped)
    assert _angle_deg(ours.pose, shipped.pose) < HAND_DEG, (ours, shipped)


def test_our_tending_plan_set_up_from_the_library_by_hand_as_on_site(
    qtbot: Any, tending_session: CellSession, tmp_path: Path, record_property: Any
) -> None:
    registry = tending_session.registry
    shipped = load_plan(SHIPPED, registry.aliases())
    handed_over = tmp_path / "tending.waypoints.json"  # the integrator's file
    write_atomic(
        handed_over, _waypoints_file([w for w in shipped.waypoints if w.name not in TAUGHT])
    )
    window = make_window(qtbot, tending_session, tmp_path)
    scene = SceneStandIn()  # the 3D scene's drag API (no OpenGL here)
    link = SceneTeachLink(scene, window.views.teacher, window.views.waypoints)
    qtbot.waitUntil(lambda: scene.gizmo is not None)
    hands = CountingBot(qtbot)
    nodes: dict[str, str] = {}

    set_plan_name(hands, window, shipped.name)
    hands.mouseClick(plan_panels(window)[0].reset_box, LEFT)
    import_waypoints(hands, window, handed_over)
    nodes["root"] = _insert(hands, window, "sequence", "sequence")
    nodes["find"] = _insert(hands, window, "ReRegisterRack", "subtree")
    _bind(hands, window, nodes["find"], FIND)
    assert run_to_end(hands, window, 60_000).status.name == "SUCCESS"  # the rack is seen
    hands.count("click Run")

    for name in TAUGHT:
        waypoint = next(w for w in shipped.waypoints if w.name == name)
        _teach_by_drag(hands, window, scene, link, _target(shipped, name, window))
        _record(hands, window, name, waypoint.reference or "")

    click_node(hands, window, nodes["find"])
    nodes["first part"] = _insert(hands, window, "WaitForPart", "subtree")
    _bind(hands, window, nodes["first part"], NEXT_PART)
    nodes["every part"] = _insert(hands, window, "iterator", "iterator")
    for parent, key, search, expect, bindings in STEPS:
        if parent is not None:
            click_node(hands, window, nodes[parent])
        nodes[key] = _insert(hands, window, search, expect)
        _bind(hands, window, nodes[key], bindings)
    actions = len(hands.actions)
    print(f"tending set up by hand: {actions} user actions for {len(nodes)} nodes")
    record_property("tending_setup_actions", actions)  # bench/teach.py reports it
    assert actions <= MOST_ACTIONS, hands.actions

    built = window.document.plan
    assert built.tree is not None and shipped.tree is not None
    assert shape(built.tree) == shape(shipped.tree)
    assert sorted((s.id, s.version) for s in built.subtrees) == sorted(
        (s.id, s.version) for s in shipped.subtrees
    )
    assert (built.run_policy, built.reset_cell, built.name) == (
        shipped.run_policy, shipped.reset_cell, shipped.name,
    )  # fmt: skip
    assert {w.name for w in built.waypoints} == {w.name for w in shipped.waypoints}
    for name in TAUGHT:
        ours = next(w for w in built.waypoints if w.name == name)
        _same_waypoint(ours, next(w for w in shipped.waypoints if w.name == name))
    assert not [p for p in validate_plan(built, registry) if p.severity == ERROR]
    window.views.validation.revalidate()
    assert window.problems_label.text() == "No problems"


def _waypoints_file(waypoints: list[Waypoint]) -> bytes:
    import json

    document = {
        "format": "costar-waypoints",
        "format_version": 1,
        "waypoints": [encode_value(w) for w in waypoints],
    }
    return json.dumps(document, indent=2).encode("utf-8")
