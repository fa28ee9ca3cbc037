"""Write the shipped Pick and Place subtrees, byte for byte (issue 26: teaching in fewer steps).

``resources/library/pick_place``: as Rethink Intera's templates and PolyScope's wizards do,
a pick is one node that takes an object and a place one node that takes a place.

- Pick (OBJECT): step out of the shoulder camera's view, look (the markers), check OBJECT was
  seen, query its pose and grasp it there with its object model's first grasp
  (``gripper.grasp``: approach, down, close, check, lift). Fails at once when OBJECT is not
  seen, so a selector can fall back to waiting and looking again (Figure 3).
- Place (PLACE): move to a waypoint (one relative to an object follows that object's latest
  detected pose; when that object was not seen, step out of view and look again first) and
  open the gripper.

Usage: python -m tools.generators.make_pick_place
"""

from __future__ import annotations

from engine.spec import NodeKind, SubtreePort, SubtreeSpec
from engine.types import JointConfig, ParamType, Waypoint, WaypointFrame
from tools.generators import RESOURCES
from tools.generators.plan_builder import PICK_PLACE, PlanBuilder, port, subtree, write_library

LIBRARY = RESOURCES / "library" / "pick_place"
# The simulated cell's taught pose that keeps the arm out of the shoulder camera's view.
OBSERVE_JOINTS = (1.2, -1.9, 2.0, -1.6, -1.57, 0.0)


def observe() -> Waypoint:
    """Where the shoulder camera sees the table (joints), Pick's LOOK_FROM by default."""
    return Waypoint("observe", WaypointFrame.JOINTS, joints=JointConfig(OBSERVE_JOINTS))


def _look_from() -> SubtreePort:
    """The LOOK_FROM input: where the arm is out of the camera's view (observe by default)."""
    return port(
        "LOOK_FROM",
        ParamType.WAYPOINT,
        "where the arm is out of the shoulder camera's view",
        observe(),
    )


def pick() -> SubtreeSpec:
    """The Pick subtree: look, find OBJECT and grasp it with its model's grasp."""
    m = PlanBuilder(PICK_PLACE, "pick")
    root = m.id()
    tree = m.node(
        NodeKind.SEQUENCE,
        "Pick",
        m.move("step out of view", "LOOK_FROM"),
        m.op("markers.detect_markers", "look"),  # the shoulder camera, by default
        m.op("markers.object_found", "OBJECT seen", object="OBJECT"),
        m.op("markers.object_pose", "pose of OBJECT", object="OBJECT", pose="POSE"),
        m.op("gripper.grasp", "grasp OBJECT at POSE", object="OBJECT", pose="POSE"),
        node_id=root,
    )
    return subtree(
        "pick_place.pick",
        "Pick",
        "Steps out of the shoulder camera's view, looks for the markers, checks the object "
        "was seen and grasps it at its pose with its object model's first grasp (approach, "
        "down, close, check, lift). Fails at once when the object is not seen.",
        tree,
        inputs=[
            port("OBJECT", ParamType.OBJECT, "the object to take (its model has the grasp)"),
            _look_from(),
        ],
        outputs=[port("POSE", ParamType.POSE, "where the object was taken")],
    )


def place() -> SubtreeSpec:
    """The Place subtree: to a waypoint (looking again first when where it is was not seen),
    then let go.
    """
    m = PlanBuilder(PICK_PLACE, "place")
    root = m.id()
    tree = m.node(
        NodeKind.SEQUENCE,
        "Place",
        m.node(
            NodeKind.SELECTOR,
            "to PLACE, or look and go",
            m.move("to PLACE", "PLACE"),
            m.node(
                NodeKind.SEQUENCE,
                "look again",
                m.move("step out of view", "LOOK_FROM"),
                m.op("markers.detect_markers", "look"),
                m.move("to PLACE", "PLACE"),
            ),
        ),
        m.op("gripper.open", "let go"),
        node_id=root,
    )
    return subtree(
        "pick_place.place",
        "Place",
        "Moves what the gripper holds to a waypoint and lets go. A waypoint taught relative "
        "to an object (over the bin) follows where that object was last seen; when it was not "
        "seen (or the move fails), the arm steps out of the shoulder camera's view, looks "
        "again and goes.",
        tree,
        inputs=[
            port("PLACE", ParamType.WAYPOINT, "where the tool lets go"),
            _look_from(),
        ],
    )


def library() -> list[SubtreeSpec]:
    """The pick-and-place subtrees, in the order they are written."""
    return [pick(), place()]


def main() -> None:
    """Write the subtrees."""
    write_library(LIBRARY, library(), RESOURCES)


if __name__ == "__main__":
    main()
