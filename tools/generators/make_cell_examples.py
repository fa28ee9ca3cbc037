"""Write the example plans that run on the simulated cell (reproducible byte for byte).

``cup_to_bin.costar.json`` is the paper's Figure 3 on the simulated cell, taught as a worker
does with the shipped Pick and Place subtrees (``make_pick_place``): "Pick cup" steps the arm
out of the shoulder camera's view, finds the cup and the waste bin through their ArUco
markers, checks the cup was found and grasps it at its pose with the grasp its object model
carries (``gripper.grasp``: approach, descend, close, lift); "Place over bin" drops it over
the bin; when the cup is not visible it waits and tries again (the root runs until
success). Its waypoints are also written to ``cup_to_bin.waypoints.json`` beside it.
``cup_to_bin_vision.costar.json`` keeps Figure 3's operation leaves (found, both poses,
grasp, move, release), finding the objects by perception.

``tending_paper.costar.json`` is the paper's wire-bender tending plan (section V-B) on the
``tending`` scene: look up the rack by its marker, then for each part wait until the bender's
welding arm swings into an occupancy region and back out, pick the part at the exit with one
taught waypoint, check it is held, drop it into the rack's tote; on any failure drop what is held, step
back and wait for the operator's Continue (the paper stopped and reset the robot).
Usage: python -m tools.generators.make_cell_examples
"""

from __future__ import annotations

from capabilities.waypoints import WaypointLibrary, waypoints_path_for
from engine.files import save_plan
from engine.spec import NodeKind, NodeSpec, PlanSpec, RunPolicy
from engine.types import (
    JointConfig,
    ParamType,
    Pose,
    Region,
    Waypoint,
    WaypointFrame,
)
from tools.generators import RESOURCES, make_pick_place
from tools.generators.plan_builder import CELL_EXAMPLES, PlanBuilder, fixed, obj, stable_id

HERE = RESOURCES / "examples"  # where the plans are written

# The tool pointing straight down (tool z along world -z).
DOWN = (1.0, 0.0, 0.0, 0.0)
# A joint configuration taught by hand that keeps the arm out of the shoulder camera's view.
OBSERVE_JOINTS = (1.2, -1.9, 2.0, -1.6, -1.57, 0.0)
BIN_DROP_Z = 0.36  # m above the bin's bottom: 14 cm over its 22 cm rim


def waypoints() -> list[Waypoint]:
    """The taught waypoints of the Figure 3 plans on the simulated cell."""
    return [
        Waypoint("observe", WaypointFrame.JOINTS, joints=JointConfig(OBSERVE_JOINTS)),
        Waypoint(
            "over bin",
            WaypointFrame.OBJECT,
            Pose((0.0, 0.0, BIN_DROP_Z), DOWN),
            reference="waste_bin",
        ),
    ]


# The tending cell: the TCP over the bender's exit, turned as the bender drops its parts (the
# weld bead along world x, the fingers closing across it), 17 mm up: the fingertips 2 mm
# above the table. Taught once, like the paper's one waypoint per part.
EXIT_DOWN = (0.0, 1.0, 0.0, 0.0)
EXIT_XY = (0.55, 0.28)
GRASP_Z, ABOVE_Z = 0.017, 0.12
# The welding arm over the exit when it releases a part (the occupancy region).
ARM_REGION = Region((0.6, 0.28, 0.235), 0.05)
# Over the middle of the rack's tote (rim 200 mm high): the fingertips 20 mm above its rim.
TOTE = (0.04, 0.0)
RACK_DROP_Z, OVER_RACK_Z = 0.235, 0.32


def tending_waypoints() -> list[Waypoint]:
    """The taught waypoints of the tending example on the simulated cell."""
    return [
        Waypoint("observe", WaypointFrame.JOINTS, joints=JointConfig(OBSERVE_JOINTS)),
        Waypoint("over exit", WaypointFrame.WORLD, Pose((*EXIT_XY, ABOVE_Z), EXIT_DOWN)),
        Waypoint("at exit", WaypointFrame.WORLD, Pose((*EXIT_XY, GRASP_Z), EXIT_DOWN)),
        Waypoint(
            "over rack",
            WaypointFrame.OBJECT,
            Pose((*TOTE, OVER_RACK_Z), DOWN),
            reference="tending_rack",
        ),
        Waypoint(
            "into rack",
            WaypointFrame.OBJECT,
            Pose((*TOTE, RACK_DROP_Z), DOWN),
            reference="tending_rack",
        ),
    ]


class _Cell(PlanBuilder):
    """The cell examples' nodes (ids in their own namespace), and moves to taught waypoints."""

    def __init__(self, example: str, wps: list[Waypoint] | None = None) -> None:
        super().__init__(CELL_EXAMPLES, example)
        self.wps = {w.name: w for w in (wps or waypoints())}

    def move_to(
        self, name: str, waypoint: str, reference: str = "", linear: bool = False
    ) -> NodeSpec:
        """``motion.move_to`` the taught waypoint named ``waypoint``."""
        return self.move(name, self.wps[waypoint], reference, linear)


def _figure3_tree(m: _Cell, finder: str, detect: str, title: str) -> NodeSpec:
    """The Figure 3 tree; ``finder`` is the capability that finds objects (markers or
    perception) and ``detect`` its operation that looks.
    """
    transfer = m.node(
        NodeKind.SEQUENCE,
        "transfer",
        m.op(f"{finder}.object_found", "CUP found", object=obj("cup")),
        m.op(f"{finder}.object_pose", "pose of CUP", object=obj("cup"), pose="CUP_POSE"),
        m.op(f"{finder}.object_pose", "pose of BIN", object=obj("waste_bin"), pose="BIN_POSE"),
        m.op("gripper.grasp", "grasp CUP at CUP_POSE", object=obj("cup"), pose="CUP_POSE"),
        m.move_to("move to BIN_POSE", "over bin", "BIN_POSE"),
        m.op("gripper.open", "release"),
    )
    wait = m.node(
        NodeKind.FORCE_FAILURE,
        "then look again",
        m.node(NodeKind.WAIT, "WAIT", seconds=1.0),
    )
    return m.node(
        NodeKind.SEQUENCE,
        title,
        m.move_to("step out of view", "observe"),
        m.op(f"{finder}.{detect}", "detect CUP and BIN"),  # the shoulder camera, by default
        m.node(NodeKind.SELECTOR, "transfer or wait", transfer, wait),
    )


# The Figure 3 plans wait a second and look again while the cup is not there: they give up
# after a minute of looks that fail the same way, not after the default 5.
LOOKS = 60


def _figure3_plan(name: str, detect: tuple[str, str], root: str, title: str, doc: str) -> PlanSpec:
    """Figure 3's plan ``name`` on the simulated cell, finding the cup with ``detect``."""
    tree = _figure3_tree(_Cell(name), *detect, root)
    return PlanSpec(
        tree,
        title,
        doc,
        RunPolicy.UNTIL_SUCCESS,
        give_up_after=LOOKS,
        waypoints=waypoints(),
        objects=["cup", "waste_bin"],
        reset_cell=True,  # each run in the Instructor starts from the scene's seed
        id=stable_id(CELL_EXAMPLES, name),
    )


def cup_to_bin() -> PlanSpec:
    """Figure 3 through the ArUco markers on the cup and the bin, taught with the shipped
    Pick and Place subtrees (each names what it takes: "Pick cup", "Place over bin").
    """
    m = _Cell("cup_to_bin")
    pick, place = make_pick_place.pick(), make_pick_place.place()
    transfer = m.node(
        NodeKind.SEQUENCE,
        "Sequence",
        m.instance(pick, "Pick cup", OBJECT=obj("cup")),
        m.instance(place, "Place over bin", PLACE=fixed(m.wps["over bin"], ParamType.WAYPOINT)),
    )
    wait = m.node(
        NodeKind.FORCE_FAILURE, "Force failure", m.node(NodeKind.WAIT, "Wait", seconds=1.0)
    )
    return PlanSpec(
        m.node(NodeKind.SELECTOR, "Selector", transfer, wait),
        "Cup to bin (Figure 3, simulated cell)",
        "The paper's Figure 3 on the simulated cell, taught with the shipped Pick and Place "
        "subtrees: Pick cup steps the arm out of the shoulder camera's view (with the arm "
        "over the table the camera cannot see the cup, and the look says 'the arm hides the "
        "table from the shoulder camera'), finds the cup and the waste bin through their "
        "markers, checks the cup was found and grasps it at its pose with the grasp of its "
        "object model; Place over bin drops it at the waypoint taught relative to the bin. "
        "When the cup is not visible the selector falls back to Wait (forced to fail) and "
        "the root, which runs until success, looks again (it gives up after 60 looks in a "
        "row that fail the same way: over a minute without a cup). Run it with: costar run "
        "example:cup_to_bin --seed N. Runs to SUCCESS.",
        RunPolicy.UNTIL_SUCCESS,
        give_up_after=LOOKS,
        waypoints=waypoints(),
        objects=["cup", "waste_bin"],
        reset_cell=True,  # each run in the Instructor starts from the scene's seed
        id=stable_id(CELL_EXAMPLES, "cup_to_bin"),
        subtrees=[pick, place],
    )


def cup_to_bin_vision() -> PlanSpec:
    """Figure 3 with model-based recognition (perception) in place of the ArUco markers."""
    return _figure3_plan(
        "cup_to_bin_vision",
        ("perception", "detect_objects"),
        "cup to bin (vision)",
        "Cup to bin, by vision (Figure 3, simulated cell)",
        "The paper's Figure 3 with model-based recognition instead of markers: with the arm "
        "stepped out of its view (over the table it hides the cup, and the look says 'the arm "
        "hides the table from the shoulder camera'), the shoulder camera's point cloud is matched to the cup and waste-bin models, the plan checks the "
        "cup was found, queries both poses, grasps the cup at its pose with the grasp of its "
        "object model and drops it over the bin; when the cup is not recognised it waits and looks "
        "again (60 times in a row at most). Run it with: costar run example:cup_to_bin_vision --seed N.",
    )


def _tending_cycle(m: _Cell) -> NodeSpec:
    """One part: the arm swings down and back up, pick at the exit, out of the arm's swing,
    onto the rack.
    """
    region = fixed(ARM_REGION, ParamType.REGION)
    long = fixed(600.0, ParamType.DURATION)
    # Four looks a second see the arm, which stays over the exit for more than a second.
    period = fixed(0.25, ParamType.DURATION)
    return m.node(
        NodeKind.SEQUENCE,
        "one part",
        m.op(
            "occupancy.wait_until_occupied",
            "wait for the welding arm",
            region=region,
            timeout=long,
            period=period,
        ),
        m.op(
            "occupancy.wait_until_empty",
            "wait until the arm is back up",
            region=region,
            period=period,
        ),
        m.move_to("over the exit", "over exit"),
        m.move_to("down to the part", "at exit", linear=True),
        m.op("gripper.close", "close on the part"),
        m.op("gripper.is_holding", "part in the gripper"),
        m.move_to("lift the part", "over exit", linear=True),
        m.op("gripper.is_holding", "part still held"),
        # As our plan does (its ReRegisterRack): out by the observe joints first. The joint
        # path from over the exit straight to the rack turns the wrist towards the welding
        # arm's swing (6.7 cm from the resting arm, against 11 cm by observe).
        m.move_to("out of the welding arm's swing", "observe"),
        m.move_to("over the rack", "over rack", "RACK_POSE"),
        m.move_to("down over the tote", "into rack", "RACK_POSE", linear=True),
        m.op("gripper.open", "let go into the tote"),
        m.move_to("up from the rack", "over rack", "RACK_POSE", linear=True),
        m.move_to("step out of view", "observe"),
    )


def tending_paper() -> PlanSpec:
    """The paper's wire-bender tending plan: no error handling but the operator's reset."""
    m = _Cell("tending_paper", tending_waypoints())
    operator = m.node(
        NodeKind.SEQUENCE,
        "stop and wait for the operator",
        m.op("gripper.open", "drop what is held"),
        m.move_to("step back", "observe"),
        m.op("collaboration.wait_for_button", "operator resets the cell, presses Continue"),
    )
    tree = m.node(
        NodeKind.SEQUENCE,
        "tend the wire bender",
        m.move_to("step out of view", "observe"),
        m.op("markers.detect_markers", "find the rack"),
        m.op("markers.object_pose", "pose of RACK", object=obj("tending_rack"), pose="RACK_POSE"),
        m.node(
            NodeKind.ITERATOR,
            "every part",
            m.node(NodeKind.SELECTOR, "part or operator", _tending_cycle(m), operator),
        ),
    )
    return PlanSpec(
        tree,
        "Wire-bender tending, the paper's plan (section V-B, simulated cell)",
        "The paper's deployment at Marlin Steel on the 'tending' scene: the rack is found by "
        "its marker once; for each part the robot waits until the bender's welding arm swings "
        "into an occupancy region and back out, picks the wireform at the exit with one taught "
        "waypoint, checks it is held before and after lifting, steps out of the welding arm's "
        "swing and drops it into the rack's tote. On any "
        "failure (a bad weld, a slipping grasp, a part not there) it drops what it holds, steps "
        "back and waits for the operator's Continue while the bender keeps producing. Runs until "
        "stopped. It is taught on the simulated scene tending, which the simulated cell opens "
        "for it. Run it with: costar run example:tending_paper.",
        RunPolicy.ONCE,
        waypoints=tending_waypoints(),
        objects=["tending_rack"],
        reset_cell=True,  # each run in the Instructor starts from the scene's seed
        scene="tending",
        id=stable_id(CELL_EXAMPLES, "tending_paper"),
    )


def main() -> None:
    """Write the simulated cell's example plans."""
    path = HERE / "cup_to_bin.costar.json"
    save_plan(cup_to_bin(), path)
    WaypointLibrary(waypoints()).save(waypoints_path_for(path))
    print(f"wrote {path.name} and its waypoints")
    vision = HERE / "cup_to_bin_vision.costar.json"
    save_plan(cup_to_bin_vision(), vision)
    print(f"wrote {vision.name}")
    tending = HERE / "tending_paper.costar.json"
    save_plan(tending_paper(), tending)
    WaypointLibrary(tending_waypoints()).save(waypoints_path_for(tending))
    print(f"wrote {tending.name} and its waypoints")


if __name__ == "__main__":
    main()
