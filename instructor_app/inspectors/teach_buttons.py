"""Teach and Move here under a Pose or Waypoint parameter of the inspector.

As on Rethink Intera's pose nodes: Teach fills the parameter from where the robot is now (a
Pose becomes the tool pose; a Waypoint is taught again in its own frame, and every node
using it follows; an unset Waypoint parameter gets a new waypoint in the world frame named
after the node), and Move here, held down, drives the arm to the parameter's pose at
reduced speed (let go and it stops). :func:`change_text` says what a Teach changed (old and
new pose in mm and degrees) and :func:`other_users` which other nodes share a waypoint (the
inspector asks before teaching such a waypoint again).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from PySide6.QtWidgets import QHBoxLayout, QPushButton, QWidget

from engine.operations import Direction, PortSpec
from engine.spec import Binding, PlanSpec
from engine.types import ParamType, Pose, Waypoint, WaypointFrame
from engine.units import quaternion_to_rpy
from instructor_app.runtime.waypoint_teach import TeachError, teach_like, teach_waypoint

__all__ = [
    "TeachButtons",
    "TeachResult",
    "change_text",
    "is_teachable",
    "move_target",
    "other_users",
    "taught_value",
]

_TEACHABLE = (ParamType.POSE, ParamType.WAYPOINT)


def is_teachable(port: PortSpec) -> bool:
    """An input that takes a Pose or a Waypoint."""
    return port.direction is Direction.IN and any(t in _TEACHABLE for t in port.types)


TeachResult = tuple[Waypoint | None, Binding]


def taught_value(
    interfaces: Any,
    port: PortSpec,
    binding: Binding | None,
    node_name: str,
    names: list[str],
    preferred: ParamType = ParamType.WAYPOINT,
) -> TeachResult:
    """(waypoint taught or None, the port's new binding) from where the arm is now; an
    unset port gets a value of ``preferred`` (the type its row shows) if it takes one.

    Raises:
        TeachError: the arm cannot be read, the binding is a parameter name, or a relative
            waypoint's object has not been recognised.
    """
    if binding is not None and binding.is_ref:
        raise TeachError(f"{port.name} is bound to the parameter {binding.ref}: choose 'value'")
    value = binding.value if binding is not None else None
    if isinstance(value, Waypoint):
        new = teach_like(interfaces, value)
        return new, Binding.fixed(new, ParamType.WAYPOINT)
    only_pose = ParamType.WAYPOINT not in port.types
    unset_pose = value is None and preferred is ParamType.POSE and ParamType.POSE in port.types
    if isinstance(value, Pose) or only_pose or unset_pose:
        arm = interfaces.get("arm")
        if arm is None:
            raise TeachError("this cell has no arm to teach from")
        return None, Binding.fixed(arm.tcp_pose(), ParamType.POSE)
    name, n = node_name or "waypoint", 2
    while name in names:
        name, n = f"{node_name} {n}", n + 1
    new = teach_waypoint(interfaces, name, WaypointFrame.WORLD)
    return new, Binding.fixed(new, ParamType.WAYPOINT)


def other_users(plan: PlanSpec, waypoint: str, node_id: str) -> list[str]:
    """Names of the nodes other than ``node_id`` with a parameter fixed to ``waypoint``."""
    return [
        node.name or node.id
        for _, node in plan.walk()
        if node.id != node_id
        and any(
            not b.is_ref and isinstance(b.value, Waypoint) and b.value.name == waypoint
            for b in node.params.values()
        )
    ]


def pose_text(value: object) -> str:
    """A Pose, or a Waypoint's pose (joints for a joint-space one), in mm and degrees."""
    if isinstance(value, Waypoint):
        if value.pose is None:
            joints = value.joints.positions if value.joints is not None else ()
            return "joints (" + ", ".join(f"{math.degrees(q):.1f}" for q in joints) + ")°"
        where = f" relative to {value.reference}" if value.reference else ""
        return pose_text(value.pose) + where
    if not isinstance(value, Pose):
        return "unset"
    x, y, z = (v * 1000 for v in value.position)
    r, p, w = (math.degrees(a) for a in quaternion_to_rpy(value.orientation))
    return f"({x:.1f}, {y:.1f}, {z:.1f}) mm, ({r:.1f}, {p:.1f}, {w:.1f})°"


def change_text(what: str, old: object, new: object) -> str:
    """What a Teach changed, for the status bar: old and new pose and how to undo it."""
    return f"Taught {what}: {pose_text(old)} → {pose_text(new)}. Undo: Ctrl+Z."


def move_target(binding: Binding | None, reference: Binding | None) -> tuple[Any, Any] | None:
    """(target, reference) for Move here; None when the parameter holds no pose."""
    if binding is None or binding.is_ref or not isinstance(binding.value, (Pose, Waypoint)):
        return None
    ref = reference.value if reference is not None and not reference.is_ref else ""
    return binding.value, ref if isinstance(ref, (Pose, str)) else ""


class TeachButtons(QWidget):
    """Teach (click) and Move here (hold) for one port.

    Args:
        teacher: the RobotTeacher (moves off the GUI thread).
        teach: called on Teach.
        target: gives (target, reference) for Move here, or None when there is none.
        by_name: True while the port is bound to a parameter name (nothing to teach then).
    """

    def __init__(
        self,
        teacher: Any,
        teach: Callable[[], object],
        target: Callable[[], tuple[Any, Any] | None],
        by_name: Callable[[], bool] = lambda: False,
        parent: QWidget | None = None,
    ) -> None:
        super().__init__(parent)
        self._teacher = teacher
        self._target = target
        self._by_name = by_name
        self.teach_button = QPushButton("Teach")
        self.teach_button.setToolTip("Fill this parameter from where the robot is now")
        self.teach_button.clicked.connect(teach)
        self.move_button = QPushButton("Move here")
        self.move_button.setToolTip(
            "Hold down to drive the arm to this pose at reduced speed; let go and it stops"
        )
        self.move_button.pressed.connect(self._pressed)
        self.move_button.released.connect(teacher.release)
        layout = QHBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.teach_button)
        layout.addWidget(self.move_button)
        layout.addStretch(1)  # the buttons keep their size at the left, in view
        teacher.availability_changed.connect(self.update_enabled)
        self.update_enabled()

    def update_enabled(self) -> None:
        reason = self._teacher.unavailable_reason("arm")
        by_name = self._by_name()
        self.teach_button.setEnabled(self._teacher.interface("arm") is not None and not by_name)
        self.teach_button.setToolTip(
            "Bound to a parameter: choose 'value' to teach it"
            if by_name
            else "Fill this parameter from where the robot is now"
        )
        has_target = self._target() is not None
        self.move_button.setEnabled(not reason and has_target)
        if reason:
            self.move_button.setToolTip(reason.capitalize())
        elif not has_target:
            self.move_button.setToolTip("Give this parameter a pose or a waypoint first")

    def _pressed(self) -> None:
        found = self._target()
        if found is not None:
            self._teacher.hold_move_to(found[0], found[1])
