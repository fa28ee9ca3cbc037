"""The shipped tending and recovery subtrees of our wire-bender tending plan.

Written by ``make_tending.py``:

- ``resources/library/tending``: PickAtExit (take a part at the exit with taught waypoints
  and feel it held before and after lifting), PlaceOnRack (drop it into the rack's tote,
  taught relative to the rack) and WaitForPart (the welding arm swings down and back up, by
  occupancy; a swing not seen in time: feel for a part at the exit).
- ``resources/library/recovery``: Regrasp (a grasp that closed on nothing or a part that
  slipped: let go, look again at the exit and grasp again, a bounded number of tries),
  DiscardToScrap (a bad part: what is still held goes to the scrap bin, and the pieces of a
  broken weld are taken from where they fall at the exit to the scrap bin), ReRegisterRack
  (find the rack's marker again and give its pose, which the place waypoints are taught
  relative to) and PartThenLeftPiece (after a scrap the next part cut short: that part to
  the rack, then the piece it lay on into the scrap bin; a part that breaks on the lift to
  the scrap bin). ClearStopAndBackOff is shipped by ``make_clear_stop.py`` and read here.
"""

from __future__ import annotations

from engine.library import load_subtree
from engine.spec import Binding, NodeKind, NodeSpec, SubtreePort, SubtreeSpec
from engine.types import ObjectModel, ParamType
from tools.generators import RESOURCES
from tools.generators.plan_builder import fixed, port, subtree
from tools.generators.tending_cell import (
    ABOVE_Z,
    ARM_TIMEOUT,
    DISCARD_SPEED,
    GRASP_Z,
    PERIOD,
    PIECE_TRIES,
    PIECES,
    REGRASP_TRIES,
    TAKE_TIME,
    TendingMaker,
    observe,
)

LIBRARY = RESOURCES / "library"


def _exit_ports() -> list[SubtreePort]:
    return [
        port("ABOVE", ParamType.WAYPOINT, "the tool over the exit, clear of the parts"),
        port("AT", ParamType.WAYPOINT, "the tool where it closes on a part at the exit"),
    ]


def _piece_ports() -> list[SubtreePort]:
    return [
        port(
            f"PIECE_{i}",
            ParamType.WAYPOINT,
            "the tool over where a piece of a broken part lies (it goes straight down "
            f"{ABOVE_Z - GRASP_Z:.3f} m to take it)",
        )
        for i in range(1, len(PIECES) + 1)
    ]


def pick_at_exit() -> SubtreeSpec:
    """The PickAtExit subtree: take a part at the exit, feeling it held."""
    m = TendingMaker("pick_at_exit")
    tree = m.take("PickAtExit", "ABOVE", "AT")
    return subtree(
        "tending.pick_at_exit",
        "PickAtExit",
        "Takes a part where a machine dropped it, with taught waypoints: over it, straight "
        "down, close, feel it held, lift, feel it still held (fails when it is not).",
        tree,
        inputs=_exit_ports(),
    )


def wait_for_part() -> SubtreeSpec:
    """The WaitForPart subtree: wait for the machine's arm to drop a part."""
    m = TendingMaker("wait_for_part")
    tree = m.node(
        NodeKind.CATCH,
        "WaitForPart",
        m.node(
            NodeKind.SEQUENCE,
            "the arm swings down and back up",
            m.op(
                "occupancy.wait_until_occupied",
                "the arm comes down",
                region="REGION",
                timeout=fixed(ARM_TIMEOUT, ParamType.DURATION),
                period=PERIOD,
            ),
            m.op(
                "occupancy.wait_until_empty", "the arm is back up", region="REGION", period=PERIOD
            ),
        ),
        # A swing the camera missed (a busy computer) leaves a part at the exit that the
        # camera cannot see (flat on the table): after the longest interval, feel for it.
        m.instance(pick_at_exit(), "feel for a part that came unseen", ABOVE="ABOVE", AT="AT"),
        errors="timeout",
    )
    return subtree(
        "tending.wait_for_part",
        "WaitForPart",
        "Waits until a machine that drops its parts at an exit has dropped one: its arm swings "
        f"into REGION and back out (the camera's occupancy, four looks a second). When no "
        f"swing is seen in {ARM_TIMEOUT:g} s (longer than the longest interval), feels for a "
        "part at the exit with PickAtExit, so the part may then be held; fails when there is "
        "none.",
        tree,
        inputs=[
            port("REGION", ParamType.REGION, "where the machine's arm swings down"),
            *_exit_ports(),
        ],
    )


def place_on_rack() -> SubtreeSpec:
    """The PlaceOnRack subtree: drop what the gripper holds into the rack's tote."""
    m = TendingMaker("place_on_rack")
    tree = m.node(
        NodeKind.SEQUENCE,
        "PlaceOnRack",
        m.move("over the rack", "OVER", "RACK"),
        m.move("down over the tote", "INTO", "RACK", linear=True),
        m.op("gripper.open", "let go into the tote"),
        m.move("up from the rack", "OVER", "RACK", linear=True),
    )
    return subtree(
        "tending.place_on_rack",
        "PlaceOnRack",
        "Drops what the gripper holds into the rack's tote, with waypoints taught relative to "
        "the rack.",
        tree,
        inputs=[
            port("RACK", ParamType.POSE, "where the rack is"),
            port("OVER", ParamType.WAYPOINT, "the tool over the tote, relative to the rack"),
            port("INTO", ParamType.WAYPOINT, "where the tool lets go, relative to the rack"),
        ],
    )


def regrasp() -> SubtreeSpec:
    """The Regrasp recovery: let go and take the part at the exit again."""
    m = TendingMaker("regrasp")
    tree = m.node(
        NodeKind.RETRY,
        "Regrasp",
        m.node(
            NodeKind.SEQUENCE,
            "grasp again",
            m.op("gripper.open", "let go"),
            m.take("take it", "ABOVE", "AT"),
        ),
        count=REGRASP_TRIES,
    )
    return subtree(
        "recovery.regrasp",
        "Regrasp",
        f"After a grasp that closed on nothing or a part that slipped out: let go and take the "
        f"part again where it lies at the exit, feeling it held before and after lifting "
        f"(tries: {REGRASP_TRIES}, the Retry's count). Fails when it is never held (nothing "
        f"there, or a broken part).",
        tree,
        inputs=_exit_ports(),
    )


def discard_to_scrap() -> SubtreeSpec:
    """The DiscardToScrap recovery: a bad part and its pieces into the scrap bin."""
    m = TendingMaker("discard_to_scrap")
    held = m.held_into_scrap("SCRAP")

    # A broken part has two pieces: the right one lies at PIECE_2 (a U's) or else at
    # PIECE_3 (a step's), the left one at PIECE_1 (either shape's); each is tried twice when
    # nothing was held. The right one first: it lies deeper under the welding arm's swing
    # (seen by swinging the arm over the robot at each spot: half-way down the arm already
    # meets the robot at PIECE_2 and PIECE_3 and still clears it by 6 cm at PIECE_1, which
    # it reaches only at the end of its swing), so the robot is done there early, before
    # the next part can come (taken last, the arm came down on the robot there: 2 of the 3
    # parts lost in 2 x 50, seeds 9100-9101). Once both are in the bin the robot leaves.
    tree = m.node(
        NodeKind.SEQUENCE,
        "DiscardToScrap",
        held,
        m.op("gripper.open", "let go"),
        m.move("up from the exit", "ABOVE", speed=DISCARD_SPEED),
        m.node(
            NodeKind.FORCE_SUCCESS,
            "the right piece, if it lies there",
            m.node(
                NodeKind.RETRY,
                "both spots twice if need be",
                m.node(
                    NodeKind.SELECTOR,
                    "where a U's lies, else a step's",
                    m.piece("PIECE_2", "SCRAP"),
                    m.piece("PIECE_3", "SCRAP"),
                ),
                count=PIECE_TRIES,
            ),
        ),
        m.node(
            NodeKind.FORCE_SUCCESS,
            "the left piece, if it lies there",
            m.node(
                NodeKind.RETRY, "twice if need be", m.piece("PIECE_1", "SCRAP"), count=PIECE_TRIES
            ),
        ),
        m.move("step out of view", observe(), speed=DISCARD_SPEED),
    )
    return subtree(
        "recovery.discard_to_scrap",
        "DiscardToScrap",
        "A bad part: whatever the gripper still holds goes into the scrap bin, then the "
        "pieces of a broken weld are taken where they fall at the exit and dropped into the "
        "scrap bin: first the right piece, at PIECE_2, or at PIECE_3 when nothing was held at "
        "PIECE_2 (the spots under the machine's arm), then the left one at PIECE_1, each "
        "tried twice when nothing was held (taught spots; the moves at twice the nominal speed, "
        "the next part is coming, but for carrying a piece to the bin).",
        tree,
        inputs=[
            port("ABOVE", ParamType.WAYPOINT, "the tool over the exit, clear of the parts"),
            port("SCRAP", ParamType.WAYPOINT, "the tool over the scrap bin (taught)"),
            *_piece_ports(),
        ],
    )


def reregister_rack() -> SubtreeSpec:
    """The ReRegisterRack recovery: find the rack again through its markers."""
    m = TendingMaker("reregister_rack")
    tree = m.node(
        NodeKind.SEQUENCE,
        "ReRegisterRack",
        m.move("step out of view", observe()),
        m.op(
            "markers.detect_markers", "look at the rack", camera=fixed("shoulder", ParamType.TEXT)
        ),
        m.op("markers.object_pose", "pose of the rack", object="RACK", pose="RACK_POSE"),
    )
    return subtree(
        "recovery.reregister_rack",
        "ReRegisterRack",
        "Finds the rack again by its marker (the arm out of the shoulder camera's view) and "
        "gives its pose now: waypoints taught relative to the rack follow it when it was "
        "moved. Fails (not_found) when its marker is not seen.",
        tree,
        inputs=[port("RACK", ParamType.OBJECT, "the rack", ObjectModel("tending_rack"))],
        outputs=[port("RACK_POSE", ParamType.POSE, "where the rack is now")],
    )


def _feel_at_exit(m: TendingMaker, name: str) -> NodeSpec:
    """Over the exit, down, close, feel a part held, in ``TAKE_TIME``."""
    return m.node(
        NodeKind.TIMEOUT,
        name,
        m.node(NodeKind.SEQUENCE, "feel for it", *m.feel("ABOVE", "AT")),
        seconds=TAKE_TIME,
    )


def _unless_the_arm_comes(m: TendingMaker, name: str, work: NodeSpec) -> NodeSpec:
    """``work`` (whatever it finds), then out of view until the next part comes
    (WaitForPart); fails as soon as the machine's arm comes into REGION before it is done.
    """
    return m.node(
        NodeKind.SEQUENCE,
        f"{name}, then the next part",
        m.node(
            NodeKind.PARALLEL,
            f"{name}, unless the next part comes",
            m.node(NodeKind.FORCE_SUCCESS, "whatever it finds", work),
            m.node(NodeKind.FORCE_FAILURE, "the next part came", arm_comes(m, "REGION")),
            success="any",
        ),
        m.move("step out of view", observe()),
        m.instance(
            wait_for_part(), "then the next part comes", REGION="REGION", ABOVE="ABOVE", AT="AT"
        ),
    )


def _clear_of_the_arm(m: TendingMaker) -> list[NodeSpec]:
    """The machine's arm came: what is held into the scrap bin, let go, up clear, out of
    view until the arm is back up (its part lies at the exit).
    """
    return [
        m.held_into_scrap("SCRAP"),
        m.op("gripper.open", "let go"),
        m.op(
            "motion.move_relative", "up, clear of it", dz=fixed(ABOVE_Z - GRASP_Z, ParamType.NUMBER)
        ),
        m.move("step out of view", observe()),
        m.op("occupancy.wait_until_empty", "the arm is back up", region="REGION", period=PERIOD),
    ]


def _to_the_rack_then_the_left_piece(m: TendingMaker) -> list[NodeSpec]:
    """The part felt at the exit: lift it, feel it still held, to the rack (found again by
    its marker), then the left piece into the scrap bin unless the next part comes first
    (that part then lies at the exit: the caller's cycle picks it).
    """
    piece = m.node(
        NodeKind.RETRY, "twice if need be", m.piece("PIECE_1", "SCRAP"), count=PIECE_TRIES
    )
    return [
        m.move("lift it", "ABOVE", linear=True),
        m.op("gripper.is_holding", "still held"),
        m.instance(reregister_rack(), "where is the rack", RACK_POSE="RACK_POSE"),
        m.instance(place_on_rack(), "PlaceOnRack", RACK="RACK_POSE", OVER="OVER", INTO="INTO"),
        m.node(
            NodeKind.SELECTOR,
            "the left piece, else the next part came",
            _unless_the_arm_comes(m, "the left piece", piece),
            m.node(
                NodeKind.SEQUENCE, "the next part came: the caller picks it", *_clear_of_the_arm(m)
            ),
        ),
    ]


def part_then_left_piece() -> SubtreeSpec:
    """The PartThenLeftPiece recovery: the part to the rack, then a left-over piece to scrap."""
    m = TendingMaker("part_then_left_piece")
    # A discard the next part cut short leaves the left piece where that part lands (a bar of
    # either shape lies on its spot): the part goes to the rack first, the piece after. A
    # part that breaks on the lift (a bad weld) goes to the scrap bin, piece by piece (left
    # at the exit, its pieces lay there for good: 1 of the 2 parts lost in 2 x 50, seeds
    # 9100-9101); when the next part cuts that short, it lies on them: it goes to the rack,
    # then the left piece. Whenever the arm comes again, its part lies at the exit: the
    # caller's cycle picks it.
    discard = m.instance(
        discard_to_scrap(),
        "DiscardToScrap",
        ABOVE="ABOVE",
        SCRAP="SCRAP",
        **{f"PIECE_{i}": f"PIECE_{i}" for i in range(1, len(PIECES) + 1)},
    )
    tree = m.node(
        NodeKind.SEQUENCE,
        "PartThenLeftPiece",
        _feel_at_exit(m, "a part at the exit"),
        m.node(
            NodeKind.SELECTOR,
            "to the rack, else it broke on the lift",
            m.node(
                NodeKind.SEQUENCE,
                "to the rack, then the left piece",
                *_to_the_rack_then_the_left_piece(m),
            ),
            m.node(
                NodeKind.SELECTOR,
                "its pieces into the scrap bin, else the next part came",
                _unless_the_arm_comes(m, "its pieces into the scrap bin", discard),
                m.node(
                    NodeKind.SEQUENCE,
                    "the next part came: it, then the left piece",
                    *_clear_of_the_arm(m),
                    _feel_at_exit(m, "the next part at the exit"),
                    *_to_the_rack_then_the_left_piece(m),
                ),
            ),
        ),
    )
    return subtree(
        "recovery.part_then_left_piece",
        "PartThenLeftPiece",
        "After a scrap the next part cut short: takes that part at the exit (fails when there "
        "is none) to the rack (found again by its marker), then the piece left at PIECE_1 "
        "into the scrap bin (tried twice), then waits for the next part (WaitForPart). A part "
        "not held after the lift (a bad weld broke) goes to the scrap bin with DiscardToScrap "
        "instead, and so does one that cannot be placed. When the machine's arm comes into "
        "REGION before the piece (or the pieces) is held, its part lies at the exit: the robot "
        "leaves the piece, steps out of view and waits until the arm is back up; after the "
        "pieces of a broken part, it takes that part to the rack and then the left piece.",
        tree,
        inputs=[
            *_exit_ports(),
            port("OVER", ParamType.WAYPOINT, "the tool over the tote, relative to the rack"),
            port("INTO", ParamType.WAYPOINT, "where the tool lets go, relative to the rack"),
            *_piece_ports(),
            port("SCRAP", ParamType.WAYPOINT, "the tool over the scrap bin (taught)"),
            port("REGION", ParamType.REGION, "where the machine's arm swings down"),
        ],
        outputs=[port("RACK_POSE", ParamType.POSE, "where the rack is now")],
    )


def clear_stop() -> SubtreeSpec:
    """ClearStopAndBackOff as shipped (written by make_clear_stop.py)."""
    return load_subtree(LIBRARY / "recovery" / "ClearStopAndBackOff.subtree.json")


def library() -> dict[str, list[SubtreeSpec]]:
    """The shipped subtrees this generator writes, by library folder."""
    return {
        "tending": [pick_at_exit(), place_on_rack(), wait_for_part()],
        "recovery": [regrasp(), discard_to_scrap(), reregister_rack(), part_then_left_piece()],
    }


def arm_comes(m: TendingMaker, region: Binding | str) -> NodeSpec:
    """Watches until the machine's arm comes into ``region`` (ten minutes at most)."""
    return m.op(
        "occupancy.wait_until_occupied",
        "the welding arm comes",
        region=region,
        timeout=fixed(600.0, ParamType.DURATION),
        period=PERIOD,
    )
