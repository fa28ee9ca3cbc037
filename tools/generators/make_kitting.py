"""Write the shipped kitting library and plan (the paper's section V-A, Figure 7), byte for byte.

Five subtrees go to ``resources/library/kitting``: Handoff (wait for the worker's bin, seen by
its markers), Unholster and Holster (the suction tool), Transfer (find a plate by its shape in
the shoulder camera's point cloud, suck it up with a waypoint taught relative to it, put it
down with a waypoint taught relative to the bin) and Return (take the bin by its wall with the
gripper and put it down elsewhere). ``resources/examples/kitting.costar.json`` composes them
as in Figure 7: Handoff, Unholster, one each of the 3-, 4- and 8-hole plates into the bin
(three instances of Transfer, reparameterized as in Figure 6, under a selector that takes
whichever plate is still on the table), Holster, Return.

Usage: python -m tools.generators.make_kitting
"""

from __future__ import annotations

import math
from typing import Any

from engine.files import save_plan
from engine.spec import (
    NodeKind,
    NodeSpec,
    PlanSpec,
    RunPolicy,
    SubtreeSpec,
)
from engine.types import JointConfig, ObjectModel, ParamType, Pose, Region, Waypoint, WaypointFrame
from tools.generators import RESOURCES
from tools.generators.plan_builder import (
    KITTING,
    PlanBuilder,
    fixed,
    obj,
    port,
    stable_id,
    subtree,
    write_library,
)

HERE = RESOURCES / "examples"  # where the plans are written
LIBRARY = RESOURCES / "library" / "kitting"

DOWN = (1.0, 0.0, 0.0, 0.0)  # the tool pointing straight down
OBSERVE_JOINTS = (1.2, -1.9, 2.0, -1.6, -1.57, 0.0)  # out of the shoulder camera's view
HOVER = 0.1  # m the tool travels straight down from a hover waypoint to the part
PLACE_DROP = 0.1  # m down from the place hover waypoint (above the bin walls) before letting go
PLATE_THICKNESS = {"plate_3_holes": 0.004, "plate_4_holes": 0.005, "plate_8_holes": 0.006}
# Where each plate goes in the bin (bin frame, m) and its turn there: side by side along the
# bin's length, the long plates turned across it.
SLOTS = {
    "plate_8_holes": ((-0.115, 0.0), math.pi / 2),
    "plate_4_holes": ((0.0, 0.0), 0.0),
    "plate_3_holes": ((0.12, 0.0), math.pi / 2),
}
BIN_FLOOR = 0.005  # m: the bin's floor thickness
WALL_Y = 0.1275  # m: the bin's long wall, from its centre
WALL_GRASP_Z = 0.06  # m: gripper TCP height on the wall (its top is at 0.08)
HANDOFF_AREA = Region((0.56, 0.27, 0.0), 0.1)  # where the worker puts the bin (sphere)
RETURN_AT = (0.5, -0.12)  # m: where the bin goes back (its centre), bin turned as the world


def _turned(yaw: float) -> tuple[float, float, float, float]:
    """DOWN turned ``yaw`` about the vertical (x, y, z, w)."""
    return (math.cos(yaw / 2), -math.sin(yaw / 2), 0.0, 0.0)


def observe() -> Waypoint:
    """The joint-space waypoint from which the shoulder camera sees the table."""
    return Waypoint("observe", WaypointFrame.JOINTS, joints=JointConfig(OBSERVE_JOINTS))


def pick_waypoint(plate: str) -> Waypoint:
    """Hover above the plate's centre, relative to the plate (the Figure 6 pick position)."""
    z = PLATE_THICKNESS[plate] - 0.0005 + HOVER
    return Waypoint(
        f"above {plate}", WaypointFrame.OBJECT, Pose((0.0, 0.0, z), DOWN), reference=plate
    )


def place_waypoint(plate: str) -> Waypoint:
    """Hover above the plate's slot, relative to the bin (the Figure 6 place position)."""
    (x, y), yaw = SLOTS[plate]
    z = BIN_FLOOR + PLATE_THICKNESS[plate] + 0.004 + PLACE_DROP
    return Waypoint(
        f"{plate} slot", WaypointFrame.OBJECT, Pose((x, y, z), _turned(yaw)), reference="kit_bin"
    )


class _Maker(PlanBuilder):
    """The kitting generator's nodes (ids in its own namespace), and a straight vertical move."""

    def __init__(self, scope: str) -> None:
        super().__init__(KITTING, scope)

    def vertical(self, name: str, dz: str | float) -> NodeSpec:
        return self.op(
            "motion.move_relative",
            name,
            dz=dz if isinstance(dz, str) else fixed(dz, ParamType.NUMBER),
        )


def _subtree(key: str, name: str, description: str, tree: NodeSpec, **ports: Any) -> SubtreeSpec:
    return subtree(f"kitting.{key}", name, description, tree, **ports)


def handoff() -> SubtreeSpec:
    """The Handoff subtree: step out of view and wait until a person hands over the bin."""
    m = _Maker("handoff")
    tree = m.node(
        NodeKind.SEQUENCE,
        "Handoff",
        m.move("step out of view", observe()),
        m.op(
            "collaboration.wait_for_handoff",
            "wait for the bin",
            object="OBJECT",
            region="AREA",
            timeout=fixed(300.0, ParamType.DURATION),
            settle=fixed(0.5, ParamType.DURATION),
            pose="POSE",
        ),
    )
    return _subtree(
        "handoff",
        "Handoff",
        "Waits for the worker to put an object (the kit bin) down in an area, seen by its "
        "markers in the shoulder camera, and tells where it is.",
        tree,
        inputs=[
            port("OBJECT", ParamType.OBJECT, "what the worker hands in", ObjectModel("kit_bin")),
            port("AREA", ParamType.REGION, "where the worker puts it"),
        ],
        outputs=[port("POSE", ParamType.POSE, "where it was put")],
    )


def _from_home(name: str, title: str, step: str, doc: str) -> SubtreeSpec:
    """Subtree ``name``: go home, then ``tool.<name>`` (the holster's approach is taught
    from home).
    """
    m = _Maker(name)
    tree = m.node(
        NodeKind.SEQUENCE, title, m.op("motion.go_home", "home"), m.op(f"tool.{name}", step)
    )
    return _subtree(name, title, doc, tree)


def unholster() -> SubtreeSpec:
    """The Unholster subtree: take the suction tool with the gripper."""
    return _from_home(
        "unholster",
        "Unholster",
        "take the suction tool",
        "Takes the suction tool out of its holster with the gripper.",
    )


def holster() -> SubtreeSpec:
    """The Holster subtree: put the suction tool back."""
    return _from_home(
        "holster",
        "Holster",
        "put the suction tool back",
        "Puts the suction tool back in its holster; the gripper is free.",
    )


def transfer() -> SubtreeSpec:
    """The Transfer subtree: find a plate on the table and put it into the kit bin."""
    m = _Maker("transfer")
    tree = m.node(
        NodeKind.SEQUENCE,
        "Transfer",
        m.move("step out of view", observe()),
        m.op("perception.detect_objects", "look", camera=fixed("shoulder", ParamType.TEXT)),
        m.op("perception.object_found", "OBJECT on the table", object="OBJECT"),
        m.op("perception.object_pose", "pose of OBJECT", object="OBJECT", pose="PART_POSE"),
        m.node(
            NodeKind.INVERTER,
            "not in the bin yet",
            m.op(
                "predicates.touching",
                "OBJECT in the bin",
                object_a="OBJECT",
                object_b=obj("kit_bin"),
            ),
        ),
        m.op("motion.go_home", "clear of the table"),  # from the camera pose, over the bin
        m.move("above OBJECT", "PICK", "PART_POSE"),
        m.vertical("down to OBJECT", -HOVER),
        m.op("tool.suction_on", "suck"),
        m.op("tool.has_part", "holding OBJECT"),
        m.vertical("lift", HOVER),
        m.move("above the slot", "PLACE", "BIN"),
        m.vertical("down into the bin", -PLACE_DROP),
        m.op("tool.suction_off", "release"),
        m.vertical("up", PLACE_DROP),
    )
    return _subtree(
        "transfer",
        "Transfer",
        "Finds a part by its shape, sucks it up with a waypoint taught relative to it and puts "
        "it down with a waypoint taught relative to the bin. Fails at once when the part is not "
        "on the table (not seen, or already in the bin).",
        tree,
        inputs=[
            port("OBJECT", ParamType.OBJECT, "the part to move"),
            port("PICK", ParamType.WAYPOINT, "the tool 10 cm above the part, relative to it"),
            port(
                "PLACE",
                ParamType.WAYPOINT,
                "the tool above where the part goes, relative to the bin",
            ),
            port("BIN", ParamType.POSE, "where the bin is"),
        ],
    )


def return_bin() -> SubtreeSpec:
    """The Return subtree: grasp the bin by its wall and put it down at the return place."""
    m = _Maker("return")
    tree = m.node(
        NodeKind.SEQUENCE,
        "Return",
        m.op("gripper.open", "open"),
        m.move("above the wall", "GRASP", "BIN"),
        m.vertical("down to the wall", -HOVER),
        m.op("gripper.close", "grasp the wall"),
        m.op("gripper.is_holding", "holding the bin"),
        m.vertical("lift", HOVER),
        m.move("above the new place", "DEST"),
        m.vertical("put it down", -HOVER),
        m.op("gripper.open", "let go"),
        m.vertical("up", HOVER),
        m.move("step out of view", observe()),
    )
    return _subtree(
        "return",
        "Return",
        "Takes the bin by its wall with the gripper and puts it down at a new place.",
        tree,
        inputs=[
            port("BIN", ParamType.POSE, "where the bin is"),
            port(
                "GRASP", ParamType.WAYPOINT, "the gripper 10 cm above the wall, relative to the bin"
            ),
            port("DEST", ParamType.WAYPOINT, "the gripper 10 cm above where it lets go (world)"),
        ],
    )


def library() -> list[SubtreeSpec]:
    """The kitting subtrees, in the order they are written."""
    return [handoff(), unholster(), transfer(), holster(), return_bin()]


def wall_grasp() -> Waypoint:
    """Above the grasp on the kit bin's wall, relative to the bin."""
    return Waypoint(
        "above the bin's wall",
        WaypointFrame.OBJECT,
        Pose((0.0, WALL_Y, WALL_GRASP_Z + HOVER), DOWN),
        reference="kit_bin",
    )


def return_place() -> Waypoint:
    """Above where the bin is put down after kitting (world frame)."""
    x, y = RETURN_AT
    at = Pose((x, y + WALL_Y, WALL_GRASP_Z + HOVER + 0.003), DOWN)
    return Waypoint("above the return place", WaypointFrame.WORLD, at)


def kitting() -> PlanSpec:
    """The kitting plan: hand-off, plates into the bin, return the bin."""
    subs = {s.id.split(".")[1]: s for s in library()}
    m = _Maker("kitting")

    def transfer_of(plate: str, label: str) -> NodeSpec:
        return m.instance(
            subs["transfer"],
            f"Transfer {label}",
            OBJECT=obj(plate),
            PICK=fixed(pick_waypoint(plate), ParamType.WAYPOINT),
            PLACE=fixed(place_waypoint(plate), ParamType.WAYPOINT),
            BIN="BIN_POSE",
        )

    plates = m.node(
        NodeKind.REPEAT,
        "one of each plate",
        m.node(
            NodeKind.SELECTOR,
            "whichever plate is on the table",
            transfer_of("plate_3_holes", "3-hole plate"),
            transfer_of("plate_4_holes", "4-hole plate"),
            transfer_of("plate_8_holes", "8-hole plate"),
        ),
        count=3,
    )
    tree = m.node(
        NodeKind.SEQUENCE,
        "Kitting",
        m.instance(
            subs["handoff"], "Handoff", AREA=fixed(HANDOFF_AREA, ParamType.REGION), POSE="BIN_POSE"
        ),
        m.instance(subs["unholster"], "Unholster"),
        plates,
        m.instance(subs["holster"], "Holster"),
        m.instance(
            subs["return"],
            "Return",
            BIN="BIN_POSE",
            GRASP=fixed(wall_grasp(), ParamType.WAYPOINT),
            DEST=fixed(return_place(), ParamType.WAYPOINT),
        ),
    )
    return PlanSpec(
        tree,
        "Kitting (Figure 7, simulated cell)",
        "The paper's kitting task composed from the shipped library: wait for the worker to hand "
        "the kit bin in, take the suction tool, put one each of the 3-, 4- and 8-hole plates into "
        "the bin (whichever is on the table), holster the tool and return the bin. It is taught "
        "on the simulated scene kitting_handoff (a worker hands the bin in), which the simulated "
        "cell opens for it. Run it with: costar run example:kitting --seed N.",
        RunPolicy.ONCE,
        objects=["kit_bin", *PLATE_THICKNESS],
        reset_cell=True,
        scene="kitting_handoff",
        id=stable_id(KITTING, "kitting"),
        subtrees=list(subs.values()),
    )


def main() -> None:
    """Write the kitting plan and its subtrees."""
    write_library(LIBRARY, library(), RESOURCES)
    plan = HERE / "kitting.costar.json"
    save_plan(kitting(), plan)
    print(f"wrote {plan.name}")


if __name__ == "__main__":
    main()
