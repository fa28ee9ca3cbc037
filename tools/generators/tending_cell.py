"""The wire-bender tending cell as taught for our plan and its library: where the exit, the
pieces of a broken weld, the rack's tote and the scrap bin are, the welding arm's region, the
waypoints, and the node maker the tending generator builds with (``make_tending.py``,
``tending_library.py``).
"""

from __future__ import annotations

import math

from engine.spec import Binding, NodeKind, NodeSpec
from engine.types import JointConfig, ParamType, Pose, Region, Waypoint, WaypointFrame
from tools.generators.plan_builder import TENDING, PlanBuilder, fixed

OBSERVE_JOINTS = (1.2, -1.9, 2.0, -1.6, -1.57, 0.0)  # out of the shoulder camera's view
# The tool down, turned as the bender drops its parts (the weld bead along world x, the
# fingers closing across it, along y), and the tool down with the fingers closing along x.
EXIT_DOWN = (0.0, 1.0, 0.0, 0.0)
ACROSS_DOWN = (math.sqrt(0.5), math.sqrt(0.5), 0.0, 0.0)
DOWN = (1.0, 0.0, 0.0, 0.0)
EXIT_XY = (0.55, 0.28)
GRASP_Z, ABOVE_Z = 0.017, 0.12  # TCP: fingertips 2 mm above the table; clear of the parts
# Where the pieces of a broken weld come to lie at the exit (world offsets from the exit
# point, taught by watching 16 break, 10 U and 6 step: each piece lands within 7 mm of where
# it lay in the part), all bars along y, so the fingers close across them along x: the left
# piece between the U's side bar and the step's end bar (the 85 mm stroke spans both), the
# U's right side bar, the step's right end bar.
PIECES = (
    ((-0.058, -0.045), ACROSS_DOWN),
    ((0.076, -0.05), ACROSS_DOWN),
    ((0.038, 0.036), ACROSS_DOWN),
)
ARM_REGION = Region((0.6, 0.28, 0.235), 0.05)  # the welding arm over the exit when it drops
TOTE = (0.04, 0.0)  # the middle of the rack's tote (rack frame)
OVER_RACK_Z, RACK_DROP_Z = 0.32, 0.235  # TCP, rack frame: the fingertips 2 cm over its rim
SCRAP_XY, SCRAP_Z = (0.42, 0.5), 0.2  # over the scrap bin (taught, world): 8 cm over its rim
REGRASP_TRIES = 1  # more tries scatter the pieces of a broken weld
ARM_TIMEOUT = 40.0  # s: longer than the bender's longest interval (20 s + 35 %) and a cycle
PERIOD = fixed(0.25, ParamType.DURATION)  # four looks a second see the welding arm come and go
# The discard races the next part (the welding arm comes down over the exit): its moves run
# at twice the nominal speed and acceleration (2.1 rad/s; a UR5's joints allow 3.15), but
# for carrying a piece to the bin: held by one thin bar, a piece slipped out at that
# acceleration on its way there (2 of 6 short trials of a step's break, under load).
DISCARD_SPEED = 2.0
PIECE_TIME = 15.0  # s: simulated seconds for one piece (a jammed finger gives up)
# Fingers that meet a piece at a slant may squeeze it out from between them (1 in 6 short
# trials of a step's break): it then lies straight where they closed, and a second try takes it.
PIECE_TRIES = 2
TAKE_TIME = 15.0  # s: simulated seconds for a pick (its moves take about 5)


def observe() -> Waypoint:
    """The joint-space waypoint from which the shoulder camera sees the cell."""
    return Waypoint("observe", WaypointFrame.JOINTS, joints=JointConfig(OBSERVE_JOINTS))


def _world(
    name: str, x: float, y: float, z: float, turn: tuple[float, float, float, float]
) -> Waypoint:
    return Waypoint(name, WaypointFrame.WORLD, Pose((x, y, z), turn))


def _on_rack(name: str, z: float) -> Waypoint:
    return Waypoint(name, WaypointFrame.OBJECT, Pose((*TOTE, z), DOWN), reference="tending_rack")


def waypoints() -> list[Waypoint]:
    """Every waypoint the plan uses (taught on the tending scene)."""
    found = [
        observe(),
        _world("over exit", *EXIT_XY, ABOVE_Z, EXIT_DOWN),
        _world("at exit", *EXIT_XY, GRASP_Z, EXIT_DOWN),
        _on_rack("over rack", OVER_RACK_Z),
        _on_rack("into rack", RACK_DROP_Z),
        _world("over scrap", *SCRAP_XY, SCRAP_Z, DOWN),
    ]
    for index, ((dx, dy), turn) in enumerate(PIECES, 1):
        found.append(_world(f"over piece {index}", EXIT_XY[0] + dx, EXIT_XY[1] + dy, ABOVE_Z, turn))
    return found


class TendingMaker(PlanBuilder):
    """The tending generator's nodes (ids in its own namespace), and a timed take."""

    def __init__(self, scope: str) -> None:
        super().__init__(TENDING, scope)

    def take(self, name: str, above: str, at: str) -> NodeSpec:
        """Down from ``above`` to ``at``, close, feel it held, lift, feel it still held; in
        ``TAKE_TIME`` (a finger that jams on a part lying askew must not hold the robot up).
        """
        return self.node(NodeKind.TIMEOUT, name, self._take(above, at), seconds=TAKE_TIME)

    def _take(self, above: str, at: str) -> NodeSpec:
        return self.node(
            NodeKind.SEQUENCE,
            "take it",
            *self.feel(above, at),
            self.move("lift it", above, linear=True),
            self.op("gripper.is_holding", "still held"),
        )

    def feel(self, above: Waypoint | str, at: Waypoint | str) -> list[NodeSpec]:
        """Over it, straight down, close, feel it held: something lies there."""
        return [
            self.move("over it", above),
            self.move("down to it", at, linear=True),
            self.op("gripper.close", "close on it"),
            self.op("gripper.is_holding", "in the gripper"),
        ]

    def piece(self, over: Waypoint | str, scrap: Waypoint | str) -> NodeSpec:
        """A piece of a broken weld from where it lies (the tool ``over`` it) into the
        scrap bin, in ``PIECE_TIME`` (a piece must not hold the robot up).
        """
        # Lifted whether or not the fingers hold anything (the next spot is reached from
        # above), then into the scrap bin only when held: an empty spot costs a close and
        # two short moves.
        down, fast = GRASP_Z - ABOVE_Z, fixed(DISCARD_SPEED, ParamType.NUMBER)
        key = over if isinstance(over, str) else over.name.replace("over ", "").replace(" ", "_")

        def vertical(name: str, dz: float) -> NodeSpec:
            return self.op(
                "motion.move_relative", name, dz=fixed(dz, ParamType.NUMBER), speed=fast, accel=fast
            )

        return self.node(
            NodeKind.TIMEOUT,
            f"{key.lower()}, {PIECE_TIME:g} s at most",
            self.node(
                NodeKind.SEQUENCE,
                f"{key.lower()} into the scrap bin",
                self.op("gripper.open", "open"),
                self.move("over it", over, speed=DISCARD_SPEED),
                vertical("down to it", down),
                self.op("gripper.close", "close on it"),
                vertical("lift it", -down),
                self.op("gripper.is_holding", "a piece held"),
                self.move("over the scrap bin", scrap),
                self.op("gripper.open", "drop it into the bin"),
            ),
            seconds=PIECE_TIME,
        )

    def held_into_scrap(self, scrap: Waypoint | str) -> NodeSpec:
        """Whatever the gripper holds goes into the scrap bin (nothing to do if nothing)."""
        return self.node(
            NodeKind.FORCE_SUCCESS,
            "what is held, into the scrap bin",
            self.node(
                NodeKind.SEQUENCE,
                "drop it over the bin",
                self.op("gripper.is_holding", "something held"),
                self.move("over the scrap bin", scrap),
                self.op("gripper.open", "drop it into the bin"),
            ),
        )


def bound(waypoint: Waypoint) -> Binding:
    """A taught waypoint as a parameter's fixed value."""
    return fixed(waypoint, ParamType.WAYPOINT)
