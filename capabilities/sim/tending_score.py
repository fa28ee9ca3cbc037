"""GROUND TRUTH scores of a tending trial (the paper's Table I), for trials and benches only.

What became of each part the wire bender produced, read from the bender's events and the
simulator's poses once things settled: on the rack's tote (caught), in a scrap bin (scrapped:
the part, or every piece of its broken weld), taken away by the operator, or lying about.
Never read by an operation: the plan perceives through the cameras.

The counters, as in Table I (two trials of 50 parts: 82 caught, 2 bad welds, 5 bad grasps,
13 lost to system ESTOPs):

- ``produced``: parts the bender released.
- ``caught``: whole parts in the rack's tote. ``scrapped``: parts in a scrap bin.
- ``bad_weld`` / ``bad_grasp``: the faults that struck (a weld came apart when lifted, a
  grasp slipped), whether a plan recovered from them or not.
- ``lost``: produced parts neither caught nor scrapped; ``lost_to_stops``: those among them
  that had no fault of their own (the robot was stopped, waiting for the operator, while
  the bender went on; or it missed them).
- ``operator_interventions``: times the plan waited for the operator.
- ``picks_per_hour``: parts caught or scrapped per simulated hour of the trial.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass
from typing import Any

from capabilities.bullet import pybullet as p
from capabilities.sim.bender import RELEASED, SLIPPED, WELD_BROKE, WireBender
from capabilities.sim.scene import SceneState
from engine.types import Pose

__all__ = ["TrialCounters", "container_of", "loose_things", "lost_parts", "score_trial"]

RACK = "rack"  # the scene object whose tote counts as caught; other totes are scrap bins
OVER_RIM = 0.03  # m over a tote's rim still counts as in it (a pile); higher: held over it


@dataclass(frozen=True)
class TrialCounters:
    """Table I's counters of one trial (or of several added up); see the module doc."""

    produced: int = 0
    caught: int = 0
    scrapped: int = 0
    bad_weld: int = 0
    bad_grasp: int = 0
    lost: int = 0
    lost_to_stops: int = 0
    operator_interventions: int = 0
    sim_seconds: float = 0.0

    @property
    def picks_per_hour(self) -> float:
        hours = self.sim_seconds / 3600.0
        return (self.caught + self.scrapped) / hours if hours > 0 else 0.0

    def __add__(self, other: TrialCounters) -> TrialCounters:
        mine, theirs = asdict(self), asdict(other)
        return TrialCounters(**{k: mine[k] + theirs[k] for k in mine})

    def as_dict(self) -> dict[str, Any]:
        """The counters as JSON values (with ``picks_per_hour``, rounded)."""
        out = asdict(self)
        out["sim_seconds"] = round(self.sim_seconds, 1)
        out["picks_per_hour"] = round(self.picks_per_hour, 1)
        return out


def _in_tote(tote: Mapping[str, Any], frame: Pose, where: Pose) -> bool:
    x, y, z = frame.inverse().compose(where).position
    (cx, cy), (ix, iy) = tote["center"], tote["inner"]
    floor, top = float(tote["floor"]), float(tote["rim"]) + OVER_RIM
    return abs(x - cx) < ix / 2 and abs(y - cy) < iy / 2 and floor - 0.002 < z < top


def _totes(client: int, scene: SceneState) -> list[tuple[str, Mapping[str, Any], Pose]]:
    """(object name, tote block, its frame now) of every object with a tote (rack, bins);
    a tote without a ``rim`` height has its object's highest collision box as rim.
    """
    found = []
    for name in scene.names():
        model = scene.model(name)
        tote = model.extra.get("tote")
        if isinstance(tote, Mapping):
            if "rim" not in tote:
                boxes = model.collision.boxes
                tote = {**tote, "rim": max(b.position[2] + b.size[2] / 2 for b in boxes)}
            found.append((name, tote, scene.truth_pose(client, name)))
    return found


def _body_pose(client: int, body: int) -> Pose:
    """Where a piece is: the middle of its bounding box (its base frame is the frame of the
    part it broke off, which may lie outside the piece).
    """
    lo, hi = p.getAABB(body, physicsClientId=client)
    middle = tuple((a + b) / 2 for a, b in zip(lo, hi, strict=True))
    return Pose(middle, (0.0, 0.0, 0.0, 1.0))


def container_of(client: int, scene: SceneState, where: Pose) -> str:
    """'caught' (in the rack's tote), 'scrapped' (in another tote) or '' (physics thread)."""
    for name, tote, frame in _totes(client, scene):
        if _in_tote(tote, frame, where):
            return "caught" if name == RACK else "scrapped"
    return ""


def _pieces_by_part(bender: WireBender, scene: SceneState) -> dict[str, list[int]]:
    """The bodies of each broken part's pieces (the bender appends them in break order)."""
    bodies, out, at = bender.pieces(), {}, 0
    for event in bender.events():
        if event.kind == WELD_BROKE:
            count = len(scene.library.get(event.shape).extra["weld"]["pieces"])
            out[event.part] = bodies[at : at + count]
            at += count
    return out


def _fate(client: int, scene: SceneState, part: str, pieces: list[int] | None) -> str:
    """Where a part is now: 'caught', 'scrapped' or '' (lost; taken away counts as lost)."""
    if pieces is not None:  # broken: scrapped when every piece lies in a scrap bin
        places = {container_of(client, scene, _body_pose(client, b)) for b in pieces}
        return "scrapped" if pieces and places == {"scrapped"} else ""
    if part not in scene.objects:
        return ""
    return container_of(client, scene, scene.truth_pose(client, part))


def loose_things(client: int, bender: WireBender, scene: SceneState) -> tuple[list[str], list[int]]:
    """Produced parts and pieces in no tote (what an operator clears away; physics thread)."""
    parts = [
        e.part
        for e in bender.produced()
        if e.part in scene.objects
        and not container_of(client, scene, scene.truth_pose(client, e.part))
    ]
    pieces = [
        b
        for b in bender.pieces()
        if _exists(client, b) and not container_of(client, scene, _body_pose(client, b))
    ]
    return parts, pieces


def _exists(client: int, body: int) -> bool:
    try:
        p.getBasePositionAndOrientation(body, physicsClientId=client)
    except p.error:
        return False
    return True


def score_trial(
    client: int,
    bender: WireBender,
    scene: SceneState,
    removed: set[int],
    interventions: int,
    sim_seconds: float,
) -> TrialCounters:
    """Table I's counters now (physics thread); ``removed``: piece bodies taken away."""
    events = bender.events()
    pieces = _pieces_by_part(bender, scene)
    fates: dict[str, str] = {}
    for event in events:
        if event.kind == RELEASED:
            kept = pieces.get(event.part)
            live = None if kept is None else [b for b in kept if b not in removed]
            fates[event.part] = _fate(client, scene, event.part, live)
    faulty = {e.part for e in events if e.kind in (WELD_BROKE, SLIPPED)}
    lost = [part for part, fate in fates.items() if not fate]
    return TrialCounters(
        produced=len(fates),
        caught=sum(f == "caught" for f in fates.values()),
        scrapped=sum(f == "scrapped" for f in fates.values()),
        bad_weld=sum(e.kind == WELD_BROKE for e in events),
        bad_grasp=sum(e.kind == SLIPPED for e in events),
        lost=len(lost),
        lost_to_stops=sum(part not in faulty for part in lost),
        operator_interventions=interventions,
        sim_seconds=sim_seconds,
    )


def _where(client: int, scene: SceneState, at: Pose, exit_at: Pose | None) -> str:
    """In words: in a tote, at the bender's exit (within 15 cm) or elsewhere, with height."""
    place = container_of(client, scene, at)
    if place:
        return "in the rack's tote" if place == "caught" else "in the scrap bin"
    x, y, z = at.position
    if exit_at is not None and math.dist(at.position[:2], exit_at.position[:2]) < 0.15:
        return f"at the exit (z {z:.3f})"
    return f"at ({x:.2f}, {y:.2f}, {z:.3f})"


def lost_parts(
    client: int, bender: WireBender, scene: SceneState, removed: set[int]
) -> list[dict[str, Any]]:
    """What became of each lost part, in words (physics thread; for the bench's report):
    its release time, its fault, and where it (or each of its pieces) is now.
    """
    events = bender.events()
    pieces = _pieces_by_part(bender, scene)
    faults = {e.part: e.kind for e in events if e.kind in (WELD_BROKE, SLIPPED)}
    out = []
    for event in events:
        if event.kind != RELEASED:
            continue
        kept = pieces.get(event.part)
        live = None if kept is None else [b for b in kept if b not in removed]
        if _fate(client, scene, event.part, live):
            continue
        if kept is not None:
            where = [
                "taken away"
                if b in removed
                else _where(client, scene, _body_pose(client, b), event.pose)
                for b in kept
            ]
        elif event.part in scene.objects:
            where = [_where(client, scene, scene.truth_pose(client, event.part), event.pose)]
        else:
            where = ["taken away"]
        out.append(
            {
                "part": event.part,
                "released": round(event.time, 1),
                "fault": faults.get(event.part, ""),
                "where": where,
            }
        )
    return out
