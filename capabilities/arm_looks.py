"""What the looks of a capability (markers, perception) remember of the arm: where it stood
at each fixed camera's last look, to say when a look found nothing because the arm hid the
table (:mod:`capabilities.arm_view` measures it).

Light to import: numpy and the arm's body model load with the first look that needs them.
"""

from __future__ import annotations

from typing import Any

from engine.error_types import ErrorType
from engine.operations import OperationFailed

__all__ = ["ArmLooks", "fail_if_occluded"]


class ArmLooks:
    """The arm's pose at each camera's last look, for one capability on one cell.

    Args:
        arm: the cell's arm interface (None: a cell without an arm; nothing is noted).
        work_area: the table's work area ((x, y) min and max, m); default the arm view's.
    """

    def __init__(self, arm: Any, work_area: Any = None) -> None:
        self._arm = arm
        self._work_area = work_area
        self._view: Any = None
        self._glances: dict[str, Any] = {}  # camera name -> arm_view.Glance of its last look

    def glance(self, camera: Any, frame: Any) -> Any:
        """Note the arm's joints right after ``camera`` took ``frame`` (a fixed camera's look),
        to tell later whether the arm hid the table in it; None without an arm.
        """
        if self._arm is None:
            return None
        if self._view is None:
            from capabilities.arm_view import ArmView

            area = () if self._work_area is None else (self._work_area,)
            self._view = ArmView(self._arm, *area)
        glance = self._view.glance(camera, frame)
        self._glances[str(camera.name)] = glance
        return glance

    def hidden(self) -> str:
        """What to add to "not seen" when the arm hid the table in a camera's last look:
        "; the arm hides the table from the <camera> camera (..)"; else "".
        """
        for glance in list(self._glances.values()):
            cover = glance.hides() if glance is not None else None
            if cover is not None:
                return f"; {cover.sentence()}"
        return ""


def fail_if_occluded(glance: Any, what: str) -> None:
    """Fail a look that found nothing (``occluded``) when the arm hid the table in it.

    Raises:
        OperationFailed: the arm hid the table; the message says so and what was not found.
    """
    cover = glance.hides() if glance is not None else None
    if cover is not None:
        raise OperationFailed(
            f"{cover.sentence()}: {what}; move the arm out of its view before looking",
            ErrorType.OCCLUDED,
        )
