"""Write the shipped recovery subtree ClearStopAndBackOff, byte for byte.

``resources/library/recovery/ClearStopAndBackOff.subtree.json``: after a collision (a
protective stop thrown into the plan and caught), clear the stop, back the tool off straight
up by ``BACK_OFF`` (what it hit is below it, or beside it: the tool leaves on a straight line)
and go to a safe pose. It runs on any cell whose arm can clear a protective stop (the
simulated cell and a UR: ``motion.clear_protective_stop``).

Usage: python resources/examples/make_clear_stop.py
"""

from __future__ import annotations

import uuid
from pathlib import Path

from engine.library import dump_subtree
from engine.plan_writer import write_atomic
from engine.spec import Binding, NodeKind, NodeSpec, SubtreePort, SubtreeSpec
from engine.types import JointConfig, ParamType, Waypoint, WaypointFrame

HERE = Path(__file__).resolve().parent
PATH = HERE.parent / "library" / "recovery" / "ClearStopAndBackOff.subtree.json"
_NAMESPACE = uuid.UUID("3f0c5b1e-8a47-4d2a-b6e1-5c9d2e7a4f10")
DATE = "2026-11-24T00:00:00Z"
BACK_OFF = 0.05  # m: out of contact, and clear of a part's edge the tool pressed on
# The simulated cell's home joints: the arm upright over its base, clear of the table.
SAFE_JOINTS = (0.0, -1.5708, 1.5708, -1.5708, -1.5708, 0.0)


def _id(n: int) -> str:
    return uuid.uuid5(_NAMESPACE, f"clear_stop/{n}").hex


def clear_stop_and_back_off() -> SubtreeSpec:
    """The subtree, with ids that stay the same from one run to the next."""
    safe = Waypoint("safe", WaypointFrame.JOINTS, joints=JointConfig(SAFE_JOINTS))
    tree = NodeSpec(NodeKind.SEQUENCE, "ClearStopAndBackOff", _id(1), children=[
        NodeSpec(NodeKind.OPERATION, "clear the stop", _id(2), op="motion.clear_protective_stop"),
        NodeSpec(NodeKind.OPERATION, "back off", _id(3), op="motion.move_relative",
                 params={"dz": Binding.reference("BACK_OFF"),
                         "speed": Binding.fixed(0.5, ParamType.NUMBER)}),
        NodeSpec(NodeKind.OPERATION, "to the safe pose", _id(4), op="motion.move_to",
                 params={"target": Binding.reference("SAFE")}),
    ])  # fmt: skip
    return SubtreeSpec(
        "recovery.clear_stop_and_back_off", "ClearStopAndBackOff", tree, 1, DATE,
        "After a collision: clears the protective stop (once the robot allows it), backs the "
        "tool off straight up and goes to a safe pose. Put it as the handler of a Catch of "
        "protective_stop around the moves.",
        inputs=[
            SubtreePort("BACK_OFF", ParamType.NUMBER,
                        "m the tool backs off straight up (half speed)", BACK_OFF),
            SubtreePort("SAFE", ParamType.WAYPOINT, "where the arm waits after backing off",
                        safe),
        ],
        outputs=[],
    )  # fmt: skip


def main() -> None:
    PATH.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(PATH, dump_subtree(clear_stop_and_back_off()).encode("utf-8"))
    print(f"wrote {PATH}")


if __name__ == "__main__":
    main()
