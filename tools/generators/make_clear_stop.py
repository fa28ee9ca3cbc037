"""Write the shipped recovery subtree ClearStopAndBackOff, byte for byte.

``resources/library/recovery/ClearStopAndBackOff.subtree.json``: after a collision (a
protective stop thrown into the plan and caught), clear the stop, back the tool off straight
up by ``BACK_OFF`` (what it hit is below it, or beside it: the tool leaves on a straight line)
and go to a safe pose. It runs on any cell whose arm can clear a protective stop (the
simulated cell and a UR: ``motion.clear_protective_stop``).

Usage: python -m tools.generators.make_clear_stop
"""

from __future__ import annotations

from engine.spec import NodeKind, SubtreeSpec
from engine.types import JointConfig, ParamType, Waypoint, WaypointFrame
from tools.generators import RESOURCES
from tools.generators.plan_builder import (
    CLEAR_STOP,
    PlanBuilder,
    fixed,
    port,
    subtree,
    write_library,
)

LIBRARY = RESOURCES / "library" / "recovery"
BACK_OFF = 0.05  # m: out of contact, and clear of a part's edge the tool pressed on
# The simulated cell's home joints: the arm upright over its base, clear of the table.
SAFE_JOINTS = (0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0)


def clear_stop_and_back_off() -> SubtreeSpec:
    """The subtree, with ids that stay the same from one run to the next."""
    safe = Waypoint("safe", WaypointFrame.JOINTS, joints=JointConfig(SAFE_JOINTS))
    m = PlanBuilder(CLEAR_STOP, "clear_stop")
    root = m.id()  # this tree is numbered from its root down
    tree = m.node(
        NodeKind.SEQUENCE,
        "ClearStopAndBackOff",
        m.op("motion.clear_protective_stop", "clear the stop"),
        m.op("motion.move_relative", "back off", dz="BACK_OFF", speed=fixed(0.5, ParamType.NUMBER)),
        m.op("motion.move_to", "to the safe pose", target="SAFE"),
        node_id=root,
    )
    return subtree(
        "recovery.clear_stop_and_back_off",
        "ClearStopAndBackOff",
        "After a collision: clears the protective stop (once the robot allows it), backs the "
        "tool off straight up and goes to a safe pose. Put it as the handler of a Catch of "
        "protective_stop around the moves.",
        tree,
        inputs=[
            port(
                "BACK_OFF",
                ParamType.NUMBER,
                "m the tool backs off straight up (half speed)",
                BACK_OFF,
            ),
            port("SAFE", ParamType.WAYPOINT, "where the arm waits after backing off", safe),
        ],
    )


def main() -> None:
    """Write the ClearStopAndBackOff subtree into the shipped library."""
    write_library(LIBRARY, [clear_stop_and_back_off()], RESOURCES)


if __name__ == "__main__":
    main()
