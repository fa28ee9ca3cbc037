"""The simulated arm's protective stop: a collision stops it as a UR's force limit does.

A UR controller stops the arm (a protective stop) when the force it has to apply departs
from its model by more than the safety configuration's force limit (150 N by default), and
refuses to unlock it earlier than 5 s after it happened. The simulated arm does the same
with what pybullet measures: after each physics step :class:`CollisionWatch` sums the normal
forces between the robot (any link, and the suction tool while the gripper holds it) and
each *fixed* body (the table, the stand, the holster, a scene's fixtures: the bender, its
welding arm, the rack). A movable object is not a collision: the part held, the intended
grasp contact of the fingers or the cup, a part pushed while placing. Physics thread only.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from capabilities.bullet import pybullet
from capabilities.faults import PROTECTIVE_STOP

__all__ = ["CollisionWatch", "ProtectiveStop"]

_BASE_LINK = -1  # the robot's base sits on its stand: a contact that is always there


@dataclass(frozen=True)
class ProtectiveStop:
    """A protective stop of the simulated arm: when (simulated s) and what caused it."""

    time: float
    cause: str

    def message(self, command: str) -> str:
        """A command's failure: the fault words (see ``capabilities.faults``) and the cause."""
        return f"{command}: {PROTECTIVE_STOP} ({self.cause})"


class CollisionWatch:
    """Finds a contact of the robot with a fixed body above the force limit.

    Args:
        client: the pybullet client.
        robot: the robot's body id.
        tool: returns the body of the tool the robot holds (the suction tool), or None.
        force_limit: N of normal force with one fixed body above which it is a collision.
        names: a body id's name for messages ("table"); unknown ids read "body N".
    """

    def __init__(
        self,
        client: int,
        robot: int,
        tool: Callable[[], int | None],
        force_limit: float,
        names: Callable[[int], str],
    ) -> None:
        self._client = client
        self._robot = robot
        self._tool = tool
        self.force_limit = force_limit
        self._names = names
        self._links: dict[int, str] = {}
        self.peak = 0.0  # the largest force with a fixed body seen so far (N), for tuning
        self._leaving: dict[int, float] = {}  # body -> force allowed while backing out

    def check(self) -> str:
        """The cause of a collision after this step ("" when there is none)."""
        forces = self._forces()
        for (body, part), force in forces.items():
            self.peak = max(self.peak, force)
            allowed = self._leaving.get(body)
            if allowed is not None and force <= allowed:
                continue  # backing out of the contact it was stopped in
            if force > self.force_limit:
                return (
                    f"the {part} pressed on the {self._names(body)} with {force:.0f} N "
                    f"(limit {self.force_limit:g} N)"
                )
        touching = {body for body, _ in forces}
        for body in [b for b in self._leaving if b not in touching]:
            del self._leaving[body]  # they parted: the limit holds again
        return ""

    def leave_contacts(self) -> None:
        """After an unlock: the arm still presses on what stopped it (it holds the pose it
        was stopped in, within a fraction of a millimetre of it, with hundreds of N). While
        it backs out, that contact stops it only if it presses harder than now; once the
        bodies part, the limit holds again.
        """
        self._leaving = {}
        for (body, _), force in self._forces().items():
            self._leaving[body] = max(self._leaving.get(body, 0.0), force)

    def _forces(self) -> dict[tuple[int, str], float]:
        """Normal force (N) between each robot part and each fixed body it touches now."""
        forces: dict[tuple[int, str], float] = {}
        self._add(forces, self._robot, robot=True)
        tool = self._tool()
        if tool is not None:
            self._add(forces, tool, robot=False)
        return forces

    def _add(self, forces: dict[tuple[int, str], float], body: int, robot: bool) -> None:
        client, tool = self._client, self._tool()
        for contact in pybullet.getContactPoints(bodyA=body, physicsClientId=client):
            other, link = int(contact[2]), int(contact[3])
            if other in (self._robot, tool) or (robot and link == _BASE_LINK):
                continue
            if not self._is_fixed(other):
                continue
            part = self._link_name(link) if robot else "suction tool"
            key = (other, part)
            forces[key] = forces.get(key, 0.0) + float(contact[9])

    def _is_fixed(self, body: int) -> bool:
        # Not cached: a body id freed by removeBody (a part that broke) may come back.
        return float(pybullet.getDynamicsInfo(body, -1, physicsClientId=self._client)[0]) <= 0.0

    def _link_name(self, link: int) -> str:
        name = self._links.get(link)
        if name is None:
            info = pybullet.getJointInfo(self._robot, link, physicsClientId=self._client)
            name = info[12].decode().replace("_", " ")
            self._links[link] = name
        return name
