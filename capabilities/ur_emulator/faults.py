"""Faults the emulator can raise by itself: a protective stop at a time or on contact."""

from __future__ import annotations

import contextlib
import threading
from typing import TYPE_CHECKING

from capabilities.bullet import pybullet

if TYPE_CHECKING:
    from capabilities.sim.cell import SimCell
    from capabilities.ur_emulator.controller import EmulatedController

__all__ = ["ContactWatch"]

_CONTACT_FORCE = 1.0  # N: lighter touches are not a collision


class ContactWatch:
    """Arms a protective stop at a simulated time, or when an arm link touches another body.

    The contact test runs on the physics thread after each step (links of the gripper are not
    arm links: a held part does not count); ``check()`` runs on the controller thread and
    raises the stop there.
    """

    def __init__(self, cell: SimCell, controller: EmulatedController) -> None:
        self._cell = cell
        self._ctl = controller
        self._at: float | None = None
        self._on_contact = False
        self._touched = threading.Event()
        self._hooked = False
        self._client = -1

    def stop_at(self, sim_time: float) -> None:
        """A protective stop once simulated time reaches ``sim_time``."""
        self._at = sim_time

    def stop_on_contact(self, on: bool = True) -> None:
        """A protective stop when an arm link touches anything (off: no more)."""
        self._touched.clear()
        self._on_contact = on
        if on and not self._hooked:
            self._client = self._cell.call(lambda client: client)
            self._cell.add_step_hook(post=self._after_step)
            self._hooked = True

    def check(self) -> None:
        """Raise the armed stop if its moment has come (controller thread)."""
        if self._at is not None and self._cell.time() >= self._at:
            self._at = None
            self._ctl.protective_stop("injected at a set time")
        if self._on_contact and self._touched.is_set():
            self._touched.clear()
            self._ctl.protective_stop("the arm touched something")

    def close(self) -> None:
        if self._hooked:
            with contextlib.suppress(Exception):  # the cell may be closed already
                self._cell.remove_step_hook(post=self._after_step)
            self._hooked = False

    def _after_step(self, _time: float) -> None:
        if not self._on_contact or self._touched.is_set():
            return
        robot = self._cell.robot_body_id
        arm_links = set(self._cell.world.arm_joints)
        for contact in pybullet.getContactPoints(bodyA=robot, physicsClientId=self._client):
            if contact[2] != robot and contact[3] in arm_links and contact[9] > _CONTACT_FORCE:
                self._touched.set()
                return
